#pragma once
/// @file
/// CLI11 validators shared by the tools (docs/spec.md, section 5b: an option value must be a finite
/// number in range), and their --version text. CLI::Range lets NaN through (every comparison with
/// NaN is false) and says nothing about infinity; these do not. The range shows in --help.

#include <cf/params.hpp>
#include <cf/version.hpp>

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <stdexcept>
#include <string>

namespace cf::cli {

/// "%g" of a bound, for --help and messages.
inline std::string bound_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// A finite number in [lo, hi].
inline CLI::Validator finite_range(double lo, double hi) {
  const std::string range = "[" + bound_text(lo) + ", " + bound_text(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const char* b = text.c_str();
        char* end = nullptr;
        const double v = std::strtod(b, &end);
        if (text.empty() || end == b || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v)) return "'" + text + "' is not a finite number";
        if (v < lo || v > hi) return "'" + text + "' is outside " + range;
        return {};
      },
      range);
}

/// A finite number that libcf's parameter table accepts for `spec` (cf/params.hpp): the same
/// range as the library's validate(), shown in --help.
inline CLI::Validator param_range(const cf::ParamSpec& spec) {
  const std::string range = std::string(spec.lo_open ? "(" : "[") + bound_text(spec.lo) + ", " +
                            bound_text(spec.hi) + "]";
  return CLI::Validator(
      [spec, range](std::string& text) -> std::string {
        const char* b = text.c_str();
        char* end = nullptr;
        const double v = std::strtod(b, &end);
        if (text.empty() || end == b || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v)) return "'" + text + "' is not a finite number";
        if (!spec.problem(v).empty()) return "'" + text + "' is outside " + range;
        return {};
      },
      range);
}

/// An option under its name before a rename, listed apart in --help: it sets the same value
/// and, when given, adds "<name> is now <now>" to `notes`, for the tool to print as a warning.
template <class T>
CLI::Option* old_option_name(CLI::App& app, const std::string& name, const std::string& now,
                             T& value, std::set<std::string>& notes) {
  return app.add_option(name, value)
      ->group("Old names (work until the next release)")
      ->each([&notes, name, now](const std::string&) { notes.insert(name + " is now " + now); });
}

/// The entry of libcf's parameter table for `path` ("epsilon_mm").
/// @throws std::logic_error when there is none (a tool asking for a parameter libcf lacks).
inline const cf::ParamSpec& param_spec(const std::string& path) {
  for (const cf::ParamSpec& spec : cf::param_specs())
    if (spec.path == path) return spec;
  throw std::logic_error("no parameter '" + path + "' in cf::param_specs()");
}

/// What `TOOL --version` prints: "cfgen 0.1.0 (graph format 1)".
inline std::string version_text(const std::string& tool) {
  return tool + " " + kVersion + " (graph format " + std::to_string(kGraphFormatVersion) + ")";
}

}  // namespace cf::cli

#pragma once
// A scratch directory for the files a test program writes, removed when it exits.

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <unistd.h>

namespace cf::test {

/// The program's scratch directory (one per process, so parallel test programs do not meet).
inline std::filesystem::path scratch() {
  namespace fs = std::filesystem;
  static const fs::path dir = [] {
    fs::path d =
        fs::temp_directory_path() / ("cf_test_" + std::to_string(static_cast<long>(::getpid())));
    fs::create_directories(d);
    return d;
  }();
  // Removed when the test program exits.
  static const struct Cleanup {
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup;
  return dir;
}

/// Writes `text` to `name` in the scratch directory; returns its path.
inline std::string write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path p = scratch() / name;
  std::ofstream out(p, std::ios::binary);
  out << text;
  return p.string();
}

}  // namespace cf::test

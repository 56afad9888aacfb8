// The parameter table and validate() (libcf/include/cf/params.hpp): the defaults pass, each
// real parameter outside its range is refused by name with its value and range, the
// constraints between parameters hold, and every entry point checks.

#include <cf/force.hpp>
#include <cf/params.hpp>

#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <set>
#include <string>

namespace {

std::string why_refused(const cf::Params& p) {
  try {
    cf::validate(p);
  } catch (const cf::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("the defaults pass, and the table names each parameter once", "[params]") {
  const cf::Params defaults;
  CHECK(why_refused(defaults).empty());
  std::set<std::string> paths, keywords, options;
  std::set<const double*> fields;
  cf::Params p;
  for (const cf::ParamSpec& s : cf::param_specs()) {
    CHECK(paths.insert(s.path).second);
    CHECK(keywords.insert(s.python).second);
    if (s.option) CHECK(options.insert(s.option).second);
    CHECK(fields.insert(&s.field(p)).second);
    CHECK(s.problem(s.get(defaults)).empty());
    CHECK(s.lo < s.hi);
  }
}

TEST_CASE("each real parameter outside its range is refused with its path, value and range",
          "[params]") {
  for (const cf::ParamSpec& s : cf::param_specs()) {
    // Just outside the range at each end, and the non-finite values.
    const double below = s.lo_open ? s.lo : s.lo - std::max(1.0, std::abs(s.lo));
    const double above = s.hi + std::max(1.0, std::abs(s.hi));
    for (double v : {below, above, std::nan(""), std::numeric_limits<double>::infinity()}) {
      cf::Params p;
      s.field(p) = v;
      const std::string why = why_refused(p);
      INFO(s.path << " = " << v);
      CHECK(why.rfind(std::string("cf::Params: parameter ") + s.path + " = ", 0) == 0);
      CHECK(why.find(" is outside ") != std::string::npos);
    }
  }
  cf::Params p;
  p.kp_N_per_mm = 0;  // a divisor of the force model (eqs. (3)-(4))
  CHECK(why_refused(p) == "cf::Params: parameter kp_N_per_mm = 0 is outside (0, 1e+09] N/mm");
}

TEST_CASE("the constraints between parameters, the counts and the points", "[params]") {
  cf::Params p;
  p.mu_static = 0.05;  // below the default mu_kinetic 0.08
  CHECK(why_refused(p) ==
        "cf::Params: parameter mu_kinetic = 0.08 is above mu_static = 0.05: kinetic friction "
        "cannot exceed static friction");
  p = cf::Params();
  p.detection.min_angular_tolerance_rad = 0.2;  // above the default ceiling 0.1
  CHECK(why_refused(p) ==
        "cf::Params: parameter detection.min_angular_tolerance_rad = 0.2 is above "
        "detection.max_angular_tolerance_rad = 0.1");
  p = cf::Params();
  p.proxy.solver_iterations = 0;
  CHECK(why_refused(p) == "cf::Params: parameter proxy.solver_iterations = 0 is below 1");
  p = cf::Params();
  p.moment_point_A.x() = std::nan("");
  CHECK(why_refused(p) == "cf::Params: parameter moment_point_A is not finite");
}

TEST_CASE("the force model checks its parameters", "[params]") {
  cf::Params p;
  p.kp_N_per_mm = 0;
  const cf::Polyhedron a = cf::test::box(10, 10, 10, "A"), b = cf::test::box(40, 40, 10, "B");
  CHECK_THROWS_WITH(cf::ForceModel(a, b, p),
                    "cf::Params: parameter kp_N_per_mm = 0 is outside (0, 1e+09] N/mm");
}

TEST_CASE("one name per parameter: cfreplay's option is the Python keyword in kebab case",
          "[params]") {
  int with_option = 0;
  for (const cf::ParamSpec& spec : cf::param_specs()) {
    if (spec.option == nullptr) continue;
    ++with_option;
    std::string kebab = std::string("--") + spec.python;
    for (char& c : kebab)
      if (c == '_') c = '-';
    CHECK(std::string(spec.option) == kebab);
    // A renamed option's old name is another name, never one in use.
    if (spec.deprecated_option != nullptr)
      for (const cf::ParamSpec& other : cf::param_specs())
        CHECK((other.option == nullptr || std::string(other.option) != spec.deprecated_option));
  }
  CHECK(with_option == 10);
  // The choices: one spelling for the options and the keywords.
  CHECK(std::string(cf::to_string(cf::FrictionDisplacement::kPerTick)) == "per_tick");
  CHECK(std::string(cf::to_string(cf::CentroidChoice::kVertexMean)) == "vertex_mean");
  CHECK(std::string(cf::to_string(cf::MomentReference::kAPoint)) == "a_point");
}

// The parameter table (cf/params.hpp): each real parameter's names, unit, range and help,
// written once, and validate().

#include <cf/params.hpp>

#include <cmath>
#include <cstdio>

namespace cf {

namespace {

#define CF_AT(path) [](Params& p) -> double& { return p.path; }

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

const char* to_string(FrictionDisplacement choice) {
  return choice == FrictionDisplacement::kPerTick ? "per_tick" : "stick_anchor";
}
const char* to_string(CentroidChoice choice) {
  return choice == CentroidChoice::kVolume ? "volume" : "vertex_mean";
}
const char* to_string(MomentReference choice) {
  return choice == MomentReference::kACentroid ? "a_centroid"
         : choice == MomentReference::kAPoint  ? "a_point"
                                               : "a_origin";
}

std::string ParamSpec::problem(double v) const {
  if (std::isfinite(v) && (lo_open ? v > lo : v >= lo) && v <= hi) return "";
  return std::string(path) + " = " + number(v) + " is outside " + (lo_open ? "(" : "[") +
         number(lo) + ", " + number(hi) + "]" + (*unit ? " " : "") + unit;
}

const std::vector<ParamSpec>& param_specs() {
  // Ranges: what the force model, detection and the proxy are defined for (a stiffness is a
  // divisor, so positive), and beyond that wide enough for any unit mistake to be caught.
  static const std::vector<ParamSpec> specs{
      {"mass_kg", "mass_kg", "--mass-kg", "kg", 0, 1e6, false, "m, mass of A", CF_AT(mass_kg),
       nullptr, "--mass"},
      {"gravity_N_per_kg", "gravity_N_per_kg", nullptr, "N/kg", -1e6, 1e6, false,
       "g, along -y of the world", CF_AT(gravity_N_per_kg)},
      {"contact_stiffness_N_per_mm", "contact_stiffness_N_per_mm", "--contact-stiffness-N-per-mm",
       "N/mm", 0, 1e9, true, "K of eq. (1)", CF_AT(contact_stiffness_N_per_mm),
       "stiffness_N_per_mm", "--stiffness"},
      {"kp_N_per_mm", "kp_N_per_mm", "--kp-N-per-mm", "N/mm", 0, 1e9, true, "K_p of eqs. (3)-(4)",
       CF_AT(kp_N_per_mm), nullptr, "--kp"},
      {"mu_static", "mu_static", "--mu-static", "", 0, 100, false,
       "static friction coefficient, mu of eqs. (2), (3), (6)", CF_AT(mu_static), nullptr, "--mu"},
      {"mu_kinetic", "mu_kinetic", "--mu-kinetic", "", 0, 100, false,
       "kinetic friction coefficient, mu_D of eq. (5)", CF_AT(mu_kinetic), nullptr, "--mu-d"},
      {"epsilon_mm", "epsilon_mm", "--epsilon-mm", "mm", 1e-6, 1e3, false,
       "contact threshold of eq. (1), detection and identification", CF_AT(epsilon_mm), nullptr,
       "--epsilon"},
      {"freedom_rank_tolerance", "freedom_rank_tolerance", nullptr, "", 0, 1, false,
       "relative singular-value tolerance of the freedoms' null space",
       CF_AT(freedom_rank_tolerance)},
      {"motion_angle_tolerance_rad", "motion_angle_tolerance_rad", nullptr, "rad", 0, M_PI, false,
       "'approximately along' angle of paper Fig. 10", CF_AT(motion_angle_tolerance_rad)},
      {"motion_noise_mm", "motion_noise_mm", nullptr, "mm", 0, 1e3, false,
       "pose changes below this are no motion", CF_AT(motion_noise_mm)},
      {"hold_fcy_threshold_N", "hold_fcy_threshold_N", "--hold-fcy-threshold-N", "N", 0, 1e6, false,
       "hold F_cy while it changes by less than this; 0: off", CF_AT(hold_fcy_threshold_N), nullptr,
       "--hold"},
      {"interpolation_time_constant_s", "interpolation_time_constant_s",
       "--interpolation-time-constant-s", "s", 0, 1e3, false,
       "low-pass time constant of the total contact force and moment; 0: off",
       CF_AT(interpolation_time_constant_s), nullptr, "--tau"},
      {"detection.deepest_contact_mm", "deepest_contact_mm", nullptr, "mm", 0, 1e6, false,
       "deepest interpenetration still a contact", CF_AT(detection.deepest_contact_mm),
       "max_penetration_mm"},
      {"detection.in_plane_tolerance_mm", "in_plane_tolerance_mm", nullptr, "mm", -1e6, 1e6, false,
       "how far outside an element a contact may fall; <= 0: epsilon_mm",
       CF_AT(detection.in_plane_tolerance_mm)},
      {"detection.angular_tolerance_rad", "angular_tolerance_rad", nullptr, "rad", -M_PI, M_PI,
       false, "fixed angular tolerance of near-parallel; <= 0: from each contact region",
       CF_AT(detection.angular_tolerance_rad)},
      {"detection.min_angular_tolerance_rad", "min_angular_tolerance_rad", nullptr, "rad", 0, M_PI,
       true, "least derived angular tolerance", CF_AT(detection.min_angular_tolerance_rad)},
      {"detection.max_angular_tolerance_rad", "max_angular_tolerance_rad", nullptr, "rad", 0, M_PI,
       true, "largest derived angular tolerance", CF_AT(detection.max_angular_tolerance_rad)},
      {"detection.dominance_penalty", "dominance_penalty", nullptr, "", 0, 1e6, false,
       "misfit added to a dominated contact", CF_AT(detection.dominance_penalty)},
      {"detection.dominance_fit", "dominance_fit", nullptr, "", 0, 1e6, false,
       "share of its tolerances within which a contact dominates", CF_AT(detection.dominance_fit)},
      {"detection.reuse_margin_mm", "reuse_margin_mm", nullptr, "mm", 0, 1e6, false,
       "margin of the element pairs kept between ticks; 0: off", CF_AT(detection.reuse_margin_mm)},
      {"identification.touch_distance_mm", "touch_distance_mm", nullptr, "mm", 0, 1e6, false,
       "contacts a CF must hold: those within this of touching",
       CF_AT(identification.touch_distance_mm)},
      {"proxy.coupling_stiffness_N_per_mm", "proxy_coupling_stiffness_N_per_mm",
       "--proxy-coupling-stiffness-N-per-mm", "N/mm", 0, 1e9, true,
       "the proxy coupling's stiffness", CF_AT(proxy.coupling_stiffness_N_per_mm),
       "proxy_stiffness_N_per_mm", "--proxy-stiffness"},
      {"proxy.coupling_damping_N_s_per_mm", "proxy_coupling_damping_N_s_per_mm",
       "--proxy-coupling-damping-N-s-per-mm", "N s/mm", 0, 1e9, false,
       "the proxy coupling's damping", CF_AT(proxy.coupling_damping_N_s_per_mm),
       "proxy_damping_N_s_per_mm", "--proxy-damping"},
      {"proxy.penetration_tolerance_mm", "proxy_penetration_tolerance_mm", nullptr, "mm", 0, 1e3,
       true, "deepest penetration of B the proxy is left with",
       CF_AT(proxy.penetration_tolerance_mm), "proxy_max_penetration_mm"},
      {"proxy.lookahead_epsilons", "proxy_lookahead_epsilons", nullptr, "", 1, 1e3, false,
       "how far a long translation is looked along at once, in epsilons; 1: off",
       CF_AT(proxy.lookahead_epsilons)},
  };
  return specs;
}

#undef CF_AT

void validate(const Params& p) {
  const auto fail = [](const std::string& why) { throw Error("cf::Params: parameter " + why); };
  for (const ParamSpec& s : param_specs())
    if (std::string why = s.problem(s.get(p)); !why.empty()) fail(why);
  const std::pair<const char*, int> counts[] = {
      {"identification.max_combinations", p.identification.max_combinations},
      {"proxy.max_substeps", p.proxy.max_substeps},
      {"proxy.solver_iterations", p.proxy.solver_iterations}};
  for (const auto& [name, n] : counts)
    if (n < 1) fail(std::string(name) + " = " + std::to_string(n) + " is below 1");
  if (!p.moment_point_A.allFinite()) fail("moment_point_A is not finite");
  if (!p.proxy.grip_point_A.allFinite()) fail("proxy.grip_point_A is not finite");
  if (p.mu_kinetic > p.mu_static)
    fail("mu_kinetic = " + number(p.mu_kinetic) + " is above mu_static = " + number(p.mu_static) +
         ": kinetic friction cannot exceed static friction");
  if (p.detection.min_angular_tolerance_rad > p.detection.max_angular_tolerance_rad)
    fail("detection.min_angular_tolerance_rad = " + number(p.detection.min_angular_tolerance_rad) +
         " is above detection.max_angular_tolerance_rad = " +
         number(p.detection.max_angular_tolerance_rad));
}

}  // namespace cf

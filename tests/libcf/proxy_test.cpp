// The proxy of section 6b of docs/spec.md (libcf/src/proxy/proxy.cpp) on the paper's cube against
// its L-block and against a thin plate: pressing into a face, an edge and the inner corner, sliding
// while pressed, a one-tick jump through a wall, letting go, the servo rate, and the proxy off as
// the paper's literal model.

#include <cf/detector.hpp>
#include <cf/renderer.hpp>

#include "fixtures.hpp"
#include "runtime_models.hpp"
#include "trajectories.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace {

// Default parameters: K = 2.3 N/mm, epsilon = 1 mm, m g = 4.9 N, mu = 0.7, mu_D = 0.08; the
// coupling's stiffness is K.
constexpr double kK = 2.3, kEps = 1.0, kWeight = 4.9, kMuD = 0.08;
// The proxy's allowed depth (ProxyParams::penetration_tolerance_mm) and the solver's residue:
// its sweeps stop when no constraint force moves the proxy by 1e-7 mm.
constexpr double kDelta = 0.01;
constexpr double kSolverForce_N = 1e-4;

const cf::CfGraph& cube_l_graph() {
  static const cf::CfGraph g =
      cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json");
  return g;
}

cf::Pose at(double x, double y, double z, double rot_z_deg = 0) {
  cf::Pose p;
  p.t_BA = {x, y, z};
  p.R_BA = Eigen::AngleAxisd(rot_z_deg * M_PI / 180, cf::Vec3::UnitZ()).toRotationMatrix();
  return p;
}

// The deepest interpenetration of A at pose X (mm, >= 0), by an independent detection.
double depth_at(const cf::CfGraph& g, const cf::Pose& X) {
  cf::ContactDetector det(g.model_a(), g.model_b());
  cf::ContactSet cs;
  det.detect(X, cs);
  double d = 0;
  for (const cf::ContactPc& c : cs) d = std::min(d, c.distance);
  return -d;
}

// Moves the device in a straight line from `from` to `to` (translation only) at 20 um per
// tick, then holds it there for `hold` ticks; returns the last result.
const cf::HapticResult& press(cf::HapticRenderer& r, double& t, const cf::Pose& from,
                              const cf::Pose& to, int hold = 20) {
  const cf::Vec3 d = to.t_BA - from.t_BA;
  const int n = std::max(1, static_cast<int>(std::ceil(d.norm() / 0.02)));
  const cf::HapticResult* res = nullptr;
  for (int i = 1; i <= n; ++i) {
    cf::Pose p = from;
    p.t_BA += d * (static_cast<double>(i) / n);
    res = &r.step(p, t += 0.001);
  }
  for (int i = 0; i < hold; ++i) res = &r.step(to, t += 0.001);
  return *res;
}

}  // namespace

TEST_CASE("pressing 1, 5 and 20 mm into a face, an edge and the inner corner", "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  struct Case {
    const char* what;
    cf::Pose surface;  // the device pose at which A just touches
    cf::Vec3 n_W;      // the contact normal (into A)
  };
  const double s2 = std::sqrt(2.0);
  const std::vector<Case> cases = {
      {"the floor under a face", at(70, 35, 40), cf::Vec3::UnitY()},
      {"the floor under an edge (cube turned 45 degrees)", at(70, 20 + 15 * s2, 40, 45),
       cf::Vec3::UnitY()},
      {"the inner corner, floor and wall", at(35, 35, 40), cf::Vec3(1, 1, 0) / s2},
  };
  for (const Case& c : cases) {
    SECTION(c.what) {
      // The CF at the surface, as the literal model identifies it there.
      cf::Params literal;
      literal.proxy.enabled = false;
      cf::HapticRenderer lit(g, literal);
      const cf::CfId surface_cf = lit.step(c.surface, 0.001).cf;
      REQUIRE(surface_cf.valid());
      double previous_push = -1e9;
      for (const double depth : {1.0, 5.0, 20.0}) {
        cf::HapticRenderer r(g);
        double t = 0;
        cf::Pose above = c.surface, inside = c.surface;
        above.t_BA += 2.0 * c.n_W;
        inside.t_BA -= depth * c.n_W;
        const double push_at_surface = press(r, t, above, c.surface).F_W.dot(c.n_W);
        const cf::HapticResult& res = press(r, t, c.surface, inside);
        CAPTURE(depth);
        REQUIRE(res.proxy != nullptr);
        CHECK(res.status == cf::RenderStatus::kOk);
        CHECK(res.cf == surface_cf);
        // The proxy stays on the surface: no deeper than delta, and where A touched.
        CHECK(depth_at(g, res.X_WP) <= kDelta);
        CHECK((res.X_WP.t_BA - c.surface.t_BA).norm() <= kDelta + 1e-9);
        // Past the surface the push along the normal grows by the coupling's K per mm, on top
        // of what the literal model gave at the surface (eq. (1)'s K epsilon, the weight and
        // the friction of the approach): it grows with depth.
        const double push = res.F_W.dot(c.n_W);
        CHECK(push - push_at_surface == Approx(kK * depth).margin(0.01 + kK * kDelta));
        CHECK(push > previous_push);
        previous_push = push;
        // The coupling is balanced by the constraint forces at rest.
        CHECK((res.proxy->F_coupling_W - res.proxy->F_constraint_W).norm() <= kSolverForce_N * 10);
        // Without the proxy the same pose renders nothing but the weight once it is deeper
        // than detection's deepest_contact_mm (1 mm): what the proxy is for.
        if (depth <= 1.0) continue;
        cf::HapticRenderer lit2(g, literal);
        double t2 = 0;
        const cf::HapticResult& l = press(lit2, t2, above, inside);
        CHECK(l.status == cf::RenderStatus::kNoContact);
        CHECK(l.F_W.isApprox(cf::Vec3(0, -kWeight, 0), 1e-12));
      }
    }
  }
}

TEST_CASE("sliding while pressed: the proxy sticks, then slides with kinetic friction", "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  const double pen = 2.0;  // mm below the floor's surface
  press(r, t, at(70, 37, 40), at(70, 35 - pen, 40));
  // Normal load at rest: K epsilon from eq. (1) plus the coupling's K pen.
  const double load = kK * (kEps + pen);
  // Sticking: a tangential offset of 0.5 mm pulls 1.15 N < mu (K pen) = 3.22 N.
  const cf::HapticResult& stick = press(r, t, at(70, 35 - pen, 40), at(69.5, 35 - pen, 40));
  CHECK(stick.X_WP.t_BA.x() == Approx(70).margin(1e-6));
  CHECK(stick.F_W.x() == Approx(kK * 0.5).margin(1e-3));
  // Sliding 10 mm further at 20 mm/s: the proxy trails the device, and the hand is pulled
  // back by kinetic friction on the whole load.
  const cf::HapticResult& slide = press(r, t, at(69.5, 35 - pen, 40), at(59.5, 35 - pen, 40), 0);
  CHECK(slide.cf.valid());
  CHECK(slide.X_WP.t_BA.y() == Approx(35).margin(kDelta));
  CHECK(slide.F_W.x() == Approx(kMuD * load).epsilon(0.01));
  CHECK(slide.X_WP.t_BA.x() - 59.5 == Approx(kMuD * kK * pen / kK).epsilon(0.01));
  CHECK(slide.F_W.y() == Approx(load - kWeight).margin(0.01));
  bool sliding = false;
  for (int j = 0; j < slide.proxy->num_contacts; ++j)
    sliding = sliding || slide.proxy->contacts[j].sliding;
  CHECK(sliding);
  // The PC's load is eq. (1)'s plus its constraint's: K (epsilon + pen).
  REQUIRE(slide.force->num_pcs == 1);
  CHECK(slide.force->pcs[0].F_cy + slide.constraint_load_N[0] == Approx(load).margin(0.01));
}

TEST_CASE("a pressed face that breaks away settles in a few solver sweeps", "[proxy]") {
  // Pressed 4 mm into the floor, the device moves 3 mm sideways in one tick: the coupling's
  // pull, K 3 = 6.9 N, exceeds static friction on the constraint load, mu K pen = 6.44 N.
  // Held at the static cones' edge, Gauss-Seidel trades a torsional pair of forces among the
  // four corners for its whole budget (this tick took 71 sweeps over 4 passes, 60 of them in
  // the first); the corners take kinetic bounds once they have held the static bound for four
  // sweeps (proxy.cpp), and settle in a few (19).
  const cf::CfGraph& g = cube_l_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  const double pen = 4.0;
  press(r, t, at(70, 37, 40), at(70, 35 - pen, 40));
  const cf::HapticResult& res = r.step(at(67, 35 - pen, 40), t += 0.001);
  CHECK(res.proxy->iterations <= 30);
  // It slides: kinetic friction on the whole load pulls the hand back; the proxy trails the
  // device by the kinetic friction of its constraint load (K pen) over the coupling's
  // stiffness; on the floor, and it does not turn (to the solver's residue, 1e-5 mm, over
  // A's size, 50 mm).
  const double load = kK * (kEps + pen);
  CHECK(res.F_W.x() == Approx(kMuD * load).epsilon(0.01));
  CHECK(res.X_WP.t_BA.x() - 67 == Approx(kMuD * kK * pen / kK).epsilon(0.01));
  CHECK(res.X_WP.t_BA.y() == Approx(35).margin(kDelta));
  CHECK(Eigen::AngleAxisd(res.X_WP.R_BA).angle() < 1e-5 / 50);
}

TEST_CASE("a region pressed harder and pulled within its new static limit sticks", "[proxy]") {
  // Pressed 2 mm in, then in one tick 4 mm in and 2.5 mm sideways: the pull, K 2.5 = 5.75 N,
  // is within static friction on the new constraint load, mu K 4 = 6.44 N, but not on the
  // old one (3.22 N). While the solve raises the loads, friction sits at mu_s times a partial
  // load: that must not count as breaking away.
  const cf::CfGraph& g = cube_l_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  press(r, t, at(70, 37, 40), at(70, 33, 40));
  const cf::HapticResult& res = r.step(at(67.5, 31, 40), t += 0.001);
  CHECK(res.X_WP.t_BA.x() == Approx(70).margin(1e-6));
  CHECK(res.X_WP.t_BA.y() == Approx(35).margin(kDelta));
  bool sliding = false;
  for (int j = 0; j < res.proxy->num_contacts; ++j)
    sliding = sliding || res.proxy->contacts[j].sliding;
  CHECK_FALSE(sliding);
}

TEST_CASE("with more point contacts than a solve holds, the nearest are kept and the rest counted",
          "[proxy]") {
  // Two faceted spheres (2,000 and 2,016 faces) with a 4 mm band: pressed together, the band
  // holds over a hundred point contacts (vertex-face and crossing edges), more than the
  // solve's ProxyResult::kMaxContacts. Pressing 6 mm in, the proxy must still not sink into
  // B: the nearest contacts are the ones that bind.
  namespace tm = cf::testmodels;
  const cf::CfGraph g = cf::CfGraph::from_parts(
      tm::faceted_sphere(30, 40, 50, cf::Vec3::Zero(), "sphere2000"),
      tm::faceted_sphere(50, 42, 48, cf::Vec3::Zero(), "sphere2016"), {}, {});
  cf::Params p;
  p.epsilon_mm = p.detection.deepest_contact_mm = 4.0;
  cf::HapticRenderer r(g, p);
  double t = 0;
  int most_dropped = 0;
  double deepest = 0;
  cf::ContactDetector det(g.model_a(), g.model_b(), p);  // sees as deep as the band
  cf::ContactSet cs;
  const cf::Vec3 dir = cf::Vec3(0.3, 1, 0.2).normalized();
  for (int i = 0; i <= 400; ++i) {
    cf::Pose X;
    X.t_BA = dir * (80 + 2 - 8.0 * i / 400);  // from 2 mm apart to 6 mm in
    const cf::HapticResult& res = r.step(X, t += 0.001);
    most_dropped = std::max(most_dropped, res.proxy->dropped_contacts);
    if (res.proxy->dropped_contacts > 0)
      CHECK(res.proxy->num_contacts == cf::ProxyResult::kMaxContacts);
    det.detect(res.X_WP, cs);
    for (const cf::ContactPc& c : cs) deepest = std::max(deepest, -c.distance);
  }
  // Out to 2 mm apart, then in to 6 mm deep in one tick: the swept passes with the band full.
  for (const double gap : {2.0, -6.0}) {
    cf::Pose X;
    X.t_BA = dir * (80 + gap);
    const cf::HapticResult& res = r.step(X, t += 0.001);
    det.detect(res.X_WP, cs);
    for (const cf::ContactPc& c : cs) deepest = std::max(deepest, -c.distance);
  }
  INFO("most point contacts left out of a solve: " << most_dropped);
  CHECK(most_dropped > 0);
  // The allowed depth (ProxyParams::penetration_tolerance_mm) over an independent detection.
  CHECK(deepest <= kDelta);
}

TEST_CASE("a jump of the device through a thin wall in one tick: the proxy stops at the near side",
          "[proxy]") {
  // A 2 mm plate, y in [0, 2], and the cube (30 mm) 0.5 mm above it.
  const cf::Polyhedron cube = cf::test::box(cf::Vec3(-15, -15, -15), cf::Vec3(15, 15, 15), "cube");
  const cf::Polyhedron plate = cf::test::box(cf::Vec3(-60, 0, -60), cf::Vec3(60, 2, 60), "plate");
  const int bottom = cf::test::face_with_plane(cube, -cf::Vec3::UnitY(), 15);
  const int top = cf::test::face_with_plane(plate, cf::Vec3::UnitY(), 2);
  REQUIRE(bottom >= 0);
  REQUIRE(top >= 0);
  std::vector<cf::CfRecord> cfs(1);
  cfs[0].pcs = cf::PcSet({cf::Pc{cf::PcType::kFF, bottom, top}});
  cfs[0].witness.t_BA = {0, 17, 0};
  const cf::CfGraph g = cf::CfGraph::from_parts(cube, plate, std::move(cfs), {});
  cf::HapticRenderer r(g);
  r.step(at(0, 17.5, 0), 0.001);
  // The device lands 20 mm below the plate: the cube wholly past it, touching nothing.
  const cf::HapticResult& res = r.step(at(5, -35, 3), 0.002);
  CHECK(res.X_WP.t_BA.y() == Approx(17).margin(kDelta));
  CHECK(depth_at(g, res.X_WP) <= kDelta);
  CHECK(res.cf == cf::CfId(0));
  CHECK(res.F_W.y() > 100);  // the coupling pulls the hand back up: K times 52 mm
  // The literal model sees nothing there.
  cf::Params literal;
  literal.proxy.enabled = false;
  cf::HapticRenderer lit(g, literal);
  lit.step(at(0, 17.5, 0), 0.001);
  CHECK(lit.step(at(5, -35, 3), 0.002).status == cf::RenderStatus::kNoContact);
}

TEST_CASE("letting go: the proxy follows the device out and the force is the weight alone",
          "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  press(r, t, at(70, 37, 40), at(70, 30, 40));
  const cf::HapticResult& out = press(r, t, at(70, 30, 40), at(70, 45, 40), 5);
  CHECK(out.status == cf::RenderStatus::kNoContact);
  CHECK(out.X_WP.t_BA == out.X_WD.t_BA);
  CHECK(out.X_WP.R_BA == out.X_WD.R_BA);
  CHECK_FALSE(out.proxy->constrained);
  CHECK(out.F_W == cf::Vec3(0, -kWeight, 0));
  CHECK(out.M_W == cf::Vec3::Zero());
}

TEST_CASE("the proxy's result does not depend on the servo rate (1 kHz against 10 kHz)",
          "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  // Device path over 1.5 s: down into the floor 3 mm, slide 15 mm along x, turn 10 degrees
  // about y while pressed, lift out.
  auto device = [](double t) {
    cf::Pose p = at(70, 37, 40);
    const double down = std::min(t / 0.3, 1.0) * 5.0;                   // to 3 mm inside
    const double slide = std::clamp((t - 0.3) / 0.6, 0.0, 1.0) * 15.0;  // 25 mm/s
    const double turn = std::clamp((t - 0.9) / 0.3, 0.0, 1.0) * 10.0;   // degrees
    const double up = std::clamp((t - 1.2) / 0.3, 0.0, 1.0) * 8.0;
    p.t_BA = {70 - slide, 37 - down + up, 40};
    p.R_BA = Eigen::AngleAxisd(turn * M_PI / 180, cf::Vec3::UnitY()).toRotationMatrix();
    return p;
  };
  auto run = [&](int rate_hz, std::vector<cf::Vec3>& F) {
    cf::HapticRenderer r(g);
    const int per_ms = rate_hz / 1000;
    for (int k = 1; k <= 1500 * per_ms; ++k) {
      const double t = static_cast<double>(k) / rate_hz;
      const cf::HapticResult& res = r.step(device(t), t);
      if (k % per_ms == 0) F.push_back(res.F_W);
    }
  };
  std::vector<cf::Vec3> slow, fast;
  run(1000, slow);
  run(10000, fast);
  REQUIRE(slow.size() == fast.size());
  // Compared while pressing, holding, breaking away and sliding (0 to 0.9 s) and once free
  // again (from 1.45 s): equal within 0.05 N, but for 0.5% of the ticks (the breakaway's
  // tick moves with the rate). Not while turning and unloading: there the proxy's
  // torsional and unloading stick-slip switches the force model's MT2 case (a: at rest,
  // largest static friction on eq. (1)'s load; c: moving, kinetic) on different ticks at the
  // two rates, a known limit (docs/force-model.md, "The proxy").
  int off = 0, compared = 0;
  double worst = 0;
  for (std::size_t i = 0; i < slow.size(); ++i) {
    const double t = static_cast<double>(i + 1) / 1000;
    if (t > 0.9 && t < 1.45) continue;
    ++compared;
    const double e = (slow[i] - fast[i]).norm();
    worst = std::max(worst, e);
    if (e > 0.05) ++off;
  }
  CAPTURE(worst);
  CHECK(compared == 951);
  CHECK(off <= compared / 200);
}

TEST_CASE("the proxy off is the paper's literal model; on, with no penetration, it changes nothing",
          "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  cf::Params off;
  off.proxy.enabled = false;
  cf::HapticRenderer lit(g, off), prox(g);
  int constrained = 0, compared = 0, differing = 0;
  for (const cf::testdata::Tick& k : cf::testdata::cube_lblock_ticks(CF_SOURCE_DIR)) {
    const cf::HapticResult& a = lit.step(k.X_WA, k.t_s);
    const cf::HapticResult& b = prox.step(k.X_WA, k.t_s);
    CHECK(a.proxy == nullptr);
    if (b.proxy->constrained) ++constrained;
    if (constrained > 0) continue;  // past a constrained tick the histories differ
    ++compared;
    if (!(a.F_W == b.F_W && a.M_W == b.M_W && a.cf == b.cf && a.motion == b.motion)) ++differing;
  }
  CHECK(compared > 1000);
  CHECK(differing == 0);
}

TEST_CASE("looking ahead along a long translation saves sub-steps and moves the proxy the same",
          "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  // A hand pressing 5 mm into the floor, sliding 15 mm (the pressed face breaks away and
  // releases 2.7 mm of coupling stretch in one tick), into the inner corner's wall, out;
  // then a jump of 30 mm along x in one tick, in free space.
  auto device = [](int k) {
    const double t = k / 1000.0;
    const double down = std::min(t / 0.3, 1.0) * 7.0;
    const double slide = std::clamp((t - 0.3) / 0.6, 0.0, 1.0) * 15.0;
    const double wall = std::clamp((t - 0.9) / 0.4, 0.0, 1.0) * 23.0;
    const double up = std::clamp((t - 1.3) / 0.3, 0.0, 1.0) * 20.0;
    cf::Pose p = at(70 - slide - wall, 37 - down + up, 40);
    if (k > 1600) p.t_BA.x() += 30;
    return p;
  };
  cf::Params off;
  off.proxy.lookahead_epsilons = 1;
  cf::HapticRenderer plain(g, off), looking(g);
  int passes_plain = 0, passes_looking = 0, most_plain = 0, most_looking = 0;
  double worst_N = 0, worst_mm = 0;
  for (int k = 1; k <= 1602; ++k) {
    const cf::HapticResult a = plain.step(device(k), k / 1000.0);
    const cf::HapticResult& b = looking.step(device(k), k / 1000.0);
    passes_plain += a.proxy->substeps;
    passes_looking += b.proxy->substeps;
    most_plain = std::max(most_plain, a.proxy->substeps);
    most_looking = std::max(most_looking, b.proxy->substeps);
    worst_N = std::max(worst_N, (a.F_W - b.F_W).norm());
    worst_mm = std::max(worst_mm, (a.X_WP.t_BA - b.X_WP.t_BA).norm());
  }
  CAPTURE(worst_N, worst_mm, passes_plain, passes_looking, most_plain, most_looking);
  // Every sub-step solves with the stages' own detection: the proxies agree to the solver's
  // stopping tolerance (1e-5 mm), the forces to the coupling's stiffness times it (2.3e-5 N).
  CHECK(worst_mm <= 1e-5);
  CHECK(worst_N <= 1e-4);
  CHECK(most_looking < most_plain);  // the jump: 37 sub-steps without, 10 with
  CHECK(passes_looking < passes_plain);
}

TEST_CASE("proxy parameters out of range are refused by name", "[proxy]") {
  const cf::CfGraph& g = cube_l_graph();
  cf::Params p;
  p.proxy.coupling_stiffness_N_per_mm = 0;
  CHECK_THROWS_WITH(
      cf::HapticRenderer(g, p),
      "cf::Params: parameter proxy.coupling_stiffness_N_per_mm = 0 is outside (0, 1e+09] N/mm");
  p = cf::Params();
  p.proxy.max_substeps = 0;
  CHECK_THROWS_WITH(cf::HapticRenderer(g, p),
                    "cf::Params: parameter proxy.max_substeps = 0 is below 1");
  p = cf::Params();
  p.proxy.coupling_damping_N_s_per_mm = -1;
  CHECK_THROWS_WITH(
      cf::HapticRenderer(g, p),
      Catch::Contains("proxy.coupling_damping_N_s_per_mm = -1 is outside [0, 1e+09] N s/mm"));
  p = cf::Params();
  p.proxy.lookahead_epsilons = 0.5;
  CHECK_THROWS_WITH(cf::HapticRenderer(g, p),
                    "cf::Params: parameter proxy.lookahead_epsilons = 0.5 is outside [1, 1000]");
}

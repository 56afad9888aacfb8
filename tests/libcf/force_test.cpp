// Contact force and moment with hand-computed values: paper eqs. (1)-(9) and the per-MT
// rules of section 4.4, with the readings of docs/spec.md, section 6 (docs/force-model.md).
//
// Scene: A is a 20 mm cube [0,20]^3 in its frame. B's faces are only named by index: the
// floor is the plane y = 0 (normal +y), walls are given per test. Defaults: K = 2.3 N/mm,
// K_p = 1.6 N/mm, mu = 0.7, mu_D = 0.08, eps = 1 mm, m g = 4.9 N along -y.

#include <cf/force.hpp>
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

namespace {

// Values are products of a few decimal numbers: agreement to 1e-9 N / N mm is exact up to
// round-off.
constexpr double kTol = 1e-9;

using cf::test::box;

const cf::Vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);

cf::ContactPc contact(cf::PcType type, int a, int b, double d, const cf::Vec3& p, const cf::Vec3& x,
                      const cf::Vec3& y) {
  cf::ContactPc c;
  c.pc = {type, a, b};
  c.distance = d;
  c.p_W = p;
  c.origin_W = p - d * y;
  c.R_WT.col(0) = x;
  c.R_WT.col(1) = y;
  c.R_WT.col(2) = x.cross(y);
  return c;
}

cf::Pose at(double x, double y, double z) {
  cf::Pose p;
  p.t_BA = {x, y, z};
  return p;
}

// A's bottom face (2) on the floor (B face 3), region centroid under A's (10, 0, 10).
cf::ContactPc floor_pc(const cf::Pose& pose) {
  return contact(cf::PcType::kFF, 2, 3, pose.t_BA.y(), pose.apply({10, 0, 10}), X, Y);
}
// A's +x face (4) against a wall x = wall_x facing -x (B face 5).
cf::ContactPc wall_pc(const cf::Pose& pose, double wall_x) {
  const cf::Vec3 p = pose.apply({20, 10, 10});
  return contact(cf::PcType::kFF, 4, 5, wall_x - p.x(), p, Y, -X);
}

cf::PriorMotion prior(cf::MotionType t, int gained = -1) {
  cf::PriorMotion p;
  p.type = t;
  p.gained = gained;
  return p;
}

double friction(const cf::PcForce& f) { return std::hypot(f.F_T.x(), f.F_T.z()); }

struct Fixture {
  cf::Polyhedron A = box({0, 0, 0}, {20, 20, 20});
  cf::Polyhedron B = box({-100, -20, -100}, {100, 0, 100});
};

}  // namespace

TEST_CASE("a cube resting face-down: MT2.a, eq. (1), gravity, moment", "[force]") {
  Fixture fx;
  cf::Params P;
  SECTION("moment about A's origin (paper eq. (9))") {
    cf::ForceModel model(fx.A, fx.B, P);
    const cf::Pose pose = at(0, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    model.step(pose, 0.000, &c, 1, prior(cf::MotionType::kMT1));
    const cf::ForceResult& r = model.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT2a));
    CHECK(r.motion == cf::MotionType::kMT2a);
    REQUIRE(r.num_pcs == 1);
    CHECK(r.pcs[0].regime == cf::Regime::kStick);
    CHECK(r.pcs[0].F_cy == Approx(1.15).margin(kTol));  // 2.3 * (1 - 0.5)
    CHECK(friction(r.pcs[0]) == Approx(0).margin(kTol));
    CHECK((r.F_contact_W - cf::Vec3(0, 1.15, 0)).norm() < kTol);
    CHECK((r.F_gravity_W - cf::Vec3(0, -4.9, 0)).norm() < kTol);
    CHECK((r.F_W - cf::Vec3(0, -3.75, 0)).norm() < kTol);
    // (10,0,10) x (0,1.15,0) + (10,10,10) x (0,-4.9,0) = (-11.5,0,11.5) + (49,0,-49)
    CHECK((r.M_W - cf::Vec3(37.5, 0, -37.5)).norm() < kTol);
    CHECK((r.M_A - r.M_W).norm() < kTol);  // R = I
  }
  SECTION("about a point the application chooses: M_q = M_origin - (q - origin) x F") {
    const cf::Pose pose = at(0, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    cf::ForceModel about_origin(fx.A, fx.B, P);
    about_origin.step(pose, 0.000, &c, 1, prior(cf::MotionType::kMT1));
    const cf::ForceResult r0 = about_origin.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT2a));
    P.moment_reference = cf::MomentReference::kAPoint;
    P.moment_point_A = cf::Vec3(3, 25, -7);  // any point fixed in A, here outside it
    cf::ForceModel about_q(fx.A, fx.B, P);
    about_q.step(pose, 0.000, &c, 1, prior(cf::MotionType::kMT1));
    const cf::ForceResult& rq = about_q.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT2a));
    const cf::Vec3 q_W = pose.apply(P.moment_point_A);
    CHECK((rq.reference_W - q_W).norm() < kTol);
    CHECK((rq.F_W - r0.F_W).norm() < kTol);
    CHECK((rq.M_W - (r0.M_W - (q_W - pose.t_BA).cross(r0.F_W))).norm() < kTol);
  }
  SECTION("about the centroid the moment vanishes") {
    P.moment_reference = cf::MomentReference::kACentroid;
    cf::ForceModel model(fx.A, fx.B, P);
    const cf::Pose pose = at(0, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    model.step(pose, 0.000, &c, 1, prior(cf::MotionType::kMT1));
    const cf::ForceResult& r = model.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT2a));
    CHECK(r.M_W.norm() < kTol);
  }
  SECTION("frames: A rotated 90 degrees about y reports A-frame vectors") {
    cf::ForceModel model(fx.A, fx.B, P);
    cf::Pose pose = at(0, 0.5, 20);
    pose.R_BA = Eigen::AngleAxisd(M_PI / 2, Y).toRotationMatrix();
    const cf::ContactPc c = contact(cf::PcType::kFF, 2, 3, 0.5, pose.apply({10, 0, 10}), X, Y);
    const cf::ForceResult& r = model.step(pose, 0, &c, 1, prior(cf::MotionType::kMT2a));
    CHECK((r.F_A - pose.R_BA.transpose() * r.F_W).norm() < kTol);
    CHECK((r.M_A - pose.R_BA.transpose() * r.M_W).norm() < kTol);
    CHECK(r.F_A.y() == Approx(-3.75).margin(kTol));
  }
}

TEST_CASE("guarded impact: eq. (2) inside the friction cone, eq. (5) outside", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  model.step(at(0, 1.6, 0), 0.000, nullptr, 0, prior(cf::MotionType::kNone));

  SECTION("inside: |tangential / normal| = 0.3 <= 0.7") {
    const cf::Pose pose = at(0.3, 0.6, 0);  // moved (0.3, -1, 0)
    const cf::ContactPc c = floor_pc(pose);
    const cf::ForceResult& r = model.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT1));
    CHECK(r.motion == cf::MotionType::kMT1);
    CHECK(r.pcs[0].regime == cf::Regime::kImpactStatic);
    CHECK(r.pcs[0].F_cy == Approx(0.92).margin(kTol));                // 2.3 * 0.4
    CHECK(r.pcs[0].F_T.x() == Approx(0.92 * 0.3 / -1).margin(kTol));  // F_cy a / b
    CHECK(r.pcs[0].F_T.z() == Approx(0).margin(kTol));
    // The stick anchor carries the impact friction into the next ticks (eq. (4)).
    const cf::ForceResult& r2 = model.step(pose, 0.002, &c, 1, prior(cf::MotionType::kMT2a));
    CHECK(r2.pcs[0].regime == cf::Regime::kStick);
    CHECK(r2.pcs[0].F_T.x() == Approx(-0.276).margin(kTol));
  }
  SECTION("outside: |tangential / normal| = 1 > 0.7: kinetic, mu_D F_cy against the motion") {
    const cf::Pose pose = at(1.0, 0.6, 0);
    const cf::ContactPc c = floor_pc(pose);
    const cf::ForceResult& r = model.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT1));
    CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
    CHECK(r.pcs[0].F_T.x() == Approx(-0.08 * 0.92).margin(kTol));
    CHECK(r.pcs[0].F_T.z() == Approx(0).margin(kTol));
  }
}

TEST_CASE("sliding on the floor: stick, then slip at the eq. (3) bound, then kinetic", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  double t = 0;
  auto tick = [&](double x) -> const cf::ForceResult& {
    const cf::Pose pose = at(x, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    t += 0.001;
    return model.step(pose, t, &c, 1, prior(cf::MotionType::kMT2a));
  };
  tick(0);
  tick(0);
  const double bound = 0.7 * 1.15 / 1.6;  // 0.503125 mm

  const cf::ForceResult& a = tick(0.25);
  CHECK(a.motion == cf::MotionType::kMT2a);
  CHECK(a.pcs[0].regime == cf::Regime::kStick);
  CHECK(a.pcs[0].s_mm == Approx(0.25).margin(kTol));
  CHECK(a.pcs[0].F_T.x() == Approx(-1.6 * 0.25).margin(kTol));

  const cf::ForceResult& b = tick(0.503);  // just inside the bound
  CHECK(b.pcs[0].regime == cf::Regime::kStick);
  CHECK(b.pcs[0].s_bound_mm == Approx(bound).margin(kTol));
  CHECK(b.pcs[0].F_T.x() == Approx(-1.6 * 0.503).margin(kTol));

  // Just past it: the PC slips. One f-f admits a pure rotation (spinning about its normal),
  // so this is case (c) with its only PC failing eq. (3): kinetic.
  const cf::ForceResult& c = tick(0.504);
  CHECK(c.motion == cf::MotionType::kMT2c);
  CHECK(c.pcs[0].regime == cf::Regime::kKinetic);
  CHECK(c.pcs[0].F_T.x() == Approx(-0.08 * 1.15).margin(kTol));

  for (double x : {0.6, 1.0, 3.0, 10.0}) {
    const cf::ForceResult& r = tick(x);
    CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
    CHECK(r.pcs[0].F_T.x() == Approx(-0.092).margin(kTol));
    CHECK(r.pcs[0].F_T.z() == Approx(0).margin(kTol));
  }
  // Stopping: the anchor trails at the bound, so static friction holds mu F_cy.
  const cf::ForceResult& s = tick(10.0);
  CHECK(s.motion == cf::MotionType::kMT2a);
  CHECK(s.pcs[0].regime == cf::Regime::kStick);
  CHECK(s.pcs[0].F_T.x() == Approx(-0.7 * 1.15).margin(kTol));
  // Easing back by 0.2 mm relaxes the spring.
  const cf::ForceResult& e = tick(9.8);
  CHECK(e.pcs[0].regime == cf::Regime::kStick);
  CHECK(e.pcs[0].F_T.x() == Approx(-1.6 * (bound - 0.2)).margin(1e-8));
}

TEST_CASE("the paper's literal per-tick s_pj makes slow sliding static", "[force]") {
  Fixture fx;
  cf::Params P;
  P.friction_displacement = cf::FrictionDisplacement::kPerTick;
  cf::ForceModel model(fx.A, fx.B, P);
  double t = 0;
  for (int i = 0; i < 10; ++i) {
    const cf::Pose pose = at(0.1 * i, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    t += 0.001;
    const cf::ForceResult& r = model.step(pose, t, &c, 1, prior(cf::MotionType::kMT2a));
    if (i > 0) {
      CHECK(r.pcs[0].regime == cf::Regime::kStick);
      CHECK(r.pcs[0].F_T.x() == Approx(-1.6 * 0.1).margin(1e-9));
    }
  }
}

TEST_CASE("MT2.b: sliding along the floor-wall line is kinetic at both PCs", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  double t = 0;
  const cf::ForceResult* r = nullptr;
  for (double z : {0.0, 0.0, 1.0, 2.0}) {
    const cf::Pose pose = at(0, 0.5, z);
    const cf::ContactPc cs[] = {floor_pc(pose), wall_pc(pose, 20.5)};
    t += 0.001;
    r = &model.step(pose, t, cs, 2, prior(cf::MotionType::kMT2a));
  }
  CHECK(r->motion == cf::MotionType::kMT2b);
  CHECK_FALSE(r->freedoms.pure_rotation);
  CHECK(r->pcs[0].regime == cf::Regime::kKinetic);
  CHECK(r->pcs[1].regime == cf::Regime::kKinetic);
  CHECK((r->F_contact_W - cf::Vec3(-1.15, 1.15, -0.184)).norm() < kTol);
  CHECK((r->F_W - cf::Vec3(-1.15, 1.15 - 4.9, -0.184)).norm() < kTol);
}

TEST_CASE("MT2.a second situation: tipping about an axis the CF does not allow (Fig. 10-i)",
          "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  cf::Pose p0 = at(0, 0.5, 0);
  const cf::ContactPc c0 = floor_pc(p0);
  model.step(p0, 0.000, &c0, 1, prior(cf::MotionType::kMT2a));
  // Tip by 0.5 rad about x through A's origin: the face centroid moves 1.22 mm in z (beyond
  // the 0.503 mm bound); the test keeps feeding f-f at 0.5 mm, as a pose of the virtual
  // object that cannot physically happen with the CF kept.
  cf::Pose p1 = p0;
  p1.R_BA = Eigen::AngleAxisd(0.5, X).toRotationMatrix();
  cf::ContactPc c1 = floor_pc(p1);
  c1.p_W = p1.apply({10, 0, 10});
  const cf::ForceResult& r = model.step(p1, 0.001, &c1, 1, prior(cf::MotionType::kMT2a));
  CHECK(r.motion == cf::MotionType::kMT2a);
  CHECK_FALSE(r.check.along);
  CHECK(r.pcs[0].regime == cf::Regime::kMaxStatic);  // eq. (6)
  CHECK(friction(r.pcs[0]) == Approx(0.7 * 1.15).margin(kTol));
}

TEST_CASE("MT2.c: rotation about a contact edge keeps the edge static, the face slides",
          "[force]") {
  // A's edge 9 (x = 20, y = 0, along z) on the floor, A's +z face (1) on a wall z = 20.5
  // facing -z. A turns about the edge line (20, 0.5, z) of the world.
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  auto pose_at = [](double theta) {
    cf::Pose p;
    p.R_BA = Eigen::AngleAxisd(theta, Z).toRotationMatrix();
    p.t_BA = cf::Vec3(20, 0.5, 0) - p.R_BA * cf::Vec3(20, 0, 0);
    return p;
  };
  auto contacts = [](const cf::Pose& p, cf::ContactPc* cs) {
    cs[0] = contact(cf::PcType::kFF, 1, 0, 20.5 - 20, p.apply({10, 10, 20}), X, -Z);
    cs[1] = contact(cf::PcType::kEF, 9, 3, 0.5, p.apply({20, 0, 10}), X, Y);
  };
  cf::ContactPc cs[2];
  const cf::Pose p0 = pose_at(-0.1);
  contacts(p0, cs);
  model.step(p0, 0.000, cs, 2, prior(cf::MotionType::kMT2a));
  const cf::Pose p1 = pose_at(-0.15);
  contacts(p1, cs);
  const cf::ForceResult& r = model.step(p1, 0.001, cs, 2, prior(cf::MotionType::kMT2a));
  CHECK(r.check.along);
  CHECK(r.freedoms.pure_rotation);
  CHECK(r.motion == cf::MotionType::kMT2c);
  // The face centroid is 10 sqrt(2) mm from the edge: it moved 2 * 14.142 * sin(0.025) mm.
  CHECK(r.pcs[0].s_mm == Approx(2 * 10 * std::sqrt(2.0) * std::sin(0.025)).epsilon(1e-9));
  CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
  CHECK(friction(r.pcs[0]) == Approx(0.08 * 1.15).margin(kTol));
  const cf::Vec3 moved = p1.apply({10, 10, 20}) - p0.apply({10, 10, 20});
  CHECK(r.pcs[0].F_W.dot(moved) < 0);  // opposes the motion
  CHECK(r.pcs[1].s_mm == Approx(0).margin(1e-9));
  CHECK(r.pcs[1].regime == cf::Regime::kStick);
  CHECK(friction(r.pcs[1]) == Approx(0).margin(1e-8));
}

TEST_CASE("MT4: gaining a wall PC inside and outside its friction cone", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  const cf::Pose p0 = at(0, 0.5, 0);
  const cf::ContactPc f0 = floor_pc(p0);
  model.step(p0, 0.000, &f0, 1, prior(cf::MotionType::kMT1));
  model.step(p0, 0.001, &f0, 1, prior(cf::MotionType::kMT2a));
  const cf::PcSet before({f0.pc});

  SECTION("inside: the new PC by eq. (2), the floor by eq. (4)") {
    const cf::Pose p1 = at(0.2, 0.5, 0.05);
    const cf::ContactPc cs[] = {floor_pc(p1), wall_pc(p1, 20.7)};
    const cf::PriorMotion pm = cf::classify_prior_motion(before, cf::PcSet({cs[0].pc, cs[1].pc}));
    REQUIRE(pm.type == cf::MotionType::kMT4);
    REQUIRE(pm.gained == 1);
    const cf::ForceResult& r = model.step(p1, 0.002, cs, 2, pm);
    CHECK(r.pcs[1].gained);
    CHECK(r.pcs[1].regime == cf::Regime::kImpactStatic);
    CHECK(r.pcs[1].F_T.z() == Approx(1.15 * 0.05 / -0.2).margin(kTol));
    CHECK(r.pcs[0].regime == cf::Regime::kStick);
    CHECK((r.F_contact_W - cf::Vec3(-0.32 - 1.15, 1.15, -0.08 - 0.2875)).norm() < kTol);

    SECTION("then MT5: losing the wall, the floor stays static while eq. (3) holds") {
      const cf::Pose p2 = at(-0.4, 0.5, 0.05);
      const cf::ContactPc c2 = floor_pc(p2);
      const cf::PriorMotion pm5 =
          cf::classify_prior_motion(cf::PcSet({cs[0].pc, cs[1].pc}), cf::PcSet({c2.pc}));
      REQUIRE(pm5.type == cf::MotionType::kMT5);
      const cf::ForceResult& r5 = model.step(p2, 0.003, &c2, 1, pm5);
      CHECK(r5.motion == cf::MotionType::kMT5);
      CHECK(r5.pcs[0].regime == cf::Regime::kStick);
      CHECK(r5.pcs[0].F_T.x() == Approx(-1.6 * -0.4).margin(kTol));
      CHECK(r5.pcs[0].F_T.z() == Approx(-1.6 * 0.05).margin(kTol));
    }
    SECTION("then MT5 with a long slide: kinetic along the anchor's trailing stretch") {
      const cf::Pose p2 = at(-1.0, 0.5, 0.05);
      const cf::ContactPc c2 = floor_pc(p2);
      const cf::ForceResult& r5 = model.step(p2, 0.003, &c2, 1, prior(cf::MotionType::kMT5));
      CHECK(r5.pcs[0].regime == cf::Regime::kKinetic);
      // The stretch (0.2, 0.05) from the anchor reaches the bound L = mu F_cy / K_p at a share
      // t of this tick's travel (-1.2, 0); over the rest the dragged anchor's stretch turns
      // towards the motion as a tractrix: tan(phi / 2) shrinks by e^(-travel / L).
      const double L = 0.7 * 1.15 / 1.6;
      const double t = (0.2 + std::sqrt(L * L - 0.05 * 0.05)) / 1.2;
      const double phi0 = std::atan2(0.05, 1.2 * t - 0.2);
      const double phi1 = 2 * std::atan(std::tan(phi0 / 2) * std::exp(-(1 - t) * 1.2 / L));
      CHECK(r5.pcs[0].F_T.x() == Approx(0.08 * 1.15 * std::cos(phi1)).margin(kTol));
      CHECK(std::abs(r5.pcs[0].F_T.z()) == Approx(0.08 * 1.15 * std::sin(phi1)).margin(kTol));
    }
  }
  SECTION("outside: every PC kinetic") {
    const cf::Pose p1 = at(0.2, 0.5, 0.3);
    const cf::ContactPc cs[] = {floor_pc(p1), wall_pc(p1, 20.7)};
    const cf::ForceResult& r = model.step(p1, 0.002, cs, 2, prior(cf::MotionType::kMT4, 1));
    CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
    CHECK(r.pcs[1].regime == cf::Regime::kKinetic);
    const cf::Vec3 dir = cf::Vec3(0.2, 0, 0.3).normalized();
    CHECK((r.pcs[0].F_W - (cf::Vec3(0, 1.15, 0) - 0.092 * dir)).norm() < kTol);
    CHECK((r.pcs[1].F_W - cf::Vec3(-1.15, 0, -0.092)).norm() < kTol);
  }
}

TEST_CASE("MT3: a face tips onto its edge (pure rotation possible) or cannot", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  const cf::Pose p0 = at(0, 0.5, 0);
  const cf::ContactPc f0 = floor_pc(p0);
  model.step(p0, 0.000, &f0, 1, prior(cf::MotionType::kMT2a));

  SECTION("f-f -> e-f: the edge can pivot: the new edge PC is static") {
    cf::Pose p1;
    p1.R_BA = Eigen::AngleAxisd(-0.02, Z).toRotationMatrix();
    p1.t_BA = cf::Vec3(20, 0.5, 0) - p1.R_BA * cf::Vec3(20, 0, 0);
    const cf::ContactPc e1 = contact(cf::PcType::kEF, 9, 3, 0.5, p1.apply({20, 0, 10}), X, Y);
    const cf::PriorMotion pm = cf::classify_prior_motion(cf::PcSet({f0.pc}), cf::PcSet({e1.pc}));
    REQUIRE(pm.type == cf::MotionType::kMT3);
    const cf::ForceResult& r = model.step(p1, 0.001, &e1, 1, pm);
    CHECK(r.freedoms.pure_rotation);
    CHECK(r.motion == cf::MotionType::kMT3);
    CHECK(r.pcs[0].regime == cf::Regime::kStick);
    CHECK(r.pcs[0].F_T.y() == Approx(1.15).margin(kTol));
  }
  SECTION("no pure rotation keeps {e-f, f-f wall}: kinetic") {
    const cf::Pose p1 = at(0.3, 0.5, 0);
    const cf::ContactPc cs[] = {contact(cf::PcType::kEF, 9, 3, 0.5, p1.apply({20, 0, 10}), X, Y),
                                wall_pc(p1, 20.5)};
    const cf::ForceResult& r = model.step(p1, 0.001, cs, 2, prior(cf::MotionType::kMT3));
    CHECK_FALSE(r.freedoms.pure_rotation);
    CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
    CHECK(r.pcs[1].regime == cf::Regime::kKinetic);
    CHECK(r.pcs[0].F_T.x() == Approx(-0.092).margin(kTol));
  }
}

TEST_CASE("conservative rendering: dominated interpretations do not add up", "[force]") {
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  const cf::Pose p0 = at(0, 0.5, 0);
  // f-f of the bottom face and e-f of its edge 9 on the same floor: the edge bounds the
  // face, so the f-f dominates it.
  const cf::ContactPc cs[] = {floor_pc(p0),
                              contact(cf::PcType::kEF, 9, 3, 0.5, {20, 0.5, 10}, X, Y)};
  model.step(p0, 0.000, cs, 2, prior(cf::MotionType::kNone), true);
  const cf::Pose p1 = at(1, 0.5, 0);
  const cf::ContactPc cs1[] = {floor_pc(p1),
                               contact(cf::PcType::kEF, 9, 3, 0.5, {21, 0.5, 10}, X, Y)};
  const cf::ForceResult& r = model.step(p1, 0.001, cs1, 2, prior(cf::MotionType::kMT2a), true);
  CHECK(r.conservative);
  CHECK(r.motion == cf::MotionType::kNone);
  REQUIRE(r.num_pcs == 1);
  CHECK(r.pcs[0].pc.type == cf::PcType::kFF);
  CHECK(r.pcs[0].regime == cf::Regime::kKinetic);
  CHECK((r.F_contact_W - cf::Vec3(-0.092, 1.15, 0)).norm() < kTol);
}

TEST_CASE("smoothing: F_cy hold deadband and rate-independent interpolation", "[force]") {
  Fixture fx;
  SECTION("hold") {
    cf::Params P;
    P.hold_fcy_threshold_N = 0.05;
    cf::ForceModel model(fx.A, fx.B, P);
    auto tick = [&](double y, double t) -> double {
      const cf::Pose pose = at(0, y, 0);
      const cf::ContactPc c = floor_pc(pose);
      return model.step(pose, t, &c, 1, prior(cf::MotionType::kMT2a)).pcs[0].F_cy;
    };
    CHECK(tick(0.5, 0.000) == Approx(1.15).margin(kTol));
    CHECK(tick(0.49, 0.001) == Approx(1.15).margin(kTol));   // change 0.023 N: held
    CHECK(tick(0.48, 0.002) == Approx(1.15).margin(kTol));   // 0.046 N from the held value
    CHECK(tick(0.47, 0.003) == Approx(1.219).margin(kTol));  // 0.069 N: updated
  }
  SECTION("interpolation") {
    cf::Params P;
    P.interpolation_time_constant_s = 0.01;
    cf::ForceModel model(fx.A, fx.B, P);
    model.step(at(0, 2, 0), 0.000, nullptr, 0, prior(cf::MotionType::kNone));
    const cf::Pose pose = at(0, 0.5, 0);
    const cf::ContactPc c = floor_pc(pose);
    const cf::ForceResult& r = model.step(pose, 0.001, &c, 1, prior(cf::MotionType::kMT1));
    CHECK(r.F_contact_W.y() == Approx(1.15 * (1 - std::exp(-0.1))).margin(kTol));
  }
}

TEST_CASE("friction never exceeds mu F_cy over random motions", "[force]") {
  Fixture fx;
  for (auto mode : {cf::FrictionDisplacement::kStickAnchor, cf::FrictionDisplacement::kPerTick}) {
    cf::Params P;
    P.friction_displacement = mode;
    cf::ForceModel model(fx.A, fx.B, P);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> step(-0.4, 0.4), depth(0.0, 0.99);
    std::uniform_int_distribution<int> pick(0, 4);
    cf::Pose pose = at(0, 0.5, 0);
    cf::PcSet prev;
    int checked = 0;
    for (int i = 0; i < 5000; ++i) {
      pose.t_BA += cf::Vec3(step(rng), 0, step(rng));
      pose.t_BA.y() = depth(rng);
      const int what = pick(rng);  // 0: no contact, 1-2: floor, 3-4: floor + wall
      cf::ContactPc cs[2];
      int n = 0;
      if (what >= 1) cs[n++] = floor_pc(pose);
      if (what >= 3) cs[n++] = wall_pc(pose, pose.apply({20, 10, 10}).x() + depth(rng));
      cf::PcSet cur;
      for (int k = 0; k < n; ++k) cur.insert(cs[k].pc);
      const cf::ForceResult& r =
          model.step(pose, 0.001 * i, cs, n, cf::classify_prior_motion(prev, cur));
      for (int k = 0; k < r.num_pcs; ++k) {
        CHECK(friction(r.pcs[k]) <= 0.7 * r.pcs[k].F_cy * (1 + 1e-12) + 1e-12);
        ++checked;
      }
      prev = cur;
    }
    CHECK(checked > 4000);
  }
}

TEST_CASE("a tick of kMaxPcs PCs that all differ from the last tick's reuses the stale slots",
          "[force]") {
  // 16 v-f contacts, then 16 others: the slots of the first tick's PCs must be taken over
  // (they used to be freed only after the new PCs asked for slots).
  Fixture fx;
  cf::ForceModel model(fx.A, fx.B);
  const cf::Pose pose = at(0, 0.5, 0);
  for (int tick = 0; tick < 3; ++tick) {
    std::vector<cf::ContactPc> cs;
    for (int v = 0; v < 8; ++v)
      for (int f = 0; f < 2; ++f)
        cs.push_back(contact(cf::PcType::kVF, v, 2 * tick + f, 0.5,
                             pose.apply(fx.A.vertex(cf::VertexId(v)).p), X, Y));
    REQUIRE(static_cast<int>(cs.size()) == cf::ForceResult::kMaxPcs);
    const cf::ForceResult& r =
        model.step(pose, 0.001 * (tick + 1), cs.data(), static_cast<int>(cs.size()),
                   prior(cf::MotionType::kMT2a));
    CHECK(r.num_pcs == cf::ForceResult::kMaxPcs);
    CHECK_FALSE(r.truncated);
    // Each contact 0.5 mm into the band: K (epsilon - 0.5) = 1.15 N along +y, 16 of them.
    CHECK(r.F_contact_W.y() == Approx(16 * 1.15).margin(1e-9));
  }
}

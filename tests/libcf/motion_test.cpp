// Freedoms of CFs from the contact constraints, the "approximately along" test of paper
// Fig. 10, and the prior-motion classification of paper section 4.2.

#include <cf/motion.hpp>
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <optional>
#include <string>

#include <cmath>

namespace {

// Round-off of 6x6 eigen decompositions of unit-scale matrices.
constexpr double kTol = 1e-9;

using cf::test::box;

cf::ContactPc contact(cf::PcType type, int a, int b, const cf::Vec3& p, const cf::Vec3& x,
                      const cf::Vec3& y) {
  cf::ContactPc c;
  c.pc = {type, a, b};
  c.distance = 0;
  c.p_W = p;
  c.origin_W = p;
  c.R_WT.col(0) = x;
  c.R_WT.col(1) = y;
  c.R_WT.col(2) = x.cross(y);
  return c;
}

const cf::Vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);

}  // namespace

TEST_CASE("freedoms of single PCs follow from their contact constraints", "[motion]") {
  // A: 20 mm cube at the origin; B: a floor slab (top face 3 at y = 0) with walls
  // elsewhere irrelevant here. Pose identity: A sits on the floor.
  const cf::Polyhedron A = box({0, 0, 0}, {20, 20, 20});
  const cf::Polyhedron B = box({-100, -20, -100}, {100, 0, 100});
  const cf::Params P;
  const cf::Pose pose;

  SECTION("v-f: 5 freedoms, 2 translations, rotations about the vertex") {
    const cf::ContactPc c = contact(cf::PcType::kVF, 0, 3, {0, 0, 0}, X, Y);
    const cf::Freedoms f = cf::compute_freedoms(&c, 1, A, B, pose, P);
    CHECK(f.num_constraints == 1);
    CHECK(f.dof == 5);
    CHECK(f.translation_dof == 2);
    CHECK(f.pure_rotation);
  }
  SECTION("e-f: 4 freedoms, 2 translations, rotation about the edge or the normal") {
    const cf::ContactPc c = contact(cf::PcType::kEF, 9, 3, {20, 0, 10}, X, Y);
    const cf::Freedoms f = cf::compute_freedoms(&c, 1, A, B, pose, P);
    CHECK(f.dof == 4);
    CHECK(f.translation_dof == 2);
    CHECK(f.pure_rotation);
  }
  SECTION("f-f: 3 freedoms, 2 translations, spinning about the normal only") {
    const cf::ContactPc c = contact(cf::PcType::kFF, 2, 3, {10, 0, 10}, X, Y);
    const cf::Freedoms f = cf::compute_freedoms(&c, 1, A, B, pose, P);
    CHECK(f.num_constraints == 3);
    CHECK(f.dof == 3);
    CHECK(f.translation_dof == 2);
    REQUIRE(f.pure_rotation);
    CHECK(std::abs(f.rotation_axis_W.dot(Y)) == Approx(1).margin(kTol));
  }
}

TEST_CASE("freedoms of multi-PC CFs: corner, edge-and-wall, three faces", "[motion]") {
  const cf::Polyhedron A = box({0, 0, 0}, {20, 20, 20});
  const cf::Polyhedron B = box({-100, -20, -100}, {100, 0, 100});  // only its indices matter
  const cf::Params P;
  const cf::Pose pose;
  const cf::ContactPc floor = contact(cf::PcType::kFF, 2, 3, {10, 0, 10}, X, Y);
  // Wall x = 20 facing -x, touching A's +x face (4).
  const cf::ContactPc wall = contact(cf::PcType::kFF, 4, 5, {20, 10, 10}, Y, -X);
  // Wall z = 20 facing -z touching A's +z face (1).
  const cf::ContactPc back = contact(cf::PcType::kFF, 1, 0, {10, 10, 20}, X, -Z);

  SECTION("floor + wall: only sliding along their common line") {
    const cf::ContactPc cs[] = {floor, wall};
    const cf::Freedoms f = cf::compute_freedoms(cs, 2, A, B, pose, P);
    CHECK(f.dof == 1);
    CHECK(f.translation_dof == 1);
    CHECK_FALSE(f.pure_rotation);
    CHECK(std::abs(f.basis.col(0).head<3>().dot(Z)) == Approx(1).margin(kTol));
  }
  SECTION("floor + wall + back wall: fixed") {
    const cf::ContactPc cs[] = {floor, wall, back};
    const cf::Freedoms f = cf::compute_freedoms(cs, 3, A, B, pose, P);
    CHECK(f.dof == 0);
    CHECK(f.translation_dof == 0);
    CHECK_FALSE(f.pure_rotation);
  }
  SECTION("edge on the floor + face on the back wall: rotation about the contact edge") {
    const cf::ContactPc edge = contact(cf::PcType::kEF, 9, 3, {20, 0, 10}, X, Y);
    const cf::ContactPc cs[] = {edge, back};
    const cf::Freedoms f = cf::compute_freedoms(cs, 2, A, B, pose, P);
    CHECK(f.dof == 2);  // slide along x, rotate about the edge
    CHECK(f.translation_dof == 1);
    REQUIRE(f.pure_rotation);
    CHECK(std::abs(f.rotation_axis_W.dot(Z)) == Approx(1).margin(kTol));
    // Instantaneously, any axis parallel to the edge in the plane x = 20 keeps both PCs (it
    // is the rotation about the edge plus the sliding along x); the edge is one of them.
    CHECK(f.rotation_point_W.x() == Approx(20).margin(1e-6));
  }
}

TEST_CASE("a pose change is approximately along the freedoms or not (paper Fig. 10)", "[motion]") {
  const cf::Polyhedron A = box({0, 0, 0}, {20, 20, 20});
  const cf::Polyhedron B = box({-100, -20, -100}, {100, 0, 100});
  const cf::Params P;
  const cf::ContactPc floor = contact(cf::PcType::kFF, 2, 3, {10, 0, 10}, X, Y);
  const cf::Pose prev;
  const cf::Freedoms f = cf::compute_freedoms(&floor, 1, A, B, prev, P);

  SECTION("sliding on the floor with a little pressing is along") {
    cf::Pose cur;
    cur.t_BA = {0.5, -0.01, 0.2};
    const cf::MotionCheck m = cf::check_motion(f, prev, cur, P);
    CHECK(m.moved);
    CHECK(m.along);
    CHECK(m.twist_angle_rad == Approx(std::atan(0.01 / std::hypot(0.5, 0.2))).margin(1e-9));
  }
  SECTION("pushing straight into the floor is not a possible motion") {
    cf::Pose cur;
    cur.t_BA = {0, -0.05, 0};
    const cf::MotionCheck m = cf::check_motion(f, prev, cur, P);
    CHECK_FALSE(m.along);
    CHECK(m.twist_angle_rad == Approx(M_PI / 2).margin(1e-9));
  }
  SECTION("tipping about a horizontal axis is not along the possible rotation axes (Fig. 10-i)") {
    cf::Pose cur;
    cur.R_BA = Eigen::AngleAxisd(0.01, X).toRotationMatrix();
    const cf::MotionCheck m = cf::check_motion(f, prev, cur, P);
    CHECK_FALSE(m.along);
    CHECK(m.rotation_angle_rad == Approx(M_PI / 2).margin(1e-6));
  }
  SECTION("no motion at all passes") {
    const cf::MotionCheck m = cf::check_motion(f, prev, prev, P);
    CHECK_FALSE(m.moved);
    CHECK(m.along);
  }
}

TEST_CASE("prior motion from the previous and current PC sets (paper section 4.2)", "[motion]") {
  const cf::Pc ff{cf::PcType::kFF, 2, 3}, ef{cf::PcType::kEF, 9, 3}, wall{cf::PcType::kFF, 4, 5};
  const cf::PcSet none;
  const cf::PcSet s_ff({ff}), s_ef({ef}), s_ff_wall({ff, wall});

  CHECK(cf::classify_prior_motion(none, none).type == cf::MotionType::kNone);
  CHECK(cf::classify_prior_motion(none, s_ff).type == cf::MotionType::kMT1);
  CHECK(cf::classify_prior_motion(s_ff, s_ff).type == cf::MotionType::kMT2a);
  CHECK(cf::classify_prior_motion(s_ff, s_ef).type == cf::MotionType::kMT3);
  const cf::PriorMotion gain = cf::classify_prior_motion(s_ff, s_ff_wall);
  CHECK(gain.type == cf::MotionType::kMT4);
  REQUIRE(gain.gained >= 0);
  CHECK(s_ff_wall[gain.gained] == wall);
  CHECK(cf::classify_prior_motion(s_ff_wall, s_ff).type == cf::MotionType::kMT5);
  CHECK(cf::classify_prior_motion(s_ff_wall, none).type == cf::MotionType::kNone);

  CHECK(std::string(cf::to_string(cf::MotionType::kMT2c)) == "MT2.c");
  CHECK(std::string(cf::to_string(cf::MotionType::kNone)) == "none");
}

TEST_CASE(
    "several PCs broken at once are MT5 through the graph (docs/spec.md, section 4: lose is any "
    "proper subset)",
    "[motion]") {
  // The cube seated in the corner block's three walls leaving two of them in one tick: the
  // graph lists single losses; the run time derives the double one from the PC sets.
  const cf::CfGraph g =
      cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/cube_corner_block.json");
  std::optional<cf::CfId> seat, one;
  for (std::size_t i = 0; i < g.num_cfs() && !seat; ++i)
    if (g.cf(cf::CfId(static_cast<std::int32_t>(i))).pcs.size() == 3) {
      const cf::PcSet& s = g.cf(cf::CfId(static_cast<std::int32_t>(i))).pcs;
      for (int k = 0; k < 3 && !one; ++k)
        if (const auto id = g.find(cf::PcSet({s[k]}))) {
          seat = cf::CfId(static_cast<std::int32_t>(i));
          one = *id;
        }
    }
  REQUIRE(seat);
  REQUIRE(one);
  const cf::PcSet& three = g.cf(*seat).pcs;
  const cf::PcSet& single = g.cf(*one).pcs;
  bool listed = false;
  for (const cf::Transition& tr : g.out_transitions(*seat)) listed = listed || tr.to == *one;
  CHECK_FALSE(listed);  // two PCs lost: not among the graph's transitions
  const cf::PriorMotion pm = cf::classify_prior_motion(three, single, &g, *seat, *one);
  CHECK(pm.type == cf::MotionType::kMT5);
  CHECK(pm.transition_in_graph);
  // A change together with a loss is still no transition of the graph.
  const cf::PriorMotion other = cf::classify_prior_motion(single, three, &g, *one, *seat);
  CHECK_FALSE(other.transition_in_graph);
}

TEST_CASE("freedoms from constraint points: the relation the generator and the run time share",
          "[motion]") {
  const cf::Params P;
  // Three points of a floor (normal +y): translations in the floor and the spin about y.
  const cf::ConstraintPoint floor[] = {{{0, 0, 0}, Y}, {{20, 0, 0}, Y}, {{0, 0, 20}, Y}};
  const cf::Freedoms f = cf::freedoms_from_points(floor, 3, {10, 10, 10}, 20.0, P);
  CHECK(f.dof == 3);
  CHECK(f.translation_dof == 2);
  CHECK(f.pure_rotation);
  CHECK(std::abs(f.rotation_axis_W.dot(Y)) == Approx(1.0).margin(kTol));
  // Two crossing contacts (a vertex on the floor, another on a wall, normal +x): 4 freedoms,
  // the translation along z among them.
  const cf::ConstraintPoint two[] = {{{0, 0, 0}, Y}, {{-10, 5, 0}, X}};
  const cf::Freedoms g = cf::freedoms_from_points(two, 2, {0, 10, 0}, 20.0, P);
  CHECK(g.dof == 4);
  CHECK(g.translation_dof == 1);
  // No constraint: every twist.
  const cf::Freedoms free = cf::freedoms_from_points(nullptr, 0, {0, 0, 0}, 20.0, P);
  CHECK(free.dof == 6);
  CHECK(free.translation_dof == 3);
}

TEST_CASE("freedoms from constraint points: bad arguments are refused with the reason",
          "[motion]") {
  const cf::Params P;
  cf::ConstraintPoint many[cf::Freedoms::kMaxRows + 1];
  CHECK_THROWS_WITH(cf::freedoms_from_points(many, cf::Freedoms::kMaxRows + 1, {0, 0, 0}, 20.0, P),
                    "computing freedoms: at most 9 constraint points, got 10");
  CHECK_THROWS_WITH(
      cf::freedoms_from_points(many, 1, {0, 0, 0}, 0.0, P),
      Catch::Matchers::StartsWith("computing freedoms: the length scale must be positive"));
}

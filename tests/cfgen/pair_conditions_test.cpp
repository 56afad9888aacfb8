// Tests of the generator's necessary conditions on two PCs
// (tools/cfgen/decide/pair_conditions.cpp): spherical distances worked out by hand on a cube's
// normal cones, rejections on the cube against the L-block that follow from one measurement each,
// and soundness on every CF of the bundled graphs (their witnesses were verified apart from these
// conditions).

#include "cfgen/decide/pair_conditions.hpp"
#include "analysed_pair.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"
#include "scratch.hpp"

#include <cf/graph.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

using cf::ElementKind;
using cf::Pc;
using cf::PcType;
using cf::Polyhedron;
using cf::Vec3;
using cf::gen::NormalCone;

namespace {

// Closed-form angles evaluated with atan2 on unit vectors: rounding only.
constexpr double kAngle = 1e-12;
// Widening used by the generator (tools/cfgen/enumerate/levels.cpp): far above rounding, far below
// its margins.
constexpr double kLengthTol = 1e-9;
constexpr double kAngleTol = 1e-9;

std::string model(const std::string& name) {
  return std::string(CF_SOURCE_DIR) + "/data/models/" + name;
}

using Pair = cf::test::AnalysedPair;

cf::gen::PairConditions exact_conditions(const Pair& p) {
  return {p.ai, p.bi, kLengthTol, kAngleTol};
}

double bbox_diagonal(const Polyhedron& m) {
  Vec3 lo = m.vertices()[0].p, hi = lo;
  for (const auto& v : m.vertices()) lo = lo.cwiseMin(v.p), hi = hi.cwiseMax(v.p);
  return (hi - lo).norm();
}

}  // namespace

TEST_CASE("the normal cones of a cube: a face's normal, an edge's arc, a corner's octant") {
  // Cube [-15, 15]^3 (data/models/cube.off).
  const Pair p(cf::tools::load_model(model("cube.off")),
               cf::tools::load_model(model("l_block.off")));
  const auto pc = exact_conditions(p);
  const int corner = cf::test::vertex_at(p.A, Vec3(15, 15, 15));
  REQUIRE(corner >= 0);
  const NormalCone& octant = pc.cone(true, ElementKind::kVertex, corner);
  REQUIRE(octant.gens.size() == 3);
  for (const Vec3& g : octant.gens) {
    CHECK(g.minCoeff() == Approx(0).margin(kAngle));
    CHECK(g.maxCoeff() == Approx(1).margin(kAngle));
  }
  const Vec3 diag = Vec3(1, 1, 1).normalized();
  CHECK(cf::gen::cone_distance(diag, octant, kAngleTol) == 0);
  CHECK(cf::gen::cone_distance(Vec3(-1, 0, 0), octant, kAngleTol) ==
        Approx(M_PI / 2).margin(kAngle));
  // (1, 1, -1) is nearest to (1, 1, 0) on the octant's boundary: acos(sqrt(2/3)).
  CHECK(cf::gen::cone_distance(Vec3(1, 1, -1).normalized(), octant, kAngleTol) ==
        Approx(std::acos(std::sqrt(2.0 / 3.0))).margin(kAngle));

  // The edge from (15, 15, -15) to (15, 15, 15): the quarter arc from +x to +y.
  int edge = -1;
  for (std::size_t e = 0; e < p.A.num_edges(); ++e) {
    const Vec3 a = p.A.edge_point(cf::EdgeId(int(e)), 0), b = p.A.edge_point(cf::EdgeId(int(e)), 1);
    if (a.x() > 14 && a.y() > 14 && b.x() > 14 && b.y() > 14) edge = static_cast<int>(e);
  }
  REQUIRE(edge >= 0);
  const NormalCone& arc = pc.cone(true, ElementKind::kEdge, edge);
  REQUIRE(arc.gens.size() == 2);
  CHECK(cf::gen::cone_distance(Vec3(0, 0, 1), arc, kAngleTol) == Approx(M_PI / 2).margin(kAngle));
  CHECK(cf::gen::cone_distance(diag, arc, kAngleTol) ==
        Approx(std::asin(1 / std::sqrt(3.0))).margin(kAngle));
  CHECK(cf::gen::cone_distance(Vec3(-1, 0, 0), arc, kAngleTol) == Approx(M_PI / 2).margin(kAngle));
  CHECK(cf::gen::cone_distance(Vec3(-1, -1, 0).normalized(), arc, kAngleTol) ==
        Approx(3 * M_PI / 4).margin(kAngle));

  // Two opposite corners' octants: u >= 0 and v <= 0 componentwise give u . v <= 0.
  const int opposite = cf::test::vertex_at(p.A, Vec3(-15, -15, -15));
  REQUIRE(opposite >= 0);
  CHECK(cf::gen::cone_cone_distance(octant, pc.cone(true, ElementKind::kVertex, opposite),
                                    kAngleTol) == Approx(M_PI / 2).margin(kAngle));
  // An octant and its own edge's arc meet.
  CHECK(cf::gen::cone_cone_distance(octant, arc, kAngleTol) == 0);
}

TEST_CASE("two PCs are rejected when a distance, an angle or a height has no common value") {
  // A: cube [-15, 15]^3. B: the L-block, slab 0 <= y <= 20 over x in [0, 120], wall
  // 0 <= x <= 20 up to y = 80, both 80 deep along z.
  const Pair p(cf::tools::load_model(model("cube.off")),
               cf::tools::load_model(model("l_block.off")));
  const auto pc = exact_conditions(p);
  const int a_bottom = cf::test::face_with_plane(p.A, Vec3(0, -1, 0), 15);
  const int a_top = cf::test::face_with_plane(p.A, Vec3(0, 1, 0), 15);
  const int a_left = cf::test::face_with_plane(p.A, Vec3(-1, 0, 0), 15);
  const int slab_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 20);
  const int wall_side = cf::test::face_with_plane(p.B, Vec3(1, 0, 0), 20);
  const int wall_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 80);
  const int slab_end = cf::test::face_with_plane(p.B, Vec3(1, 0, 0), 120);
  REQUIRE(std::min({a_bottom, a_top, a_left, slab_top, wall_side, wall_top, slab_end}) >= 0);

  // The cube in the inner corner: bottom on the slab, left face on the wall. Valid.
  CHECK(pc.compatible(Pc{PcType::kFF, a_bottom, slab_top}, Pc{PcType::kFF, a_left, wall_side}));
  // Angle: A's bottom and top are antiparallel (pi), the slab's top and the wall's side are
  // at pi/2.
  CHECK_FALSE(
      pc.compatible(Pc{PcType::kFF, a_bottom, slab_top}, Pc{PcType::kFF, a_top, wall_side}));
  // Distance: the wall's side (x = 20, y >= 20) and the slab's far end (x = 120, y <= 20)
  // are 100 mm apart, more than the cube's diagonal (52 mm); a corner of A's left face
  // cannot reach the end. (A height over either plane is at most that distance, so the
  // heights reject it too.)
  const int left_corner = cf::test::vertex_at(p.A, Vec3(-15, 15, 15));
  REQUIRE(left_corner >= 0);
  CHECK_FALSE(
      pc.compatible(Pc{PcType::kFF, a_left, wall_side}, Pc{PcType::kVF, left_corner, slab_end}));
  CHECK(pc.compatible(Pc{PcType::kFF, a_left, wall_side}, Pc{PcType::kVF, left_corner, slab_top}));
  // Height: with the cube's bottom on the slab (y = 20), its top vertices are at y = 50, but
  // the wall's top is at y = 80 (its distance from the slab's top, 60 mm, is within the
  // cube's diagonal, so only the height tells).
  const int top_corner = cf::test::vertex_at(p.A, Vec3(15, 15, 15));
  REQUIRE(top_corner >= 0);
  CHECK_FALSE(
      pc.compatible(Pc{PcType::kFF, a_bottom, slab_top}, Pc{PcType::kVF, top_corner, wall_top}));
  CHECK_FALSE(
      pc.compatible(Pc{PcType::kVF, top_corner, wall_top}, Pc{PcType::kFF, a_bottom, slab_top}));
  // The same corner against the wall's side: heights 0 to 60 over the slab hold 30.
  CHECK(pc.compatible(Pc{PcType::kFF, a_bottom, slab_top}, Pc{PcType::kVF, top_corner, wall_side}));
}

TEST_CASE("the cones shrunk by the verified slack exclude normals at a cone's boundary") {
  const Pair p(cf::tools::load_model(model("cube.off")),
               cf::tools::load_model(model("l_block.off")));
  constexpr double kMargin = 5e-4;  // rad, about the generator's default (half of 1e-3)
  const cf::gen::PairConditions shrunk(p.ai, p.bi, kLengthTol, kAngleTol, kMargin);
  const double s = std::sin(kMargin);
  // The corner (15, 15, 15): the octant u >= sin(margin) componentwise, corners (s, s, c).
  const NormalCone& octant =
      shrunk.cone(true, ElementKind::kVertex, cf::test::vertex_at(p.A, Vec3(15, 15, 15)));
  REQUIRE(octant.gens.size() == 3);
  for (const Vec3& g : octant.gens) {
    CHECK(g.minCoeff() == Approx(s).margin(kAngle));
    CHECK(g.maxCoeff() == Approx(std::sqrt(1 - 2 * s * s)).margin(kAngle));
  }
  CHECK(cf::gen::cone_distance(Vec3(1, 1, 0).normalized(), octant, 0) > 0.99 * kMargin);

  const int a_bottom = cf::test::face_with_plane(p.A, Vec3(0, -1, 0), 15);
  const int slab_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 20);
  const int wall_side = cf::test::face_with_plane(p.B, Vec3(1, 0, 0), 20);
  int bottom_left = -1;  // the edge from (-15, -15, -15) to (-15, -15, 15)
  for (std::size_t e = 0; e < p.A.num_edges(); ++e) {
    const Vec3 a = p.A.edge_point(cf::EdgeId(int(e)), 0), b = p.A.edge_point(cf::EdgeId(int(e)), 1);
    if (a.x() < -14 && a.y() < -14 && b.x() < -14 && b.y() < -14) bottom_left = static_cast<int>(e);
  }
  REQUIRE(bottom_left >= 0);
  // The cube's bottom on the slab and its bottom-left edge on the wall's side: the edge's
  // normal must be -x, the end of its arc, i.e. the left face lies on the wall and the edge
  // is no principal contact. The exact cones allow it (the angle ranges touch at pi/2); the
  // shrunk ones do not.
  const Pc ff{PcType::kFF, a_bottom, slab_top}, ef{PcType::kEF, bottom_left, wall_side};
  CHECK(exact_conditions(p).compatible(ff, ef));
  CHECK_FALSE(shrunk.compatible(ff, ef));
}

TEST_CASE("every pair of PCs of every CF of the bundled graphs passes") {
  // The graphs' CFs have verified witnesses (contact normals at least the generator's slack,
  // about 5e-4 rad, inside their cones): a rejected pair among them would be a set the conditions
  // throw away although the generator can verify it.
  for (const char* name : {"cube_l_block.json", "cube_corner_block.json", "peg_hole_block.json"}) {
    INFO(name);
    const cf::CfGraph g = cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/" + name);
    const Pair p(g.model_a(), g.model_b());
    // As enumerate/levels.cpp builds them for the default --angle-margin (1e-3 rad) and
    // --min-margin (2e-4 of the smaller model's bounding-box diagonal).
    const double diag = std::min(bbox_diagonal(p.A), bbox_diagonal(p.B));
    const cf::gen::PairConditions pc(p.ai, p.bi, kLengthTol, kAngleTol,
                                     std::asin(0.5 * std::sin(1e-3)) - kAngleTol,
                                     0.5 * 2e-4 * diag);
    std::size_t pairs = 0, rejected = 0;
    for (std::size_t i = 0; i < g.num_cfs(); ++i) {
      const cf::PcSet& s = g.cf(cf::CfId(static_cast<int>(i))).pcs;
      for (int x = 0; x < s.size(); ++x)
        for (int y = x + 1; y < s.size(); ++y) {
          ++pairs;
          if (!pc.compatible(s[x], s[y]) || !pc.compatible(s[y], s[x])) {
            ++rejected;
            UNSCOPED_INFO("rejected " << cf::to_string(s[x]) << " with " << cf::to_string(s[y]));
          }
        }
    }
    CHECK(pairs > 500);
    CHECK(rejected == 0);
  }
}

TEST_CASE(
    "contact points inside their elements: faces that meet only at B's convex edge are rejected") {
  // The cube's top (+z) against the L-block's end (z = 0, outward -z) and its front (+y)
  // against the block's underside (y = 0, outward -y). The end and the underside meet at
  // their common edge, so the two contacts hold at once only on that edge: on the boundary
  // of both of B's faces. Angles (pi/2 each side), distances and heights over the closed
  // faces all allow it; over the points the generator's margin inside the faces, the cube's
  // front lies at heights of at least that margin behind the end's plane, the underside's
  // points at least that margin in front of it.
  const Pair p(cf::tools::load_model(model("cube.off")),
               cf::tools::load_model(model("l_block.off")));
  const int a_top = cf::test::face_with_plane(p.A, Vec3(0, 0, 1), 15);
  const int a_front = cf::test::face_with_plane(p.A, Vec3(0, 1, 0), 15);
  const int b_end = cf::test::face_with_plane(p.B, Vec3(0, 0, -1), 0);
  const int b_under = cf::test::face_with_plane(p.B, Vec3(0, -1, 0), 0);
  REQUIRE(std::min({a_top, a_front, b_end, b_under}) >= 0);
  const Pc x{PcType::kFF, a_top, b_end}, y{PcType::kFF, a_front, b_under};
  constexpr double kContactMargin =
      0.005;  // mm, half the default min_margin for the cube (2e-4 x 52 mm)
  const cf::gen::PairConditions inside(p.ai, p.bi, kLengthTol, kAngleTol, 0, kContactMargin);
  CHECK(exact_conditions(p).compatible(x, y));
  CHECK_FALSE(inside.compatible(x, y));
  CHECK_FALSE(inside.compatible(y, x));
  // The same faces with the cube's bottom on the slab and its left face on the wall (the inner
  // corner, a valid CF) still pass.
  const int a_bottom = cf::test::face_with_plane(p.A, Vec3(0, -1, 0), 15);
  const int a_left = cf::test::face_with_plane(p.A, Vec3(-1, 0, 0), 15);
  const int slab_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 20);
  const int wall_side = cf::test::face_with_plane(p.B, Vec3(1, 0, 0), 20);
  CHECK(inside.compatible(Pc{PcType::kFF, a_bottom, slab_top}, Pc{PcType::kFF, a_left, wall_side}));
}

TEST_CASE(
    "an e-e whose normal another PC's rotational condition fixes: refuted where that normal "
    "is on the boundary of an edge's cone, kept where it is inside") {
  // The cube's two edges along z: an e-f puts the first on a face of normal +y (R keeps the
  // edges perpendicular to y), so the second edge, crossing an edge of B along z, has the
  // contact normal +y or -y. On the L-block that edge is the wall's top edge, one of whose faces
  // (the wall's top) has normal +y: the normal lies on its cone's boundary, never the local
  // slack inside it. On a roof-shaped block the ridge's cone holds +y 45 degrees inside, and
  // the cube's own cones decide.
  const Polyhedron cube = cf::tools::load_model(model("cube.off"));
  const int a1 = cf::test::edge_between(cube, cf::test::vertex_at(cube, Vec3(-15, -15, -15)),
                                        cf::test::vertex_at(cube, Vec3(-15, -15, 15)));
  const int a2 = cf::test::edge_between(cube, cf::test::vertex_at(cube, Vec3(15, 15, -15)),
                                        cf::test::vertex_at(cube, Vec3(15, 15, 15)));
  const int a3 = cf::test::edge_between(cube, cf::test::vertex_at(cube, Vec3(-15, 15, -15)),
                                        cf::test::vertex_at(cube, Vec3(15, 15, -15)));
  const int a_bottom = cf::test::face_with_plane(cube, Vec3(0, -1, 0), 15);
  REQUIRE(std::min({a1, a2, a3, a_bottom}) >= 0);
  // As enumerate/levels.cpp builds them for the default --angle-margin (1e-3 rad).
  const double cone_margin = std::asin(0.5 * std::sin(1e-3)) - kAngleTol;
  {
    const Pair p(cube, cf::tools::load_model(model("l_block.off")));
    const cf::gen::PairConditions pc(p.ai, p.bi, kLengthTol, kAngleTol, cone_margin);
    const int slab_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 20);
    const int wall_top = cf::test::edge_between(p.B, cf::test::vertex_at(p.B, Vec3(20, 80, 0)),
                                                cf::test::vertex_at(p.B, Vec3(20, 80, 80)));
    REQUIRE(std::min(slab_top, wall_top) >= 0);
    const Pc on_slab{PcType::kEF, a1, slab_top}, across{PcType::kEE, a2, wall_top};
    CHECK(pc.forced_normal_fails(on_slab, across));
    CHECK_FALSE(pc.compatible(on_slab, across));
    CHECK_FALSE(pc.compatible(across, on_slab));
    // The cube's bottom flat on the slab and an edge of it along x across the wall's top
    // edge: the face-face PC holds that edge perpendicular to y as well.
    const Pc flat{PcType::kFF, a_bottom, slab_top}, across_x{PcType::kEE, a3, wall_top};
    CHECK(pc.forced_normal_fails(flat, across_x));
    // An edge along x with the e-f's edge along z: R keeps it off y only by chance, no rule.
    CHECK_FALSE(pc.forced_normal_fails(on_slab, across_x));
    // Without the slack (the exact cones), nothing is forced out.
    const cf::gen::PairConditions exact(p.ai, p.bi, kLengthTol, kAngleTol);
    CHECK_FALSE(exact.forced_normal_fails(on_slab, across));
  }
  {
    // Cross-section (0,0) (40,0) (40,10) (30,20) (20,10) (0,10), extruded 40 along z: a flat
    // top at y = 10 and a ridge along z at (30, 20), its faces' normals (+-1, 1, 0) / sqrt 2.
    const std::string roof = cf::test::write_file(
        "roof.off",
        "OFF\n12 8 0\n"
        "0 0 0\n40 0 0\n40 10 0\n30 20 0\n20 10 0\n0 10 0\n"
        "0 0 40\n40 0 40\n40 10 40\n30 20 40\n20 10 40\n0 10 40\n"
        "6 5 4 3 2 1 0\n6 6 7 8 9 10 11\n4 0 1 7 6\n4 1 2 8 7\n4 2 3 9 8\n4 3 4 10 9\n"
        "4 4 5 11 10\n4 5 0 6 11\n");
    const Pair p(cube, cf::tools::load_model(roof));
    const cf::gen::PairConditions pc(p.ai, p.bi, kLengthTol, kAngleTol, cone_margin);
    const int flat_top = cf::test::face_with_plane(p.B, Vec3(0, 1, 0), 10);
    const int ridge = cf::test::edge_between(p.B, cf::test::vertex_at(p.B, Vec3(30, 20, 0)),
                                             cf::test::vertex_at(p.B, Vec3(30, 20, 40)));
    REQUIRE(std::min(flat_top, ridge) >= 0);
    const int bottom = cf::test::face_with_plane(p.B, Vec3(0, -1, 0), 0);
    const int a4 = cf::test::edge_between(cube, cf::test::vertex_at(cube, Vec3(15, -15, -15)),
                                          cf::test::vertex_at(cube, Vec3(15, -15, 15)));
    REQUIRE(std::min(bottom, a4) >= 0);
    // B's side passes (N = +y lies inside the ridge's cone), A's cannot: the e-f keeps R^T y
    // in the quadrant x, y > 0 of the cube's frame (the cube's faces at a1 above the top),
    // where the opposite edge a2 (faces at -x and -y) would lie below the contact plane, and
    // so would the bottom face at a4, the bottom's other edge along z (a cube leaning from the
    // flat top onto the ridge: the ridge, crossing a4, pokes through that face).
    CHECK(pc.forced_normal_fails(Pc{PcType::kEF, a1, flat_top}, Pc{PcType::kEE, a2, ridge}));
    CHECK(pc.forced_normal_fails(Pc{PcType::kEF, a1, flat_top}, Pc{PcType::kEE, a4, ridge}));
    // Against B's underside (normal -y) the ridge would touch a2 from above (N = -n), which
    // both cones allow with a1 on that face: the rule keeps the pair (the other conditions
    // judge where the solids are).
    CHECK_FALSE(pc.forced_normal_fails(Pc{PcType::kEF, a1, bottom}, Pc{PcType::kEE, a2, ridge}));
  }
}

namespace {

// The edge of m from p0 to p1 (either way round), or -1.
int edge_at(const Polyhedron& m, const Vec3& p0, const Vec3& p1) {
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const Vec3 &q0 = m.edge_point(cf::EdgeId(static_cast<int>(e)), 0),
               &q1 = m.edge_point(cf::EdgeId(static_cast<int>(e)), 1);
    if ((q0 == p0 && q1 == p1) || (q0 == p1 && q1 == p0)) return static_cast<int>(e);
  }
  return -1;
}

}  // namespace

TEST_CASE("two e-e PCs on parallel edges of both models need parallel or opposite normals") {
  // Each e-e's normal is perpendicular to both of its edges: with A's two edges parallel and
  // B's two parallel, the two normals are parallel or opposite at every rotation.
  const double cone_margin = std::asin(0.5 * std::sin(1e-3)) - kAngleTol;  // verify's slack
  {
    // The peg's end-face edges along x at z = -10 and z = 10 across the hole's rims along x at
    // z = 28 and z = 52 (y = 0). B's normal cones run from -y towards +z and from -y towards
    // -z: shrunk by the slack they hold no common direction and no opposite pair.
    const Pair p(cf::tools::load_model(model("peg.off")),
                 cf::tools::load_model(model("hole_block.off")));
    const int a1 = edge_at(p.A, Vec3(-10, -30, -10), Vec3(10, -30, -10));
    const int a2 = edge_at(p.A, Vec3(-10, -30, 10), Vec3(10, -30, 10));
    const int b1 = edge_at(p.B, Vec3(28, 0, 28), Vec3(52, 0, 28));
    const int b2 = edge_at(p.B, Vec3(28, 0, 52), Vec3(52, 0, 52));
    REQUIRE(std::min({a1, a2, b1, b2}) >= 0);
    const cf::gen::PairConditions pc(p.ai, p.bi, kLengthTol, kAngleTol, cone_margin);
    const Pc x{PcType::kEE, a1, b1}, y{PcType::kEE, a2, b2};
    CHECK(pc.parallel_normals_fail(x, y));
    CHECK(pc.parallel_normals_fail(y, x));
    CHECK_FALSE(pc.compatible(x, y));
    // The same pair on both models moved by generic motions (coordinates rounded, edges
    // parallel only to about 1e-16): still rejected, as the rule allows 1e-9.
    const Eigen::Matrix3d Ra =
        Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Matrix3d Rb =
        Eigen::AngleAxisd(-1.3, Vec3(-2, 0.5, 1).normalized()).toRotationMatrix();
    const Vec3 ta(3.1, -7.7, 0.3), tb(-40.2, 11.9, 5.5);
    const Pair q(cf::test::moved(p.A, Ra, ta), cf::test::moved(p.B, Rb, tb));
    const cf::gen::PairConditions qc(q.ai, q.bi, kLengthTol, kAngleTol, cone_margin);
    // Moving keeps the elements' indices.
    REQUIRE(q.A.edge_point(cf::EdgeId(a1), 0) == Ra * p.A.edge_point(cf::EdgeId(a1), 0) + ta);
    CHECK(qc.parallel_normals_fail(x, y));
    // Only pairs of e-e PCs are judged so.
    CHECK_FALSE(pc.parallel_normals_fail(
        Pc{PcType::kEE, a1, b1},
        Pc{PcType::kVF, 0, cf::test::face_with_plane(p.B, Vec3(0, -1, 0), 0)}));
  }
  {
    // The cube's edges along z at (15, 15) and (-15, -15), cones from +x to +y and from -x to
    // -y, against the L-block's at (0, 0) and (120, 20), cones from -x to -y and from +x to
    // +y: opposite normals (a diagonal and its opposite) lie inside all four.
    const Pair p(cf::tools::load_model(model("cube.off")),
                 cf::tools::load_model(model("l_block.off")));
    const int a1 = edge_at(p.A, Vec3(15, 15, -15), Vec3(15, 15, 15));
    const int a2 = edge_at(p.A, Vec3(-15, -15, -15), Vec3(-15, -15, 15));
    const int b1 = edge_at(p.B, Vec3(0, 0, 0), Vec3(0, 0, 80));
    const int b2 = edge_at(p.B, Vec3(120, 20, 0), Vec3(120, 20, 80));
    REQUIRE(std::min({a1, a2, b1, b2}) >= 0);
    const cf::gen::PairConditions pc(p.ai, p.bi, kLengthTol, kAngleTol, cone_margin);
    CHECK_FALSE(pc.parallel_normals_fail(Pc{PcType::kEE, a1, b1}, Pc{PcType::kEE, a2, b2}));
    // The other assignment asks the same angle of each model: it passes too.
    CHECK_FALSE(pc.parallel_normals_fail(Pc{PcType::kEE, a1, b2}, Pc{PcType::kEE, a2, b1}));
  }
}

// Unit tests of the independent oracle's own geometry: shape families, the feature rebuild,
// touching/PC classification, contact normals, the tangent-cone interior test (including the
// L-foot-in-wall case), the transition rules, times of impact, a smoke run of the sampler and
// the test of unambiguous poses.

#include "classify.hpp"
#include "graph.hpp"
#include "motion.hpp"
#include "sampler.hpp"
#include "shapes.hpp"
#include "transitions.hpp"
#include "unambiguous.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>

using namespace oracle;

namespace {

// A featured polyhedron from maximal polygonal faces (one loop each), edges from the loops.
Poly poly_from_faces(const std::vector<Vec3>& V, const std::vector<std::vector<int>>& F,
                     const std::string& name) {
  std::set<std::pair<int, int>> es;
  for (const auto& f : F)
    for (std::size_t i = 0; i < f.size(); ++i) {
      int a = f[i], b = f[(i + 1) % f.size()];
      es.insert({std::min(a, b), std::max(a, b)});
    }
  std::vector<std::array<int, 2>> edges;
  for (const auto& e : es) edges.push_back({e.first, e.second});
  std::vector<std::vector<std::vector<int>>> faces;
  for (const auto& f : F) faces.push_back({f});
  return build_poly(V, edges, faces, name);
}

// Prism over a CCW profile (x, y), z in [z0, z1]; caps are single (possibly non-convex) faces.
Poly prism(const std::vector<Vec2>& prof, double z0, double z1, const std::string& name) {
  std::vector<Vec3> V;
  const int n = static_cast<int>(prof.size());
  for (const auto& p : prof) V.emplace_back(p.x(), p.y(), z0);
  for (const auto& p : prof) V.emplace_back(p.x(), p.y(), z1);
  std::vector<std::vector<int>> F;
  std::vector<int> top, bot;
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  for (int i = n - 1; i >= 0; --i) bot.push_back(i);
  F.push_back(bot);
  F.push_back(top);
  for (int i = 0; i < n; ++i) F.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  return poly_from_faces(V, F, name);
}

Poly cube(double s) { return prism({{0, 0}, {s, 0}, {s, s}, {0, s}}, 0, s, "cube"); }

int face_with_normal(const Poly& P, const Vec3& n) {
  for (std::size_t i = 0; i < P.F.size(); ++i)
    if (P.F[i].n.dot(n) > 1 - 1e-12) return static_cast<int>(i);
  return -1;
}

Tolerances tol_for(const Poly& A, const Poly& B) { return default_tolerances(A, B); }

}  // namespace

TEST_CASE("every shape family and every pairing gives closed, outward, manifold meshes") {
  struct F {
    Mesh m;
    int faces, verts;
  };
  std::vector<F> fam = {
      {make_box(3, 4, 5), 6, 8},
      {make_l_section(20, 15, 3, 4, 10), 8, 12},
      {make_u_channel(10, 2, 3, 12, 30), 10, 16},
      {make_t_section(30, 4, 5, 20, 25), 10, 16},
      {make_t_slot(40, 30, 25, 10, 5, 20, 6), 14, 24},
      {make_corner_block(30, 40, 4, 3, 5, 20), 9, 14},
      {make_stairs({5, 6, 7}, {3, 4, 5}, 20), 10, 16},
      {make_stairs({5, 6}, {3, 4}, 20), 8, 12},
      {make_square_hole_block(30, 10, 12, 1, -2), 10, 16},
      {make_ngon_hole_block(30, 10, 5, 10, 0.3), 11, 18},
      {make_ngon_hole_block(30, 10, 8, 13, 0.1), 14, 24},
      {make_ngon_prism(3, 5, 10, 0.2), 5, 6},
      {make_ngon_prism(8, 5, 10, 0.2), 10, 16},
      {make_wedge(10, 6, 3, 8), 5, 6},
      {make_pyramid(10, 8, 7, 1, -2), 5, 5},
      {make_ramp_step(20, 6, 15, 8, 14, 4, 9, 3, 30), 11, 18},
  };
  for (const auto& f : fam) {
    INFO(f.m.name);
    CHECK(check_mesh(f.m).empty());
    CHECK(count_planar_faces(f.m) == f.faces);
    CHECK(count_corner_vertices(f.m) == f.verts);
    CHECK(mesh_volume(f.m) > 0);
    // a rigid motion keeps everything
    std::mt19937_64 rng(7);
    Mesh t = transform(f.m, random_rigid(rng));
    CHECK(check_mesh(t).empty());
    CHECK(std::abs(mesh_volume(t) - mesh_volume(f.m)) < 1e-9 * mesh_volume(f.m));
  }
  // a broken mesh is reported
  Mesh b = make_box(1, 1, 1);
  b.F.pop_back();
  CHECK_FALSE(check_mesh(b).empty());
  Mesh inv = make_box(1, 1, 1);
  for (auto& f : inv.F) std::reverse(f.begin(), f.end());
  CHECK_FALSE(check_mesh(inv).empty());
  std::set<int> pairings;
  for (std::uint64_t seed = 0; seed < 48; ++seed) {
    ShapePair P = make_pair(seed);
    INFO("seed " << seed << ": " << P.desc);
    CHECK(check_mesh(P.A).empty());
    CHECK(check_mesh(P.B).empty());
    pairings.insert(P.pairing);
  }
  CHECK(pairings.size() == static_cast<std::size_t>(kPairings));
  for (int which = 0; which < kExtraPairings; ++which)
    for (std::uint64_t seed = 1; seed < 9; ++seed) {
      ShapePair P = make_extra_pair(which, seed);
      INFO("extra " << which << " seed " << seed << ": " << P.desc);
      CHECK(check_mesh(P.A).empty());
      CHECK(check_mesh(P.B).empty());
      CHECK(P.pairing == -1 - which);
    }
}

TEST_CASE("triangulation of a square with an octagonal hole adds up") {
  std::vector<Vec2> outer{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  std::vector<Vec2> hole;
  for (int i = 7; i >= 0; --i)
    hole.emplace_back(5 + 4.9 * std::cos(0.3 + i * kPi / 4), 5 + 4.9 * std::sin(0.3 + i * kPi / 4));
  auto tris = triangulate(outer, {hole});
  CHECK(tris.size() == 4 + 8);  // one bridge: n + h triangles
}

TEST_CASE("features rebuilt from arrays: normals, convexity, corners") {
  Poly L = prism({{0, 0}, {40, 0}, {40, 10}, {10, 10}, {10, 30}, {0, 30}}, 0, 20, "L");
  CHECK(L.F.size() == 8);
  CHECK(L.E.size() == 18);
  int reflex = 0;
  for (const auto& e : L.E) reflex += e.convex ? 0 : 1;
  CHECK(reflex == 1);
  CHECK(L.volume() == Approx(20 * (40 * 10 + 10 * 20)));
  // the vertex at the reflex corner has a 270 degree corner in each cap
  int v = -1;
  for (std::size_t i = 0; i < L.V.size(); ++i)
    if ((L.V[i].p - Vec3(10, 10, 0)).norm() < 1e-12) v = static_cast<int>(i);
  REQUIRE(v >= 0);
  double maxspan = 0;
  for (const auto& c : L.V[v].corners) maxspan = std::max(maxspan, c.span);
  CHECK(maxspan == Approx(1.5 * kPi));
}

TEST_CASE("a cube face-down on a floor is one f-f") {
  Poly A = cube(10);
  Poly B = prism({{-50, -50}, {50, -50}, {50, 50}, {-50, 50}}, -20, 0, "floor");
  Classifier C(A, B, tol_for(A, B));
  Pose X;
  X.t = Vec3(3, -4, 0);
  Verdict V = C.classify(X);
  INFO(V.describe());
  REQUIRE(V.valid_cf());
  CfKey k = V.key();
  REQUIRE(k.size() == 1);
  CHECK(k[0].type == PcType::FF);
  CHECK(k[0].a == face_with_normal(A, Vec3(0, 0, -1)));
  CHECK(k[0].b == face_with_normal(B, Vec3(0, 0, 1)));
  CHECK(V.clearance > 1);
  // spun about the normal and moved: still one f-f
  X.R = Eigen::AngleAxisd(0.7, Vec3::UnitZ()).toRotationMatrix();
  CHECK(C.classify(X).key() == k);
  // lifted: free; sunk: penetrating
  X.t.z() = 0.01;
  CHECK(C.classify(X).free());
  X.t.z() = -0.01;
  CHECK(C.classify(X).penetrating);
  // tilted about an edge of the bottom face: e-f
  Pose Y;
  Y.R = Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix();
  Verdict W = C.classify(Y);
  INFO(W.describe());
  REQUIRE(W.valid_cf());
  REQUIRE(W.key().size() == 1);
  CHECK(W.key()[0].type == PcType::EF);
  // tilted about two axes: a single vertex
  Pose Z;
  Z.R = Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix() *
        Eigen::AngleAxisd(-0.2, Vec3::UnitY()).toRotationMatrix();
  Verdict U = C.classify(Z);
  INFO(U.describe());
  REQUIRE(U.valid_cf());
  REQUIRE(U.key().size() == 1);
  CHECK(U.key()[0].type == PcType::VF);
}

TEST_CASE("a cube edge crossing a table edge is e-e") {
  Poly A = cube(10);
  Poly B = prism({{-50, -50}, {0, -50}, {0, 50}, {-50, 50}}, -20, 0,
                 "table");  // edge along y at x=0, z=0
  Classifier C(A, B, tol_for(A, B));
  Vec3 d = Vec3(1, 0, -1).normalized();
  Vec3 s = d.cross(Vec3(0, 1, 0)).normalized();  // separating plane normal; B on s.x <= 0
  Vec3 c = d.cross(s).normalized();
  Vec3 n1 = (-s + c).normalized(), n2 = (-s - c).normalized();
  // cube edge along local x at y=0, z=0: faces y=0 (normal -y) and z=0 (normal -z)
  Pose X;
  X.R.col(0) = d;
  X.R.col(1) = -n1;
  X.R.col(2) = -n2;
  if (X.R.determinant() < 0) {
    X.R.col(1) = -n2;
    X.R.col(2) = -n1;
  }
  X.t = Vec3(0, 7, 0) - X.R * Vec3(5, 0, 0);
  Verdict V = C.classify(X);
  INFO(V.describe());
  REQUIRE(V.valid_cf());
  REQUIRE(V.key().size() == 1);
  CHECK(V.key()[0].type == PcType::EE);
  // pushed a little further: penetrating
  X.t -= 0.01 * s;
  CHECK(C.classify(X).penetrating);
}

TEST_CASE("contact normals point from B into A for every non-degenerate type") {
  // Exact up to rounding of the rotations (coordinates of tens of mm).
  constexpr double kSame = 1e-12;
  Poly A = cube(10);
  Poly floor_ = prism({{-50, -50}, {50, -50}, {50, 50}, {-50, 50}}, -20, 0, "floor");
  Classifier C(A, floor_, tol_for(A, floor_));
  // One PC of the pose, with its normal into A.
  auto only = [](const Poly& B, const Verdict& V) {
    INFO(V.describe());
    REQUIRE(V.valid_cf());
    REQUIRE(V.pcs.size() == 1);
    const Touch& t = V.touches[V.pcs[0]];
    return std::make_pair(t.type, normal_into_a(B, t));
  };
  // On the floor (top face z = 0): f-f flat, e-f tilted about x, v-f tilted about two axes;
  // B's face normal, +z, each time.
  Pose X;
  X.t = Vec3(3, -4, 0);
  auto [ff, n_ff] = only(floor_, C.classify(X));
  CHECK(ff == PcType::FF);
  CHECK((n_ff - Vec3(0, 0, 1)).norm() < kSame);
  Pose Y;
  Y.R = Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix();
  auto [ef, n_ef] = only(floor_, C.classify(Y));
  CHECK(ef == PcType::EF);
  CHECK((n_ef - Vec3(0, 0, 1)).norm() < kSame);
  Pose Z;
  Z.R = Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix() *
        Eigen::AngleAxisd(-0.2, Vec3::UnitY()).toRotationMatrix();
  auto [vf, n_vf] = only(floor_, C.classify(Z));
  CHECK(vf == PcType::VF);
  CHECK((n_vf - Vec3(0, 0, 1)).norm() < kSame);
  // A table (x <= 0, z <= 0), its edge along y at x = z = 0. The cube's bottom face turned 45
  // degrees about y so that its outward normal is (-1, 0, -1)/sqrt(2), its centre on the edge:
  // f-e, and the normal into A is minus the face's, (1, 0, 1)/sqrt(2).
  Poly table = prism({{-50, -50}, {0, -50}, {0, 50}, {-50, 50}}, -20, 0, "table");
  Classifier T(A, table, tol_for(A, table));
  Pose F;
  F.R = Eigen::AngleAxisd(kPi / 4, Vec3::UnitY()).toRotationMatrix();
  F.t = Vec3(0, 7, 0) - F.R * Vec3(5, 5, 0);
  const Verdict VF = T.classify(F);
  auto [fe, n_fe] = only(table, VF);
  CHECK(fe == PcType::FE);
  CHECK((VF.touches[VF.pcs[0]].normal - Vec3(-1, 0, -1).normalized()).norm() < kSame);
  CHECK((n_fe - Vec3(1, 0, 1).normalized()).norm() < kSame);
  // A block in the octant x, y, z <= 0, the cube's bottom face square to (1, 1, 1) with its
  // centre on the block's corner vertex: f-v, normal into A (1, 1, 1)/sqrt(3).
  Poly block = prism({{-50, -50}, {0, -50}, {0, 0}, {-50, 0}}, -20, 0, "block");
  Classifier K(A, block, tol_for(A, block));
  Pose G;
  G.R = Eigen::Quaterniond::FromTwoVectors(Vec3(0, 0, -1), -Vec3(1, 1, 1).normalized())
            .toRotationMatrix();
  G.t = -G.R * Vec3(5, 5, 0);
  auto [fv, n_fv] = only(block, K.classify(G));
  CHECK(fv == PcType::FV);
  CHECK((n_fv - Vec3(1, 1, 1).normalized()).norm() < kSame);
  // The cube's edge across the table's edge (as in the e-e test above): the plane of both
  // edges, on the side of the table edge's outward bisector (1, 0, 1)/sqrt(2), whichever way
  // the cross product of the edges points.
  Vec3 d = Vec3(1, 0, -1).normalized();
  Vec3 s = d.cross(Vec3(0, 1, 0)).normalized();
  Vec3 c = d.cross(s).normalized();
  Vec3 n1 = (-s + c).normalized(), n2 = (-s - c).normalized();
  Pose E;
  E.R.col(0) = d;
  E.R.col(1) = -n1;
  E.R.col(2) = -n2;
  if (E.R.determinant() < 0) {
    E.R.col(1) = -n2;
    E.R.col(2) = -n1;
  }
  E.t = Vec3(0, 7, 0) - E.R * Vec3(5, 0, 0);
  const Verdict VE = T.classify(E);
  auto [ee, n_ee] = only(table, VE);
  CHECK(ee == PcType::EE);
  CHECK((s - Vec3(1, 0, 1).normalized()).norm() < kSame);
  CHECK((n_ee - s).norm() < kSame);
  Touch flipped = VE.touches[VE.pcs[0]];
  flipped.normal = -flipped.normal;
  CHECK((normal_into_a(table, flipped) - s).norm() < kSame);
}

TEST_CASE("an e-e at a small angle is not read as line contacts on the ridge's faces") {
  // A: a box whose ridge x = y = 10 runs along z; its material lies towards -x, -y. B: a 60
  // degree wedge whose apex edge is the z axis, its material towards +x, +y. A is placed with
  // its ridge through the origin, turned by 1.7 degrees about the wedges' bisector (1, 1, 0), so
  // the two ridges cross at that angle in the plane x + y = 0 that separates the solids, 42
  // touch tolerances from A's corner at z = -20. Towards that corner B's edge rises out of A's
  // face x = 10 at 0.021 rad and leaves the ridge's capsule (radius tol) 34 tolerances from the
  // crossing, still within tol of the plane, and meets the capsule of the face's end edge
  // z = -20 before it rises out of it: 7 tolerances within tol of the face's plane and, in
  // space, more than tol from its boundary, but beside the ridge in the plane. That is the e-e
  // seen at the tolerance, not an f-e.
  Poly A = prism({{0, 0}, {10, 0}, {10, 10}, {0, 10}}, -20, 20, "box");
  const double half = 30 * kPi / 180;
  const Vec2 bis(std::sqrt(0.5), std::sqrt(0.5));
  auto ray = [&](double turn) {  // a side of the wedge, 40 mm long
    return Vec2(40 * (bis.x() * std::cos(turn) - bis.y() * std::sin(turn)),
                40 * (bis.x() * std::sin(turn) + bis.y() * std::cos(turn)));
  };
  Poly B = prism({{0, 0}, ray(-half), ray(half)}, -20, 20, "wedge");
  const double theta = 1.7 * kPi / 180;
  const Vec3 axis = Vec3(1, 1, 0).normalized();
  Pose X;
  X.R = Eigen::AngleAxisd(theta, axis).toRotationMatrix();
  const Classifier C(A, B, tol_for(A, B));
  X.t = -X.R * Vec3(10, 10, -20 + 42 * C.tol().len);
  const Verdict V = C.classify(X);
  INFO(V.describe());
  REQUIRE(V.valid_cf());
  REQUIRE(V.pcs.size() == 1);
  const Touch& t = V.touches[V.pcs[0]];
  CHECK(t.type == PcType::EE);
  CHECK(std::abs(t.sin_angle - std::sin(theta)) < 1e-9);
  for (const Touch& u : V.touches) CHECK(u.type == PcType::EE);
}

TEST_CASE("the L-foot inside a wall is caught although elements only touch on boundaries") {
  // B: floor slab (top y = 0 for x > 0) and a wall x in [-10, 0] rising to y = 20; reflex edge
  // at x = 0, y = 0. A: an L-part whose bottom face (y = 0) runs through B's reflex edge and
  // whose reflex edge (x = 0, y = 3) lies on B's wall face; its foot is 7.8 mm inside the wall.
  Poly B = prism({{-10, -10}, {40, -10}, {40, 0}, {0, 0}, {0, 20}, {-10, 20}}, -20, 20, "L-block");
  Poly A = prism({{-7.8, 0}, {5, 0}, {5, 12}, {0, 12}, {0, 3}, {-7.8, 3}}, -5, 5, "L-part");
  Classifier C(A, B, tol_for(A, B));
  Pose X;  // identity: coordinates above are world coordinates
  Verdict V = C.classify(X);
  INFO(V.describe());
  CHECK(V.penetrating);
  CHECK_FALSE(C.interiors_disjoint(X));
  // no open edge crosses an open face: only the tangent cones see it
  CHECK(V.why.find("tangent cones overlap") != std::string::npos);
  for (const Touch& t : V.touches) CHECK_FALSE(t.transversal);
  // the tangent cones alone see it: A's vertex at the end of its reflex edge against B's wall
  int v = -1;
  for (std::size_t i = 0; i < A.V.size(); ++i)
    if ((A.V[i].p - Vec3(0, 3, 5)).norm() < 1e-12) v = static_cast<int>(i);
  int wall = face_with_normal(B, Vec3(1, 0, 0));
  REQUIRE(v >= 0);
  REQUIRE(wall >= 0);
  CHECK(cones_overlap(vertex_cone(A, v, Mat3::Identity()), face_cone(B, wall, Mat3::Identity()),
                      1e-6));
  // the same part moved out of the wall by 7.8 mm sits in the corner: two f-f on distinct planes
  Pose Y;
  Y.t = Vec3(7.8, 0, 0);
  Verdict W = C.classify(Y);
  INFO(W.describe());
  REQUIRE(W.valid_cf());
  CHECK(W.key().size() == 2);
  for (const Pc& p : W.key()) CHECK(p.type == PcType::FF);
  // a whole cube inside B (nothing touches): containment
  Poly K = cube(2);
  Classifier CK(K, B, tol_for(K, B));
  Pose Z;
  Z.t = Vec3(-6, 5, 0);
  Verdict VK = CK.classify(Z);
  CHECK(VK.penetrating);
  CHECK(VK.touches.empty());
}

TEST_CASE("tangent cones: closed forms") {
  Cone up, down, tilted;
  up.kind = down.kind = tilted.kind = 0;
  up.n = Vec3(0, 0, 1);
  down.n = Vec3(0, 0, -1);
  tilted.n = Vec3(0, 0.1, -1).normalized();
  CHECK_FALSE(cones_overlap(up, down, 1e-9));
  CHECK(cones_overlap(up, up, 1e-9));
  CHECK(cones_overlap(up, tilted, 1e-9));
  Poly A = cube(10);
  // the cube's vertex at the origin on a floor face: no overlap; tilted into it: overlap
  Cone floor_;
  floor_.kind = 0;
  floor_.n = Vec3(0, 0, 1);
  CHECK_FALSE(cones_overlap(vertex_cone(A, 0, Mat3::Identity()), floor_, 1e-9));
  Mat3 R = Eigen::AngleAxisd(0.2, Vec3(1, -1, 0).normalized()).toRotationMatrix();
  Cone kv = vertex_cone(A, 0, R);
  bool any_down = false;
  for (const auto& r : kv.rays) any_down |= r.first.z() < 0;
  CHECK(cones_overlap(kv, floor_, 1e-9) == any_down);
  // the cube's edge at a floor: flat OK, rotated 45 degrees OK (tilted wedge), reflex never
  int e = A.edge_index(0, 1);
  REQUIRE(e >= 0);
  CHECK_FALSE(cones_overlap(edge_cone(A, e, Mat3::Identity()), floor_, 1e-9));
  Mat3 R45 = Eigen::AngleAxisd(kPi / 4, A.E[e].dir).toRotationMatrix();
  Cone ce = edge_cone(A, e, R45);
  CHECK(cones_overlap(ce, floor_, 1e-9) == (ce.w.m1.z() < -1e-9 || ce.w.m2.z() < -1e-9));
  Poly L = prism({{0, 0}, {40, 0}, {40, 10}, {10, 10}, {10, 30}, {0, 30}}, 0, 20, "L");
  for (std::size_t i = 0; i < L.E.size(); ++i)
    if (!L.E[i].convex) {
      Cone top;
      top.kind = 0;
      top.n = L.F[L.E[i].face[0]].n * -1.0;
      CHECK(cones_overlap(edge_cone(L, static_cast<int>(i), Mat3::Identity()), top, 1e-9));
    }
  // the same vertex cone against itself overlaps
  Cone k0 = vertex_cone(A, 0, Mat3::Identity());
  CHECK(cones_overlap(k0, k0, 1e-9));
  CHECK(point_in_cone(k0, Vec3(1, 1, 1).normalized()));
  CHECK_FALSE(point_in_cone(k0, Vec3(-1, 1, 1).normalized()));
  // reflex vertex cone of the L (corner at (10,10,0)) contains three octants' worth
  int v = -1;
  for (std::size_t i = 0; i < L.V.size(); ++i)
    if ((L.V[i].p - Vec3(10, 10, 0)).norm() < 1e-12) v = static_cast<int>(i);
  Cone kl = vertex_cone(L, v, Mat3::Identity());
  CHECK(point_in_cone(kl, Vec3(-1, -1, 1).normalized()));
  CHECK(point_in_cone(kl, Vec3(1, -1, 1).normalized()));
  CHECK(point_in_cone(kl, Vec3(-1, 1, 1).normalized()));
  CHECK_FALSE(point_in_cone(kl, Vec3(1, 1, 1).normalized()));
  CHECK_FALSE(point_in_cone(kl, Vec3(1, 1, -1).normalized()));
}

TEST_CASE("the transition rules (docs/spec.md section 4) on a cube against a box") {
  // Two convex boxes (8 vertices, 12 edges, 6 faces, three edges and three faces at every
  // vertex): each PC's neighbours, counted by hand from the boundary relations of
  // docs/spec.md, section 4.
  //   f-f: 4 e-f (A's face's edges) + 4 f-e (B's face's edges)                        = 8
  //   e-f: 2 f-f (the edge's faces) + 2 v-f (its ends) + 4 e-e (B's face's edges)      = 8
  //   f-e: 2 f-f + 2 f-v + 4 e-e, likewise                                             = 8
  //   v-f: 3 e-f (the vertex's edges) + 3 x 4 e-e (those edges, B's face's edges)      = 15
  //   f-v: 3 f-e + 4 x 3 e-e, likewise                                                 = 15
  //   e-e: 2 e-f + 2 f-e (the edges' faces) + 2 x 2 v-f + 2 x 2 f-v (ends and faces)   = 12
  Poly A = cube(10);
  Poly B = prism({{-50, -50}, {50, -50}, {50, 50}, {-50, 50}}, -20, 0, "floor");
  const std::map<PcType, int> expected = {{PcType::FF, 8},  {PcType::EF, 8},  {PcType::FE, 8},
                                          {PcType::VF, 15}, {PcType::FV, 15}, {PcType::EE, 12}};
  auto count = [](const Poly& P, int kind) {
    return static_cast<int>(kind == 0 ? P.V.size() : kind == 1 ? P.E.size() : P.F.size());
  };
  std::vector<Pc> all;
  for (const auto& [t, n] : expected)
    for (int a = 0; a < count(A, kind_a(t)); ++a)
      for (int b = 0; b < count(B, kind_b(t)); ++b) all.push_back(Pc{t, a, b});
  CHECK(all.size() == 6 * 6 + 12 * 6 + 6 * 12 + 8 * 6 + 6 * 8 + 12 * 12);
  int asymmetric = 0;
  for (const Pc& x : all) {
    int n = 0;
    for (const Pc& y : all) {
      const bool nb = neighbouring_pcs(A, B, x, y);
      if (nb != neighbouring_pcs(A, B, y, x)) ++asymmetric;
      n += nb ? 1 : 0;
    }
    INFO(key_string({x}));
    CHECK(n == expected.at(x.type));
  }
  CHECK(asymmetric == 0);
  // Real elements: A's bottom face and B's top face, an edge and a vertex of A's bottom.
  const int fa = face_with_normal(A, Vec3(0, 0, -1)), fb = face_with_normal(B, Vec3(0, 0, 1));
  const int fa2 = face_with_normal(A, Vec3(1, 0, 0)), fb2 = face_with_normal(B, Vec3(-1, 0, 0));
  REQUIRE(fa >= 0);
  REQUIRE(fb >= 0);
  const int ea = A.edge_index(0, 1);  // (0,0,0)-(10,0,0), on the bottom face
  REQUIRE(ea >= 0);
  REQUIRE(A.edge_on_face(ea, fa));
  const int eb_off = B.edge_index(0, 4);  // a vertical edge of B: not on its top face
  REQUIRE(eb_off >= 0);
  REQUIRE_FALSE(B.edge_on_face(eb_off, fb));
  CHECK(neighbouring_pcs(A, B, Pc{PcType::FF, fa, fb}, Pc{PcType::EF, ea, fb}));
  CHECK_FALSE(neighbouring_pcs(A, B, Pc{PcType::FF, fa, fb}, Pc{PcType::EF, ea, fb2}));
  CHECK_FALSE(neighbouring_pcs(A, B, Pc{PcType::FF, fa, fb}, Pc{PcType::FF, fa, fb}));
  CHECK(neighbouring_pcs(A, B, Pc{PcType::EF, ea, fb}, Pc{PcType::VF, 0, fb}));
  CHECK_FALSE(neighbouring_pcs(A, B, Pc{PcType::EF, ea, fb}, Pc{PcType::VF, 2, fb}));
  CHECK_FALSE(neighbouring_pcs(A, B, Pc{PcType::EF, ea, fb}, Pc{PcType::EE, ea, eb_off}));
  auto key = [](std::vector<Pc> pcs) {
    std::sort(pcs.begin(), pcs.end());
    return pcs;
  };
  const CfKey ff = key({{PcType::FF, fa, fb}});
  const CfKey ff2 = key({{PcType::FF, fa, fb}, {PcType::FF, fa2, fb2}});
  CHECK(is_gain(ff, ff2));
  CHECK_FALSE(is_gain(ff2, ff));  // a lose, not a gain
  CHECK_FALSE(is_gain(ff, ff));
  CHECK_FALSE(is_gain(key({{PcType::EF, ea, fb}}), ff2));  // not a subset
  CHECK_FALSE(is_gain(CfKey{}, ff2));                      // two PCs added
  // A change replaces PCs by neighbours, one to one, in any order of the sorted keys.
  CHECK(is_change(A, B, ff, key({{PcType::EF, ea, fb}})));
  CHECK(is_change(A, B, key({{PcType::EF, ea, fb}}), ff));
  CHECK_FALSE(is_change(A, B, ff, key({{PcType::VF, 0, fb}})));  // two steps: f-f, e-f, v-f
  CHECK_FALSE(is_change(A, B, ff, ff));
  CHECK_FALSE(is_change(A, B, ff, ff2));
  CHECK(is_change(A, B, ff2, key({{PcType::FF, fa2, fb2}, {PcType::EF, ea, fb}})));
  CHECK_FALSE(is_change(A, B, ff2, key({{PcType::FF, fa2, fb2}, {PcType::VF, 0, fb}})));
}

TEST_CASE("time of impact: translation is exact, rotation lands on contact") {
  Poly A = cube(10);
  Poly B = prism({{-50, -50}, {0, -50}, {0, 50}, {20, 50}, {20, 60}, {-50, 60}}, -20, 0, "plate");
  Classifier C(A, B, tol_for(A, B));
  Pose X;
  X.t = Vec3(-20, 0, 7.25);
  Motion M;
  M.u = Vec3(0, 0, -1);
  double s = time_of_impact(A, B, X, M, 100, C.tol().len);
  CHECK(s == Approx(7.25).epsilon(1e-14));
  Verdict V = C.classify(apply_motion(X, M, s));
  REQUIRE(V.valid_cf());
  CHECK(V.key()[0].type == PcType::FF);
  // random poses and motions: the pose at the time of impact touches without penetrating,
  // and a fine scan before it sees no contact
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N(0, 1);
  int checked = 0;
  for (int trial = 0; trial < 300 && checked < 60; ++trial) {
    Pose P0;
    P0.R = random_rotation(rng);
    P0.t = Vec3(N(rng) * 20, N(rng) * 30, 10 + std::abs(N(rng)) * 10);
    if (!C.classify(P0, false).free()) continue;
    Motion m;
    double lmax;
    if (trial % 2 == 0) {
      m.u = Vec3(N(rng), N(rng), -2 - std::abs(N(rng))).normalized();
      lmax = 200;
    } else {
      m.rotation = true;
      m.c = P0.t + Vec3(N(rng), N(rng), -10 - std::abs(N(rng)) * 5);
      m.w = Vec3(N(rng), N(rng), N(rng)).normalized();
      lmax = kPi;
    }
    double l = time_of_impact(A, B, P0, m, lmax, C.tol().len);
    if (!(l < kInf)) continue;
    ++checked;
    Verdict W = C.classify(apply_motion(P0, m, l), false);
    INFO("trial " << trial << " lambda " << l << " " << W.describe());
    CHECK_FALSE(W.penetrating);
    CHECK_FALSE(W.touches.empty());
    for (int k = 1; k < 40; ++k) CHECK(C.classify(apply_motion(P0, m, l * k / 40.0), false).free());
  }
  CHECK(checked >= 30);
}

TEST_CASE("sampler on a cube against an L-block: every sample re-verifies") {
  Poly A = cube(10);
  Poly B = prism({{0, 0}, {40, 0}, {40, 10}, {10, 10}, {10, 30}, {0, 30}}, 0, 20, "L");
  Classifier C(A, B, tol_for(A, B));
  SamplerOptions o;
  o.budget_s = 1.5;
  o.seed = 5;
  Sampler S(C, o);
  S.run();
  INFO(S.stats().str());
  CHECK(S.samples().size() > 100);
  std::set<PcType> types;
  std::set<std::size_t> sizes;
  for (const auto& [k, s] : S.samples()) {
    Verdict V = C.classify(s.pose);
    INFO(key_string(k) << " " << V.describe());
    CHECK(V.valid_cf());
    CHECK(V.key() == k);
    for (const Pc& p : k) types.insert(p.type);
    sizes.insert(k.size());
  }
  CHECK(types.size() == 6);
  CHECK(sizes.count(2));
  // a cube against an L-block (B = union of two convex pieces, A convex) has no 3-PC CF
  CHECK_FALSE(sizes.count(3));
}

TEST_CASE("graph reader and witness checker on a hand-written graph") {
  Poly A = cube(10);
  Poly B = prism({{-50, -50}, {50, -50}, {50, 50}, {-50, 50}}, -20, 0, "floor");
  auto model = [](const Poly& P) {
    nlohmann::json m;
    m["name"] = P.name;
    for (const auto& v : P.V) m["vertices"].push_back({v.p.x(), v.p.y(), v.p.z()});
    for (const auto& e : P.E) m["edges"].push_back({e.v0, e.v1});
    for (const auto& f : P.F) m["faces"].push_back({{"loops", f.loops}});
    return m;
  };
  const int fa = face_with_normal(A, Vec3(0, 0, -1)), fb = face_with_normal(B, Vec3(0, 0, 1));
  auto cf = [&](int id, const std::string& type, int a, int b, double z) {
    nlohmann::json c;
    c["id"] = id;
    c["pcs"] = nlohmann::json::array({{{"type", type}, {"a", a}, {"b", b}}});
    c["witness"]["R"] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    c["witness"]["t"] = {3, -4, z};
    return c;
  };
  nlohmann::json g;
  g["format"] = "cf-graph";
  g["version"] = 1;
  g["units"] = "mm";
  g["models"]["A"] = model(A);
  g["models"]["B"] = model(B);
  const double tol = default_tolerances(A, B).len;
  g["cfs"] = {cf(0, "f-f", fa, fb, 0.0),        // sound
              cf(1, "f-f", fa, fb, -0.01),      // sunk 0.01 mm: unsound
              cf(2, "v-f", 0, fb, 0.0),         // the pose holds an f-f, not this: unsound
              cf(3, "f-f", fa, fb, 20 * tol)};  // lifted by 20 tol: marginal
  g["transitions"] = nlohmann::json::array();
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("oracle_graph_" + std::to_string(::getpid()) + ".json"))
                               .string();
  std::ofstream(path) << g.dump();
  Graph G = read_graph(path);
  std::filesystem::remove(path);
  REQUIRE(G.cfs.size() == 4);
  CHECK(G.A.F.size() == 6);
  CheckReport rep = check_graph(G, default_tolerances(G.A, G.B));
  CHECK(rep.total == 4);
  CHECK(rep.sound == 1);
  CHECK(rep.unsound == 2);
  CHECK(rep.marginal == 1);
  CHECK(rep.min_clearance > 1);
  for (const auto& w : rep.bad) {
    INFO(w.id << ": " << w.problem);
    if (w.id == 1) CHECK(w.problem.find("interiors overlap") != std::string::npos);
    if (w.id == 2) CHECK(w.problem.find("differ") != std::string::npos);
    if (w.id == 3) CHECK(w.verdict == 1);
  }
  // a broken file is reported, not crashed on
  const std::string bad = path + ".bad";
  std::ofstream(bad) << "{\"format\": \"cf-graph\", \"models\": {}}";
  CHECK_THROWS_AS(read_graph(bad), std::runtime_error);
  std::filesystem::remove(bad);
}

TEST_CASE("unambiguous poses: other pairs beyond the band, leaning ones beyond their tolerance") {
  // B: a floor (top y = 0 for x in [-30, 50]) with a wall (face x = -30), z in [-50, 50].
  Poly B = prism({{-50, -20}, {50, -20}, {50, 0}, {-30, 0}, {-30, 40}, {-50, 40}}, -50, 50, "L");
  const BandParams band;  // epsilon 1 mm, margins 0.05 mm and 10%
  {
    Poly A = cube(10);
    Classifier C(A, B, tol_for(A, B));
    // Face-down on the floor: one f-f; its own corners and edges are readings of it.
    Pose X;
    X.t = Vec3(-28, 0, -5);  // 2 mm from the wall
    Verdict V = C.classify(X);
    REQUIRE(V.valid_cf());
    REQUIRE(V.key().size() == 1);
    Ambiguity a = check_unambiguous(A, B, X, V.key(), band);
    INFO(a.why);
    CHECK(a.unambiguous);
    // 1.04 mm from the wall (within epsilon + margin): the wall's pairs are in the band.
    X.t.x() = -30 + 1.04;
    V = C.classify(X);
    REQUIRE(V.key().size() == 1);
    a = check_unambiguous(A, B, X, V.key(), band);
    CHECK_FALSE(a.unambiguous);
    CHECK(a.why.find("distance") != std::string::npos);
    X.t.x() = -30 + 1.06;
    CHECK(check_unambiguous(A, B, X, C.classify(X).key(), band).unambiguous);
  }
  {
    // A 30 mm cube on its edge (along z, at x = 5), its bottom face tilted up by theta: that
    // face's f-f and its two edges' e-f are within the band (they meet the floor along the
    // edge or at its ends), their tolerance atan(1 / (30 cos theta)), about 0.0333 rad:
    // unambiguous beyond 1.1 times that.
    Poly A = cube(30);
    Classifier C(A, B, tol_for(A, B));
    const double tol = std::atan(1.0 / 30);
    for (double theta : {0.036, 0.05}) {
      CAPTURE(theta);
      Pose X;
      X.R = Eigen::AngleAxisd(theta, Vec3::UnitZ()).toRotationMatrix();
      X.t = Vec3(5, 0, -15);
      Verdict V = C.classify(X);
      REQUIRE(V.valid_cf());
      REQUIRE(V.key().size() == 1);
      CHECK(V.key()[0].type == PcType::EF);
      CHECK(30 * std::sin(theta) > band.eps + band.dist_margin);  // the far edge is beyond
      const Ambiguity a = check_unambiguous(A, B, X, V.key(), band);
      INFO(a.why);
      CHECK(std::abs(std::atan(1.0 / (30 * std::cos(theta))) - tol) < 1e-3);
      if (theta < 1.1 * tol) {
        CHECK_FALSE(a.unambiguous);
        CHECK(a.why.find("within the band at angle") != std::string::npos);
      } else {
        CHECK(a.unambiguous);
        CHECK(a.leaning >= 1);
      }
    }
  }
}

#include <cf/geometry.hpp>
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>

namespace {

// Values below come from small integers; a few ulps of the 10-100 mm scale.
constexpr double kTol = 1e-9;

using cf::ElementKind;
using cf::Vec3;

cf::Polyhedron box(double sx, double sy, double sz) { return cf::test::box(sx, sy, sz); }

// A 30 x 30 x 10 square frame with a 10 x 10 through-hole at [10,20]^2: its top face
// (index 1) has a hole.
cf::Polyhedron frame() {
  std::vector<Vec3> v = {{0, 0, 0},    {30, 0, 0},   {30, 30, 0},  {0, 30, 0},     // outer bottom
                         {0, 0, 10},   {30, 0, 10},  {30, 30, 10}, {0, 30, 10},    // outer top
                         {10, 10, 0},  {20, 10, 0},  {20, 20, 0},  {10, 20, 0},    // inner bottom
                         {10, 10, 10}, {20, 10, 10}, {20, 20, 10}, {10, 20, 10}};  // inner top
  std::vector<std::vector<std::vector<int>>> f = {
      {{0, 3, 2, 1}, {8, 9, 10, 11}},    // bottom, hole clockwise seen from below
      {{4, 5, 6, 7}, {12, 15, 14, 13}},  // top
      {{0, 1, 5, 4}},
      {{2, 3, 7, 6}},
      {{1, 2, 6, 5}},
      {{0, 4, 7, 3}},
      // hole walls, normals pointing into the hole
      {{8, 12, 13, 9}},
      {{10, 14, 15, 11}},
      {{9, 13, 14, 10}},
      {{8, 11, 15, 12}}};
  std::vector<std::array<int, 2>> e = {{0, 1},   {1, 2},   {2, 3},   {0, 3},  {4, 5},   {5, 6},
                                       {6, 7},   {4, 7},   {0, 4},   {1, 5},  {2, 6},   {3, 7},
                                       {8, 9},   {9, 10},  {10, 11}, {8, 11}, {12, 13}, {13, 14},
                                       {14, 15}, {12, 15}, {8, 12},  {9, 13}, {10, 14}, {11, 15}};
  return cf::Polyhedron::from_features("frame", v, e, f);
}

cf::Pose translation(double x, double y, double z) {
  cf::Pose p;
  p.t_BA = Vec3(x, y, z);
  return p;
}

}  // namespace

TEST_CASE("point-face distance: plane distance inside, boundary distance outside", "[geometry]") {
  const cf::Polyhedron b = box(20, 10, 30);
  const cf::FaceId top(1);
  auto c = cf::point_face({5, 5, 33}, b, top);
  CHECK(c.distance == Approx(3).margin(kTol));
  CHECK((c.p_b - Vec3(5, 5, 30)).norm() < kTol);
  c = cf::point_face({25, 5, 34}, b, top);  // nearest point is on the edge x = 20
  CHECK(c.distance == Approx(std::sqrt(41.0)).margin(kTol));
  CHECK((c.p_b - Vec3(20, 5, 30)).norm() < kTol);
  c = cf::point_face({5, 5, 25}, b, top);  // below the plane, still projects inside
  CHECK(c.distance == Approx(5).margin(kTol));
}

TEST_CASE("point-face distance respects holes", "[geometry]") {
  const cf::Polyhedron m = frame();
  const cf::FaceId top(1);
  // Above the hole's centre: 5 mm in-plane to the hole boundary, 2 mm up.
  auto c = cf::point_face({15, 15, 12}, m, top);
  CHECK(c.distance == Approx(std::sqrt(29.0)).margin(kTol));
  CHECK(std::abs(c.p_b.z() - 10) < kTol);
  // Above the solid ring: plane distance.
  c = cf::point_face({5, 15, 12}, m, top);
  CHECK(c.distance == Approx(2).margin(kTol));
  const cf::FaceLocation loc = cf::locate_in_face(m, top, m.face_coords(top, {15, 12, 10}));
  CHECK_FALSE(loc.inside);
  CHECK(loc.boundary_distance == Approx(2).margin(kTol));
  CHECK(loc.inset() == Approx(m.face_inset(top, {15, 12, 10})).margin(kTol));
}

TEST_CASE("segment-segment distance: skew, parallel, collinear, degenerate", "[geometry]") {
  auto c = cf::segment_segment({0, 0, 0}, {2, 0, 0}, {1, -1, 1}, {1, 1, 1});
  CHECK(c.distance == Approx(1).margin(kTol));
  CHECK((c.p_a - Vec3(1, 0, 0)).norm() < kTol);
  CHECK((c.p_b - Vec3(1, 0, 1)).norm() < kTol);
  // Skew, closest points at end points: the nearest pair is (2,0,0)-(3,0,1)... here the
  // second segment lies at x = 3, beyond the first one's end.
  c = cf::segment_segment({0, 0, 0}, {2, 0, 0}, {3, -1, 1}, {3, 1, 1});
  CHECK(c.distance == Approx(std::sqrt(2.0)).margin(kTol));
  // Parallel and overlapping in projection.
  c = cf::segment_segment({0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {3, 1, 0});
  CHECK(c.distance == Approx(1).margin(kTol));
  CHECK(c.p_a.x() >= 1 - kTol);
  CHECK(c.p_a.x() <= 2 + kTol);
  // Collinear, disjoint.
  c = cf::segment_segment({0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {4, 0, 0});
  CHECK(c.distance == Approx(2).margin(kTol));
  // Antiparallel collinear, overlapping: touching.
  c = cf::segment_segment({0, 0, 0}, {2, 0, 0}, {3, 0, 0}, {1, 0, 0});
  CHECK(c.distance == Approx(0).margin(kTol));
  // A point (zero-length segment) against a segment.
  c = cf::segment_segment({1, 2, 0}, {1, 2, 0}, {0, 0, 0}, {2, 0, 0});
  CHECK(c.distance == Approx(2).margin(kTol));
}

TEST_CASE("segment-face distance", "[geometry]") {
  const cf::Polyhedron b = box(20, 10, 30);
  const cf::FaceId top(1);
  CHECK(cf::segment_face({5, 5, 25}, {5, 5, 35}, b, top).distance == Approx(0).margin(kTol));
  // Parallel above the face.
  CHECK(cf::segment_face({2, 2, 31.5}, {8, 8, 31.5}, b, top).distance == Approx(1.5).margin(kTol));
  // Tilted, lowest end inside.
  auto c = cf::segment_face({5, 5, 31}, {5, 5, 40}, b, top);
  CHECK(c.distance == Approx(1).margin(kTol));
  CHECK((c.p_b - Vec3(5, 5, 30)).norm() < kTol);
  // Passing beside the face: nearest to the edge x = 20, y in [0, 10].
  c = cf::segment_face({23, -5, 34}, {23, 15, 34}, b, top);
  CHECK(c.distance == Approx(5).margin(kTol));
  // Piercing the plane through the hole of the frame: not touching the top face.
  const cf::Polyhedron m = frame();
  c = cf::segment_face({15, 15, 5}, {15, 15, 15}, m, top);
  CHECK(c.distance == Approx(5).margin(kTol));
  // Lying in the plane across the hole: touches the ring.
  CHECK(cf::segment_face({12, 15, 10}, {25, 15, 10}, m, top).distance == Approx(0).margin(kTol));
}

TEST_CASE("face-face and element distances between posed boxes", "[geometry]") {
  const cf::Polyhedron a = box(10, 10, 10);
  const cf::Polyhedron b = box(20, 10, 30);
  // A's bottom face (0) 2 mm above B's top face (1), overlapping in projection.
  cf::Pose pose = translation(5, 0, 32);
  auto c = cf::face_face(a, pose, cf::FaceId(0), b, cf::FaceId(1));
  CHECK(c.distance == Approx(2).margin(kTol));
  CHECK(std::abs(c.p_a.z() - 32) < kTol);
  CHECK(std::abs(c.p_b.z() - 30) < kTol);
  // Shifted sideways past B's edge x = 20 by 3 mm and up 4 mm: distance 5.
  pose = translation(23, 0, 34);
  CHECK(cf::face_face(a, pose, cf::FaceId(0), b, cf::FaceId(1)).distance == Approx(5).margin(kTol));
  // Rotated 45 degrees about x and sunk so that it crosses B's top plane: 0.
  pose.R_BA = Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()).toRotationMatrix();
  pose.t_BA = Vec3(5, 2, 28);
  CHECK(cf::face_face(a, pose, cf::FaceId(0), b, cf::FaceId(1)).distance == Approx(0).margin(kTol));

  // Element pairs through the convenience function: A's bottom corner vertex 0 at (5,0,32).
  pose = translation(5, 0, 32);
  CHECK_THROWS_WITH(
      cf::element_distance(a, pose, ElementKind::kVertex, 8, b, ElementKind::kFace, 1),
      Catch::Contains("element_distance: element index 8 is out of range for its model's A"));
  CHECK_THROWS_WITH(
      cf::element_distance(a, pose, ElementKind::kVertex, 0, b, ElementKind::kFace, -1),
      Catch::Contains("element index -1 is out of range for its model's B"));
  CHECK(cf::element_distance(a, pose, ElementKind::kVertex, 0, b, ElementKind::kFace, 1).distance ==
        Approx(2).margin(kTol));
  // B's vertex 5 = (20, 0, 30) against A's bottom face [5,15] x [0,10] at z = 32: 5 in-plane, 2 up.
  c = cf::element_distance(a, pose, ElementKind::kFace, 0, b, ElementKind::kVertex, 5);
  CHECK(c.distance == Approx(std::sqrt(29.0)).margin(kTol));
  CHECK((c.p_a - Vec3(15, 0, 32)).norm() < kTol);
  CHECK((c.p_b - Vec3(20, 0, 30)).norm() < kTol);
  // A's edge 0 ((5,0,32)-(15,0,32)) against B's top face: 2.
  CHECK(cf::element_distance(a, pose, ElementKind::kEdge, 0, b, ElementKind::kFace, 1).distance ==
        Approx(2).margin(kTol));
  // B's edge 4 ((0,0,30)-(20,0,30)) against A's bottom face: 2.
  CHECK(cf::element_distance(a, pose, ElementKind::kFace, 0, b, ElementKind::kEdge, 4).distance ==
        Approx(2).margin(kTol));
  // A's edge 1 ((15,0,32)-(15,10,32)) against B's edge 5 ((20,0,30)-(20,10,30)): parallel,
  // 5 apart in x and 2 in z.
  CHECK(cf::element_distance(a, pose, ElementKind::kEdge, 1, b, ElementKind::kEdge, 5).distance ==
        Approx(std::sqrt(29.0)).margin(kTol));
  // Vertex-vertex and vertex-edge.
  CHECK(
      cf::element_distance(a, pose, ElementKind::kVertex, 0, b, ElementKind::kVertex, 4).distance ==
      Approx(std::sqrt(29.0)).margin(kTol));
  CHECK(cf::element_distance(a, pose, ElementKind::kVertex, 0, b, ElementKind::kEdge, 4).distance ==
        Approx(2).margin(kTol));
  CHECK(cf::element_distance(a, pose, ElementKind::kEdge, 0, b, ElementKind::kVertex, 5).distance ==
        Approx(std::sqrt(29.0)).margin(kTol));
}

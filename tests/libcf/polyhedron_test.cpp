#include <cf/polyhedron.hpp>
#include "fixtures.hpp"

#include <catch2/catch.hpp>

namespace {

// Unit tolerance for values computed from exact small integers: a few ulps of 100.
constexpr double kExact = 1e-12;

// Axis-aligned box [0,sx] x [0,sy] x [0,sz] with outward-oriented faces.
cf::Polyhedron box(double sx, double sy, double sz) { return cf::test::box(sx, sy, sz); }

}  // namespace

TEST_CASE("a box has the planes, convexity and mass properties of a box", "[polyhedron]") {
  const cf::Polyhedron m = box(20, 10, 30);
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  CHECK(m.volume() == Approx(6000).epsilon(kExact));
  CHECK((m.volume_centroid() - cf::Vec3(10, 5, 15)).norm() < kExact * 100);
  CHECK((m.vertex_centroid() - cf::Vec3(10, 5, 15)).norm() < kExact * 100);
  CHECK((m.face(cf::FaceId(0)).normal - cf::Vec3(0, 0, -1)).norm() < kExact);
  CHECK(m.face(cf::FaceId(1)).offset == Approx(30));
  CHECK(m.face(cf::FaceId(1)).area == Approx(200));
  for (const cf::Edge& e : m.edges()) {
    CHECK(e.convex);
    CHECK(e.dihedral == Approx(M_PI / 2));
  }
  CHECK(m.face_inset(cf::FaceId(1), {5, 5, 30}) == Approx(5));
  CHECK(m.face_inset(cf::FaceId(1), {25, 5, 30}) == Approx(-5));
}

TEST_CASE("a model with an inward orientation is rejected", "[polyhedron]") {
  std::vector<cf::Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<std::array<int, 2>> e = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  std::vector<std::vector<std::vector<int>>> inward = {
      {{0, 1, 2}}, {{0, 3, 1}}, {{0, 2, 3}}, {{1, 3, 2}}};
  CHECK_THROWS_WITH(
      cf::Polyhedron::from_features("t", v, e, inward),
      Catch::Contains("model 't': encloses a non-positive volume: faces are oriented inward"));
}

TEST_CASE("with_vertices keeps the features and derives the rest at the new coordinates",
          "[polyhedron]") {
  const cf::Polyhedron m = box(20, 10, 30);
  std::vector<cf::Vec3> v;
  for (const cf::Vertex& x : m.vertices()) v.push_back(2 * x.p + cf::Vec3(1, 2, 3));
  const cf::Polyhedron big = m.with_vertices(v);
  CHECK(big.name() == m.name());
  CHECK(big.num_edges() == m.num_edges());
  CHECK(big.num_faces() == m.num_faces());
  CHECK(big.volume() == Approx(8 * 6000).epsilon(kExact));
  CHECK((big.volume_centroid() - cf::Vec3(21, 12, 33)).norm() < kExact * 100);
  CHECK(big.face(cf::FaceId(1)).offset == Approx(63));
  CHECK(big.face(cf::FaceId(1)).loops == m.face(cf::FaceId(1)).loops);
  // A corner moved off its faces' planes, or a wrong count, is refused by name.
  v[0] += cf::Vec3(0, 0, 5);
  CHECK_THROWS_WITH(m.with_vertices(v), Catch::Contains("is not planar"));
  CHECK_THROWS_WITH(m.with_vertices({}), Catch::Contains("with_vertices: 0 vertices given for 8"));
}

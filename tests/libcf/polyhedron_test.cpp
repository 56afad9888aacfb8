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

#pragma once
// Models shared by several tests.

#include <cf/polyhedron.hpp>

#include <array>
#include <string>
#include <vector>

namespace cf::test {

/// Axis-aligned box [lo, hi] with outward-oriented faces. Vertex 0 is lo, vertex 6 is hi;
/// faces: 0 bottom (-z), 1 top (+z), 2 front (-y), 3 back (+y), 4 right (+x), 5 left (-x).
inline Polyhedron box(const Vec3& lo, const Vec3& hi, const std::string& name = "box") {
  std::vector<Vec3> v = {{lo.x(), lo.y(), lo.z()}, {hi.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), lo.z()},
                         {lo.x(), hi.y(), lo.z()}, {lo.x(), lo.y(), hi.z()}, {hi.x(), lo.y(), hi.z()},
                         {hi.x(), hi.y(), hi.z()}, {lo.x(), hi.y(), hi.z()}};
  std::vector<std::vector<std::vector<int>>> f = {
      {{0, 3, 2, 1}}, {{4, 5, 6, 7}}, {{0, 1, 5, 4}}, {{2, 3, 7, 6}}, {{1, 2, 6, 5}}, {{0, 4, 7, 3}}};
  std::vector<std::array<int, 2>> e = {{0, 1}, {1, 2}, {2, 3}, {0, 3}, {4, 5}, {5, 6},
                                       {6, 7}, {4, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  return Polyhedron::from_features(name, v, e, f);
}

/// Box [0, sx] x [0, sy] x [0, sz].
inline Polyhedron box(double sx, double sy, double sz, const std::string& name = "box") {
  return box(Vec3::Zero(), Vec3(sx, sy, sz), name);
}

}  // namespace cf::test

#pragma once
// Models built in code for the run-time tests and benchmarks: the paper's cube and L-block
// (as data/models/cube.off and l_block.off) and faceted spheres of about 2,000 faces.
// Part of tests/support, shared by the tests and the benchmarks.

#include <cf/polyhedron.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace cf::testmodels {

/// Builds a polyhedron from vertices and one outer loop per face, deriving the edges.
inline Polyhedron from_loops(const std::string& name, const std::vector<Vec3>& v,
                             const std::vector<std::vector<int>>& faces) {
  std::map<std::pair<int, int>, int> seen;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::vector<std::vector<int>>> loops;
  for (const auto& f : faces) {
    for (std::size_t k = 0; k < f.size(); ++k) {
      int a = f[k], b = f[(k + 1) % f.size()];
      if (a > b) std::swap(a, b);
      if (seen.emplace(std::make_pair(a, b), static_cast<int>(edges.size())).second)
        edges.push_back({a, b});
    }
    loops.push_back({f});
  }
  return Polyhedron::from_features(name, v, edges, loops);
}

/// data/models/cube.off: a cube of side `s` centred on its origin.
inline Polyhedron cube(double s = 30) {
  const double h = s / 2;
  return from_loops(
      "cube",
      {{-h, -h, -h},
       {h, -h, -h},
       {h, h, -h},
       {-h, h, -h},
       {-h, -h, h},
       {h, -h, h},
       {h, h, h},
       {-h, h, h}},
      {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}});
}

/// data/models/l_block.off: 120 x 80 x 80, slab (y in [0, 20]) and wall (x in [0, 20]).
/// Faces: 0 z=0, 1 z=80, 2 y=0, 3 x=120, 4 y=20 (slab top), 5 x=20 (wall side),
/// 6 y=80 (wall top), 7 x=0.
inline Polyhedron l_block() {
  return from_loops("l_block",
                    {{0, 0, 0},
                     {120, 0, 0},
                     {120, 20, 0},
                     {20, 20, 0},
                     {20, 80, 0},
                     {0, 80, 0},
                     {0, 0, 80},
                     {120, 0, 80},
                     {120, 20, 80},
                     {20, 20, 80},
                     {20, 80, 80},
                     {0, 80, 80}},
                    {{5, 4, 3, 2, 1, 0},
                     {6, 7, 8, 9, 10, 11},
                     {0, 1, 7, 6},
                     {1, 2, 8, 7},
                     {2, 3, 9, 8},
                     {3, 4, 10, 9},
                     {4, 5, 11, 10},
                     {5, 0, 6, 11}});
}

/// A UV sphere of radius r centred at c: `rings` latitude bands of `sectors` faces (planar
/// trapezoids, triangles at the poles): rings * sectors faces.
inline Polyhedron faceted_sphere(double r, int rings, int sectors, const Vec3& c = Vec3::Zero(),
                                 const std::string& name = "sphere") {
  std::vector<Vec3> v;
  v.push_back(c + Vec3(0, -r, 0));  // south pole
  for (int i = 1; i < rings; ++i) {
    const double th = M_PI * i / rings - M_PI / 2;
    for (int j = 0; j < sectors; ++j) {
      const double ph = 2 * M_PI * j / sectors;
      v.push_back(
          c + r * Vec3(std::cos(th) * std::cos(ph), std::sin(th), -std::cos(th) * std::sin(ph)));
    }
  }
  v.push_back(c + Vec3(0, r, 0));  // north pole
  const int north = static_cast<int>(v.size()) - 1;
  auto at = [&](int ring, int j) { return 1 + (ring - 1) * sectors + (j % sectors); };
  std::vector<std::vector<int>> f;
  for (int j = 0; j < sectors; ++j) f.push_back({0, at(1, j + 1), at(1, j)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < sectors; ++j)
      f.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
  for (int j = 0; j < sectors; ++j) f.push_back({north, at(rings - 1, j), at(rings - 1, j + 1)});
  return from_loops(name, v, f);
}

}  // namespace cf::testmodels

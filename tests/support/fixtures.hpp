#pragma once
// Models shared by several tests.

#include <cf/polyhedron.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>
#include <vector>

namespace cf::test {

/// Axis-aligned box [lo, hi] with outward-oriented faces. Vertex 0 is lo, vertex 6 is hi;
/// faces: 0 bottom (-z), 1 top (+z), 2 front (-y), 3 back (+y), 4 right (+x), 5 left (-x).
inline Polyhedron box(const Vec3& lo, const Vec3& hi, const std::string& name = "box") {
  std::vector<Vec3> v = {{lo.x(), lo.y(), lo.z()}, {hi.x(), lo.y(), lo.z()},
                         {hi.x(), hi.y(), lo.z()}, {lo.x(), hi.y(), lo.z()},
                         {lo.x(), lo.y(), hi.z()}, {hi.x(), lo.y(), hi.z()},
                         {hi.x(), hi.y(), hi.z()}, {lo.x(), hi.y(), hi.z()}};
  std::vector<std::vector<std::vector<int>>> f = {{{0, 3, 2, 1}}, {{4, 5, 6, 7}}, {{0, 1, 5, 4}},
                                                  {{2, 3, 7, 6}}, {{1, 2, 6, 5}}, {{0, 4, 7, 3}}};
  std::vector<std::array<int, 2>> e = {{0, 1}, {1, 2}, {2, 3}, {0, 3}, {4, 5}, {5, 6},
                                       {6, 7}, {4, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  return Polyhedron::from_features(name, v, e, f);
}

/// Box [0, sx] x [0, sy] x [0, sz].
inline Polyhedron box(double sx, double sy, double sz, const std::string& name = "box") {
  return box(Vec3::Zero(), Vec3(sx, sy, sz), name);
}

/// A polyhedron from its vertices and face loops (every loop side is an edge; edges in
/// ascending order of their end points).
inline Polyhedron from_loops(const std::string& name, const std::vector<Vec3>& v,
                             const std::vector<std::vector<int>>& faces) {
  std::set<std::array<int, 2>> edges;
  std::vector<std::vector<std::vector<int>>> loops;
  for (const auto& f : faces) {
    for (std::size_t i = 0; i < f.size(); ++i) {
      const int a = f[i], b = f[(i + 1) % f.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
    loops.push_back({f});
  }
  return Polyhedron::from_features(name, v, {edges.begin(), edges.end()}, loops);
}

/// A small L-shaped block: profile (0,0) (40,0) (40,10) (10,10) (10,40) (0,40), vertices
/// 0..5 at z=0 and 6..11 at z=20. Faces: 0 z=0, 1 z=20, then side i+2 over profile edge
/// i -> i+1: 2 y=0 (bottom), 3 x=40, 4 y=10 (floor top), 5 x=10 (wall, facing +x), 6 y=40
/// (wall top), 7 x=0. Edges 0..5 bottom ring, 6..11 top ring, 12..17 verticals; edge 15
/// (3,9) is the reflex corner between floor and wall.
inline Polyhedron small_l_block() {
  const double px[6] = {0, 40, 40, 10, 10, 0};
  const double py[6] = {0, 0, 10, 10, 40, 40};
  std::vector<Vec3> v;
  for (double z : {0.0, 20.0})
    for (int i = 0; i < 6; ++i) v.emplace_back(px[i], py[i], z);
  std::vector<std::vector<std::vector<int>>> f = {{{0, 5, 4, 3, 2, 1}}, {{6, 7, 8, 9, 10, 11}}};
  for (int i = 0; i < 6; ++i) f.push_back({{i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6}});
  std::vector<std::array<int, 2>> e;
  for (int ring : {0, 6})
    for (int i = 0; i < 6; ++i) {
      const int a = ring + i, b = ring + (i + 1) % 6;
      e.push_back({std::min(a, b), std::max(a, b)});
    }
  for (int i = 0; i < 6; ++i) e.push_back({i, i + 6});
  return Polyhedron::from_features("L-block", v, e, f);
}

/// Index of the edge joining vertices v0 and v1 of m, or -1.
inline int edge_between(const Polyhedron& m, int v0, int v1) {
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const Edge& E = m.edges()[e];
    if ((E.v0.value() == v0 && E.v1.value() == v1) || (E.v0.value() == v1 && E.v1.value() == v0))
      return static_cast<int>(e);
  }
  return -1;
}

/// Index of the face of m with this outward unit normal and plane offset (mm), or -1.
inline int face_with_plane(const Polyhedron& m, const Vec3& n, double offset) {
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    if (m.faces()[f].normal.dot(n) > 1 - 1e-12 && std::abs(m.faces()[f].offset - offset) < 1e-9)
      return static_cast<int>(f);
  return -1;
}

/// Index of the vertex of m at x (within 1e-9 mm), or -1.
inline int vertex_at(const Polyhedron& m, const Vec3& x) {
  for (std::size_t v = 0; v < m.num_vertices(); ++v)
    if ((m.vertices()[v].p - x).norm() < 1e-9) return static_cast<int>(v);
  return -1;
}

/// m with every vertex moved by x -> R x + t (same elements and numbering).
inline Polyhedron moved(const Polyhedron& m, const Eigen::Matrix3d& R, const Vec3& t) {
  std::vector<Vec3> v;
  for (const auto& x : m.vertices()) v.push_back(R * x.p + t);
  return m.with_vertices(std::move(v));
}

}  // namespace cf::test

#pragma once
// A pair of the independent oracle's shape families (tests/oracle/shapes.hpp), written out and
// read back through cfgen's loader, with the oracle's own polyhedra rebuilt from what cfgen
// read: both sides then number the elements alike; and one of the oracle's meshes as cfgen's
// model (from_oracle). For the tests that link cfgen_core and the oracle (cf_oracle).

#include "mesh/model_loader.hpp"
#include "poly.hpp"
#include "scratch.hpp"
#include "shapes.hpp"

#include <cf/polyhedron.hpp>

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace cf::test {

/// The oracle's polyhedron, from the vertices, edges and face loops of `m` (the oracle
/// derives everything else itself).
inline oracle::Poly to_oracle(const cf::Polyhedron& m, const std::string& name) {
  std::vector<oracle::Vec3> verts;
  for (const cf::Vertex& v : m.vertices()) verts.push_back(v.p);
  std::vector<std::array<int, 2>> edges;
  for (const cf::Edge& e : m.edges())
    edges.push_back({static_cast<int>(e.v0.index()), static_cast<int>(e.v1.index())});
  std::vector<std::vector<std::vector<int>>> faces;
  for (const cf::Face& f : m.faces()) {
    std::vector<std::vector<int>> loops;
    for (const auto& loop : f.loops) {
      loops.emplace_back();
      for (cf::VertexId v : loop) loops.back().push_back(static_cast<int>(v.index()));
    }
    faces.push_back(loops);
  }
  return oracle::build_poly(verts, edges, faces, name);
}

/// cfgen's model of one of the oracle's meshes, read as its loader reads a file's polygon
/// soup (coplanar facets joined into faces, vertices inside a face or an edge dropped).
inline cf::Polyhedron from_oracle(const oracle::Mesh& mesh, const std::string& name) {
  cf::tools::PolygonSoup soup;
  soup.points = mesh.V;
  soup.polygons = mesh.F;
  cf::tools::LoadOptions options;
  options.name = name;
  return cf::tools::model_from_soup(soup, name, options);
}

struct OraclePair {
  cf::Polyhedron A, B;
  oracle::Poly oA, oB;
  cf::Vec3 cA, cB;        // bounding-box centres (own frames)
  double rA = 0, rB = 0;  // half diagonals, mm
};

/// The oracle's pair of `seed` (pairing seed % oracle::kPairings).
inline OraclePair make_oracle_pair(std::uint64_t seed) {
  const oracle::ShapePair sp = oracle::make_pair(seed);
  const std::string tag = std::to_string(seed);
  const std::string a = (scratch() / ("A" + tag + ".off")).string();
  const std::string b = (scratch() / ("B" + tag + ".off")).string();
  oracle::write_off(sp.A, a);
  oracle::write_off(sp.B, b);
  OraclePair p;
  p.A = cf::tools::load_model(a);
  p.B = cf::tools::load_model(b);
  p.oA = to_oracle(p.A, "A");
  p.oB = to_oracle(p.B, "B");
  p.cA = 0.5 * (p.A.bbox_min() + p.A.bbox_max());
  p.cB = 0.5 * (p.B.bbox_min() + p.B.bbox_max());
  p.rA = 0.5 * (p.A.bbox_max() - p.A.bbox_min()).norm();
  p.rB = 0.5 * (p.B.bbox_max() - p.B.bbox_min()).norm();
  return p;
}

inline cf::Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  cf::Vec3 v(g(rng), g(rng), g(rng));
  return v.normalized();
}

/// A posed with its bounding sphere clear of B's, along a random direction `away` from B's
/// centre: no pair touches.
inline cf::Pose clear_pose(const OraclePair& p, std::mt19937_64& rng, cf::Vec3& away) {
  cf::Pose X;
  X.R_BA = oracle::random_rotation(rng);
  away = random_unit(rng);
  X.t_BA = p.cB + (p.rA + p.rB + 1.0) * away - X.R_BA * p.cA;
  return X;
}

}  // namespace cf::test

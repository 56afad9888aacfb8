// Tests of the rule for two e-e PCs at mirror corners (tools/cfgen/decide/mirror_corners.cpp):
// which pairs it refutes on the cube against the L-block (docs/generator.md, "Two e-e PCs at
// mirror corners"), that it refutes none of the pairs of PCs of any CF of the bundled graphs
// (their witnesses were verified apart from it), and that it decides exactly: the same models
// moved by a motion exact in binary refute the same pairs, a turn that rounds the coordinates
// none.

#include "cfgen/decide/mirror_corners.hpp"
#include "mesh/model_loader.hpp"

#include <cf/graph.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <string>
#include <vector>

using cf::Pc;
using cf::PcType;
using cf::Polyhedron;
using cf::Vec3;

namespace {

Polyhedron model(const std::string& name) {
  return cf::tools::load_model(std::string(CF_SOURCE_DIR) + "/data/models/" + name);
}

// Pairs of edges of a model that share an end vertex.
std::vector<std::array<int, 2>> corner_pairs(const Polyhedron& m) {
  std::vector<std::array<int, 2>> out;
  for (const cf::Vertex& v : m.vertices())
    for (std::size_t i = 0; i < v.edges.size(); ++i)
      for (std::size_t j = i + 1; j < v.edges.size(); ++j)
        out.push_back({static_cast<int>(v.edges[i].index()), static_cast<int>(v.edges[j].index())});
  return out;
}

Pc ee(int a, int b) { return Pc{PcType::kEE, a, b}; }

// Every pair of e-e PCs whose A edges share a vertex and whose B edges share one, each
// assignment of B's edges to A's once: the ones the rule refutes.
std::vector<std::array<Pc, 2>> refuted(const Polyhedron& A, const Polyhedron& B) {
  std::vector<std::array<Pc, 2>> out;
  for (const auto& a : corner_pairs(A))
    for (const auto& b : corner_pairs(B))
      for (int swap = 0; swap < 2; ++swap) {
        const Pc p = ee(a[0], b[swap]), q = ee(a[1], b[1 - swap]);
        if (cf::gen::mirror_corners(A, B, p, q)) out.push_back({p, q});
      }
  return out;
}

Polyhedron moved(const Polyhedron& m, const Eigen::Matrix3d& R, const Vec3& t) {
  std::vector<Vec3> v;
  for (const cf::Vertex& x : m.vertices()) v.push_back(R * x.p + t);
  return m.with_vertices(v);
}

}  // namespace

TEST_CASE("on the cube and L-block the rule refutes one order of the pairs at the reflex corners") {
  const Polyhedron A = model("cube.off"), B = model("l_block.off");
  const auto r = refuted(A, B);
  // The L's two corners where its reflex edge meets the end faces (20, 20, 0) and (20, 20, 80),
  // each with two rims on its end face: 8 cube corners x 3 pairs of edges x 1 order of 2.
  CHECK(r.size() == 48);
  for (const auto& [p, q] : r) {
    const cf::Edge &b1 = B.edges()[static_cast<std::size_t>(p.b)],
                   &b2 = B.edges()[static_cast<std::size_t>(q.b)];
    int w = -1;
    for (auto v : {b1.v0, b1.v1})
      if (v == b2.v0 || v == b2.v1) w = static_cast<int>(v.index());
    REQUIRE(w >= 0);
    const Vec3& pw = B.vertices()[static_cast<std::size_t>(w)].p;
    CHECK(pw.x() == 20);
    CHECK(pw.y() == 20);
    CHECK((pw.z() == 0 || pw.z() == 80));
    // The rims lie on the end face, across x and y: perpendicular, both horizontal.
    CHECK(b1.dir.z() == 0);
    CHECK(b2.dir.z() == 0);
    CHECK(b1.dir.dot(b2.dir) == 0);
    // The other order (A's edges swapped) is the same-handed pairing, which has poses.
    CHECK_FALSE(cf::gen::mirror_corners(A, B, ee(p.a, q.b), ee(q.a, p.b)));
    // The rule is a property of the pair of PCs, not of their order in the set.
    CHECK(cf::gen::mirror_corners(A, B, q, p));
  }
}

TEST_CASE("the rule refutes no pair of PCs of a CF of the bundled graphs") {
  for (const char* name : {"cube_l_block.json", "cube_corner_block.json", "peg_hole_block.json"}) {
    INFO(name);
    const cf::CfGraph g = cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/" + name);
    std::size_t pairs = 0, against = 0;
    for (std::size_t i = 0; i < g.num_cfs(); ++i) {
      const cf::PcSet& s = g.cf(cf::CfId(static_cast<int>(i))).pcs;
      for (int x = 0; x < s.size(); ++x)
        for (int y = x + 1; y < s.size(); ++y) {
          pairs += s[x].type == PcType::kEE && s[y].type == PcType::kEE;
          if (cf::gen::mirror_corners(g.model_a(), g.model_b(), s[x], s[y])) {
            ++against;
            UNSCOPED_INFO("refuted " << cf::to_string(s[x]) << " with " << cf::to_string(s[y]));
          }
        }
    }
    CHECK(pairs >= 96);  // e-e pairs the rule had to pass (96 on the cube and L-block)
    CHECK(against == 0);
  }
}

TEST_CASE("the rule decides on the coordinates exactly: exact motions keep it, rounding ends it") {
  const Polyhedron A = model("cube.off"), B = model("l_block.off");
  // A quarter turn about z and a translation by whole and half millimetres: every coordinate
  // exact in binary, so the corners stay exactly congruent.
  Eigen::Matrix3d quarter;
  quarter << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const Polyhedron A2 = moved(A, quarter, Vec3(3.5, -7, 12.25));
  const Polyhedron B2 = moved(B, quarter.transpose(), Vec3(-40, 0.5, 2));
  CHECK(refuted(A2, B2).size() == 48);
  // A generic turn rounds the coordinates: the angles and the right dihedral angles are then
  // equal only to about 1e-16, which the theorem does not cover (a corner angle off by d admits
  // poses whose margins grow like sqrt(d)); the rule refutes nothing rather than guess.
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  CHECK(refuted(moved(A, turn, Vec3::Zero()), B).empty());
}

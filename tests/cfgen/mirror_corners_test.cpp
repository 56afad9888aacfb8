// Tests of the rule for two e-e PCs at mirror corners (tools/cfgen/decide/mirror_corners.cpp):
// which pairs it refutes on the cube against the L-block (docs/generator.md, "Two e-e PCs at
// mirror corners"), that it refutes none of the pairs of PCs of any CF of the bundled graphs
// (their witnesses were verified apart from it), and that it holds on rounded coordinates: the
// same models moved by any motion refute the same pairs, a corner angle changed by far more
// than the theorem's tolerance none.

#include "cfgen/decide/mirror_corners.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"

#include <cf/graph.hpp>

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <string>
#include <vector>

using cf::Pc;
using cf::PcType;
using cf::Polyhedron;
using cf::Vec3;
using cf::test::moved;

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

// The verifier's local slack at the default --angle-margin (1e-3 rad): half its sine.
const double kSlack = 0.5 * std::sin(1e-3);

bool mirror(const Polyhedron& A, const Polyhedron& B, const Pc& p, const Pc& q) {
  return cf::gen::mirror_corners(A, B, p, q, kSlack);
}

// Every pair of e-e PCs whose A edges share a vertex and whose B edges share one, each
// assignment of B's edges to A's once: the ones the rule refutes.
std::vector<std::array<Pc, 2>> refuted(const Polyhedron& A, const Polyhedron& B) {
  std::vector<std::array<Pc, 2>> out;
  for (const auto& a : corner_pairs(A))
    for (const auto& b : corner_pairs(B))
      for (int swap = 0; swap < 2; ++swap) {
        const Pc p = ee(a[0], b[swap]), q = ee(a[1], b[1 - swap]);
        if (mirror(A, B, p, q)) out.push_back({p, q});
      }
  return out;
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
    CHECK_FALSE(mirror(A, B, ee(p.a, q.b), ee(q.a, p.b)));
    // The rule is a property of the pair of PCs, not of their order in the set.
    CHECK(mirror(A, B, q, p));
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
          if (mirror(g.model_a(), g.model_b(), s[x], s[y])) {
            ++against;
            UNSCOPED_INFO("refuted " << cf::to_string(s[x]) << " with " << cf::to_string(s[y]));
          }
        }
    }
    CHECK(pairs >= 96);  // e-e pairs the rule had to pass (96 on the cube and L-block)
    CHECK(against == 0);
  }
}

TEST_CASE("the rule holds on rounded coordinates and ends where the corners stop being mirrors") {
  const Polyhedron A = model("cube.off"), B = model("l_block.off");
  // Generic motions of both models round every coordinate: angles and right dihedral angles
  // then hold to about 1e-16, far inside the theorem's tolerance (5.8e-8 for right corners at
  // this slack).
  const Eigen::Matrix3d ra = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d rb =
      Eigen::AngleAxisd(-2.1, Vec3(-3, 1, 0.5).normalized()).toRotationMatrix();
  CHECK(refuted(moved(A, ra, Vec3(3.1, -7.7, 0.3)), moved(B, rb, Vec3(-40.2, 11.9, 5.5))).size() ==
        48);
  // The L's outer slab edge (120, 20, z) moved up by h turns the rim from w = (20, 20, 80) along
  // +x by h / 100 rad towards the other rim (+y): the corner's angle changes by that much.
  auto lean = [&](double h) {
    std::vector<Vec3> v;
    for (const cf::Vertex& x : B.vertices())
      v.push_back(x.p.x() == 120 && x.p.y() == 20 ? Vec3(120, 20 + h, x.p.z()) : x.p);
    return B.with_vertices(v);
  };
  // 1e-9 rad: still refuted at both reflex corners. 1e-5 rad, far above the tolerance, is not
  // (such corners have poses whose margins grow like the square root of the mismatch: about
  // 1.8e-3 here, above the slack).
  CHECK(refuted(A, lean(1e-7)).size() == 48);
  CHECK(refuted(A, lean(1e-3)).empty());
  // The slack sets the tolerance: at a hundredth of it, 1e-9 rad is already too much.
  const Polyhedron leaned = lean(1e-7);
  std::size_t kept = 0;
  for (const auto& [p, q] : refuted(A, leaned))
    kept += cf::gen::mirror_corners(A, leaned, p, q, kSlack / 100);
  CHECK(kept == 0);
}

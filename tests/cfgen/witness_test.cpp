// Tests of the witness search's search near given rotations (tools/cfgen/decide/witness.cpp,
// WitnessSearch::find with seeds_only, and its last stage, the climb past obstacles), on a
// hexagonal peg in a hexagonal through-hole 5% wider: CFs of a peg tilted across the hole's
// rim hold only in a sliver of orientations, and a rotation a few hundredths of a radian off
// places the contacts but runs A into another pair of elements.

#include "cfgen/decide/witness.hpp"
#include "analysed_pair.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/generate.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"
#include "ngon_models.hpp"
#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace {

// The rotations find(seeds_only) tries before its climb: the seed, and the seed turned by
// 0.01 and 0.025 rad about each axis, both ways (sets of point PCs: no projection).
std::vector<cf::Mat3> tried_before_climb(const cf::Mat3& seed) {
  std::vector<cf::Mat3> out{seed};
  for (double ang : {0.01, 0.025})
    for (int ax = 0; ax < 3; ++ax)
      for (double sg : {1.0, -1.0})
        out.push_back(cf::gen::axis_angle(sg * cf::Vec3::Unit(ax), ang) * seed);
  return out;
}

}  // namespace

TEST_CASE(
    "witness search near given rotations: from a rotation turned off a witness, the climb past "
    "obstacles finds the CF again, and every pose it returns verifies",
    "[witness][cfgen]") {
  const auto [peg, hole] = cf::test::ngon_peg_and_hole(6, "witness");
  cf::test::AnalysedPair p(cf::tools::load_model(peg, {}), cf::tools::load_model(hole, {}));
  cf::gen::EnumerateOptions opt;
  opt.max_pcs = 2;  // the pairs: seconds, not the whole graph
  cf::gen::ExecuteOptions exec;
  exec.threads = 2;
  const cf::gen::SearchParams params = cf::tools::scaled_search(p.A, p.B, {});
  const cf::gen::Enumeration e = cf::gen::enumerate_pair(p.ai, p.bi, params, opt, exec);
  const cf::gen::WitnessSearch search(p.ai, p.bi, params);
  // The turn off each witness: larger than the slivers (a few hundredths of a radian), small
  // against the spread the search's own samples keep (0.15 rad).
  constexpr double kTurn = 0.06;  // rad
  const cf::Vec3 axis = cf::Vec3(0.36, -0.48, 0.8).normalized();
  std::size_t tried = 0, found = 0, climbed = 0;
  for (const auto& r : e.cfs) {
    if (r.pcs.size() != 2) continue;
    bool point_pcs = true;  // no rotational condition: the rotations tried are not projected
    for (const cf::Pc& pc : r.pcs)
      point_pcs = point_pcs && (pc.type == cf::PcType::kVF || pc.type == cf::PcType::kFV ||
                                pc.type == cf::PcType::kEE);
    if (!point_pcs) continue;
    const cf::Mat3 seed = cf::gen::axis_angle(axis, kTurn) * r.witness.R_BA;
    const cf::gen::Witness w = search.find(r.pcs, {seed}, true);
    ++tried;
    if (!w.found) continue;
    ++found;
    // The only gate to the graph: whatever the search returns verifies.
    CHECK(search.verify(r.pcs, w.pose) >= params.min_clearance);
    const std::vector<cf::Mat3> before = tried_before_climb(seed);
    const bool from_climb = std::none_of(before.begin(), before.end(), [&](const cf::Mat3& R) {
      return (R - w.pose.R_BA).norm() < 1e-12;  // the same rotation, bit for bit or nearly
    });
    climbed += from_climb ? 1 : 0;
  }
  INFO("tried " << tried << ", found " << found << ", of which " << climbed << " by the climb");
  REQUIRE(tried > 1000);
  // Measured on 9,324 sets: 6,605 found (71%), 610 of them (6.5% of the sets) at a rotation
  // the climb turned to (none of the rotations tried before it). Bounds a little below what
  // was measured, so that only a real loss fails.
  CHECK(found * 100 >= tried * 65);
  CHECK(climbed * 100 >= tried * 5);
}

TEST_CASE(
    "witness search: a cube wedged across a square hole by two opposite edges on the facing "
    "walls, where A's width across the walls must be the hole's",
    "[witness][cfgen]") {
  // A cube of side 16.8 (a square prism along y) and a block 6.56 thick with a square hole
  // of side 18.5, both as diamonds in xz. Two diagonally opposite side edges of the cube on two
  // facing walls: the walls' planes are parallel, so a translation places both edges only
  // where the cube's width across them is 18.5, a condition on the rotation that random
  // rotations never meet (translation_residual with two PCs).
  const double side = 16.8, hole = 18.5;
  const double r = side / std::sqrt(2.0), r_in = hole / std::sqrt(2.0);
  const std::string a =
      cf::test::write_file("wedge_cube.off", cf::test::ngon_off(4, r, 0, 0, side));
  const std::string b =
      cf::test::write_file("wedge_hole.off", cf::test::ngon_off(4, 25, r_in, 0, 6.56));
  cf::test::AnalysedPair p(cf::tools::load_model(a, {}), cf::tools::load_model(b, {}));
  const cf::gen::SearchParams params = cf::tools::scaled_search(p.A, p.B, {});
  const cf::gen::WitnessSearch search(p.ai, p.bi, params);
  auto edge_at = [&](double x, double z) {
    return cf::test::edge_between(p.A, cf::test::vertex_at(p.A, {x, 0, z}),
                                  cf::test::vertex_at(p.A, {x, side, z}));
  };
  const int e0 = edge_at(r, 0), e2 = edge_at(-r, 0);
  const cf::Vec3 n = cf::Vec3(1, 0, 1).normalized();
  const int wall_out = cf::test::face_with_plane(p.B, -n, -r_in / std::sqrt(2.0));
  const int wall_in = cf::test::face_with_plane(p.B, n, -r_in / std::sqrt(2.0));
  REQUIRE(e0 >= 0);
  REQUIRE(e2 >= 0);
  REQUIRE(wall_out >= 0);
  REQUIRE(wall_in >= 0);
  cf::PcSet pcs;
  pcs.insert(cf::Pc{cf::PcType::kEF, e0, wall_out});
  pcs.insert(cf::Pc{cf::PcType::kEF, e2, wall_in});
  const cf::gen::Witness w = search.find(pcs, {});
  REQUIRE(w.found);
  CHECK(search.verify(pcs, w.pose) >= params.min_clearance);
  // The edges' separation across the walls is the hole's width: each edge lies on its wall to
  // the touch tolerance, and parallel to it to the rotational conditions' 1e-8, which over
  // the 17 mm edge is under 2e-7 mm.
  constexpr double kWidthTol = 1e-6;  // mm
  const cf::Vec3 d = w.pose.R_BA * (p.A.vertices()[p.A.edges()[e0].v0.index()].p -
                                    p.A.vertices()[p.A.edges()[e2].v0.index()].p);
  CHECK(std::abs(std::abs(d.dot(n)) - hole) < kWidthTol);
}

// Tests of the generator's per-model facts (tools/cfgen/verify/analysis.cpp): the points of an
// element at least a margin inside it, worked out by hand on the cube and the L-block; the
// index of the elements' boxes against a brute-force test.

#include "cfgen/verify/analysis.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

using cf::ElementKind;
using cf::Vec3;

namespace {

// Sums and products of exact inputs: rounding only.
constexpr double kLength = 1e-12;

std::string model(const std::string& name) {
  return std::string(CF_SOURCE_DIR) + "/data/models/" + name;
}

bool holds(const std::vector<Vec3>& pts, const Vec3& q) {
  return std::any_of(pts.begin(), pts.end(),
                     [&](const Vec3& p) { return (p - q).norm() < kLength; });
}

}  // namespace

TEST_CASE(
    "inset closure points: an edge's ends moved in, a convex face's corners moved in, others "
    "whole") {
  const cf::Polyhedron cube = cf::tools::load_model(model("cube.off"));  // [-15, 15]^3
  const cf::Polyhedron l = cf::tools::load_model(model("l_block.off"));
  constexpr double m = 0.25;  // mm

  // A vertex is itself.
  const int corner = cf::test::vertex_at(cube, Vec3(15, 15, 15));
  REQUIRE(corner >= 0);
  CHECK(cf::gen::inset_closure_points(cube, ElementKind::kVertex, corner, m) ==
        std::vector<Vec3>{Vec3(15, 15, 15)});

  // An edge of 30 mm keeps [m, 30 - m].
  for (std::size_t e = 0; e < cube.num_edges(); ++e) {
    const std::vector<Vec3> pts =
        cf::gen::inset_closure_points(cube, ElementKind::kEdge, int(e), m);
    REQUIRE(pts.size() == 2);
    const Vec3 a = cube.edge_point(cf::EdgeId(int(e)), 0),
               b = cube.edge_point(cf::EdgeId(int(e)), 1);
    CHECK((pts[0] - a).norm() == Approx(m).margin(kLength));
    CHECK((pts[1] - b).norm() == Approx(m).margin(kLength));
    CHECK((pts[1] - pts[0]).norm() == Approx(30 - 2 * m).margin(kLength));
  }
  // An edge shorter than twice the margin keeps its ends.
  CHECK(cf::gen::inset_closure_points(cube, ElementKind::kEdge, 0, 16).size() == 2);
  CHECK(cf::gen::inset_closure_points(cube, ElementKind::kEdge, 0, 16)[0] ==
        cube.edge_point(cf::EdgeId(0), 0));

  // The cube's top: the square [-15 + m, 15 - m]^2 at z = 15.
  const int top = cf::test::face_with_plane(cube, Vec3(0, 0, 1), 15);
  REQUIRE(top >= 0);
  const std::vector<Vec3> sq = cf::gen::inset_closure_points(cube, ElementKind::kFace, top, m);
  REQUIRE(sq.size() == 4);
  const double c = 15 - m;
  for (const Vec3& q : {Vec3(c, c, 15), Vec3(-c, c, 15), Vec3(c, -c, 15), Vec3(-c, -c, 15)})
    CHECK(holds(sq, q));
  // A 30 mm square holds one point 15 mm inside (its centre) and none farther: whole.
  CHECK(holds(cf::gen::inset_closure_points(cube, ElementKind::kFace, top, 15), Vec3(0, 0, 15)));
  CHECK(holds(cf::gen::inset_closure_points(cube, ElementKind::kFace, top, 16), Vec3(15, 15, 15)));

  // The L-block's end (z = 0) is L-shaped, a reflex corner at (20, 20): its whole closure.
  const int end = cf::test::face_with_plane(l, Vec3(0, 0, -1), 0);
  REQUIRE(end >= 0);
  const std::vector<Vec3> lpts = cf::gen::inset_closure_points(l, ElementKind::kFace, end, m);
  CHECK(lpts.size() == 6);
  CHECK(holds(lpts, Vec3(20, 20, 0)));
  CHECK(holds(lpts, Vec3(120, 0, 0)));
  // Its slab's top (y = 20, x in [20, 120], z in [0, 80]) is a rectangle.
  const int slab_top = cf::test::face_with_plane(l, Vec3(0, 1, 0), 20);
  const std::vector<Vec3> r = cf::gen::inset_closure_points(l, ElementKind::kFace, slab_top, m);
  REQUIRE(r.size() == 4);
  for (const Vec3& q : {Vec3(20 + m, 20, m), Vec3(120 - m, 20, m), Vec3(20 + m, 20, 80 - m),
                        Vec3(120 - m, 20, 80 - m)})
    CHECK(holds(r, q));
}

TEST_CASE(
    "box index: the boxes meeting a query box, as a brute-force test over every box finds them") {
  // Random boxes on a coarse lattice, so that ends coincide (ties at the sorted bounds) and
  // queries touch boxes exactly at an end (closed boxes meet there).
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(-6, 6), extent(0, 4);
  for (int n : {1, 5, 63, 64, 65, 200}) {
    std::vector<Vec3> lo, hi;
    for (int i = 0; i < n; ++i) {
      const Vec3 l(coord(rng), coord(rng), coord(rng));
      lo.push_back(l);
      hi.push_back(l + Vec3(extent(rng), extent(rng), extent(rng)));
    }
    const cf::gen::BoxIndex index(lo, hi);
    REQUIRE(index.size() == n);
    REQUIRE(index.words() == (n + 63) / 64);
    std::vector<std::uint64_t> bits(static_cast<std::size_t>(index.words()));
    for (int q = 0; q < 300; ++q) {
      const Vec3 ql(coord(rng), coord(rng), coord(rng));
      const Vec3 qh = ql + Vec3(extent(rng), extent(rng), extent(rng));
      index.query(ql, qh, bits.data());
      for (int i = 0; i < n; ++i) {
        const bool meets =
            (lo[i].array() <= qh.array()).all() && (hi[i].array() >= ql.array()).all();
        const bool listed = (bits[static_cast<std::size_t>(i / 64)] >> (i % 64)) & 1u;
        INFO("n " << n << " box " << i << " query " << ql.transpose() << " .. " << qh.transpose());
        CHECK(listed == meets);
      }
      // No bit past the last box.
      if (n % 64 != 0) CHECK((bits.back() >> (n % 64)) == 0u);
    }
  }
}

TEST_CASE(
    "box index: real-valued boxes, clustered ends and queries beyond every box agree with brute "
    "force") {
  // The search for a query's end runs in one bucket of the sorted ends: ends piled on one
  // value (a face's vertices on one plane), boxes of zero extent, ends far apart in scale and
  // queries wholly outside the boxes' range all exercise the bucket bounds.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto check_all = [&](const std::vector<Vec3>& lo, const std::vector<Vec3>& hi,
                       const std::vector<std::pair<Vec3, Vec3>>& queries) {
    const cf::gen::BoxIndex index(lo, hi);
    std::vector<std::uint64_t> bits(static_cast<std::size_t>(index.words()));
    for (const auto& [ql, qh] : queries) {
      index.query(ql, qh, bits.data());
      for (std::size_t i = 0; i < lo.size(); ++i) {
        const bool meets =
            (lo[i].array() <= qh.array()).all() && (hi[i].array() >= ql.array()).all();
        const bool listed = (bits[i / 64] >> (i % 64)) & 1u;
        INFO("box " << i << " query " << ql.transpose() << " .. " << qh.transpose());
        CHECK(listed == meets);
      }
    }
  };
  std::vector<Vec3> lo, hi;
  std::vector<std::pair<Vec3, Vec3>> queries;
  for (int i = 0; i < 150; ++i) {
    // A third of the boxes share their lower x and z (one plane), some are points, and the
    // rest spread over six orders of magnitude.
    const double s = std::pow(10.0, 3.0 * unit(rng));
    Vec3 l(i % 3 == 0 ? 2.5 : s * unit(rng), unit(rng), i % 3 == 0 ? -1.0 : s * unit(rng));
    lo.push_back(l);
    hi.push_back(i % 5 == 0 ? l : Vec3(l + s * Vec3(unit(rng), unit(rng), unit(rng)).cwiseAbs()));
  }
  for (int q = 0; q < 400; ++q) {
    const double s = std::pow(10.0, 3.5 * unit(rng));
    Vec3 l = s * Vec3(unit(rng), unit(rng), unit(rng));
    if (q % 7 == 0) l = lo[static_cast<std::size_t>(q) % lo.size()];  // an end exactly
    queries.push_back({l, l + s * Vec3(unit(rng), unit(rng), unit(rng)).cwiseAbs()});
  }
  queries.push_back({Vec3::Constant(-1e300), Vec3::Constant(-1e299)});  // below every box
  queries.push_back({Vec3::Constant(1e299), Vec3::Constant(1e300)});    // above every box
  queries.push_back({Vec3::Constant(-1e300), Vec3::Constant(1e300)});   // around every box
  check_all(lo, hi, queries);
  // Every box the same: the ends span nothing, and one bucket holds them all.
  check_all(std::vector<Vec3>(70, Vec3(1, 2, 3)), std::vector<Vec3>(70, Vec3(1, 2, 3)),
            {{Vec3(1, 2, 3), Vec3(1, 2, 3)},
             {Vec3(0, 0, 0), Vec3(0.5, 5, 5)},
             {Vec3(0, 0, 0), Vec3(5, 5, 5)}});
}

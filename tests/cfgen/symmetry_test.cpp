// Tests of the models' symmetries (tools/cfgen/enumerate/symmetry.cpp) and of the generator's use
// of them: counts of symmetry groups worked out by hand, the image of a pose checked point by
// point, and a graph generated with one search per orbit checked for closure under the
// symmetries and against a run that searches every set.

#include "cfgen/enumerate/symmetry.hpp"
#include "analysed_pair.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/generate.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"
#include "ngon_models.hpp"
#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <set>
#include <sstream>
#include <string>

using cf::Pose;
using cf::Vec3;
using cf::gen::PairSymmetries;
using cf::gen::symmetries;

using cf::test::moved;

namespace {

// Vertices of the test models are given to 1e-15 relative; rigid maps and their images are
// exact to a few ulps of coordinates of tens of mm.
constexpr double kTol = 1e-9;  // mm

// The PC sets of an enumeration's CFs, as text.
std::set<std::string> cf_sets(const cf::gen::Enumeration& e) {
  std::set<std::string> out;
  for (const auto& r : e.cfs) out.insert(cf::to_string(r.pcs));
  return out;
}

// cfgen's default search for the pair (lengths scaled to it).
cf::gen::SearchParams search_for(const cf::test::AnalysedPair& p) {
  return cf::tools::scaled_search(p.A, p.B, {});
}

// The pair enumerated with the generator's defaults, on two threads.
cf::gen::Enumeration enumerate(const cf::test::AnalysedPair& p,
                               const cf::gen::EnumerateOptions& opt) {
  cf::gen::ExecuteOptions exec;
  exec.threads = 2;
  return cf::gen::enumerate_pair(p.ai, p.bi, search_for(p), opt, exec);
}

int proper(const std::vector<cf::gen::Symmetry>& s) {
  int n = 0;
  for (const auto& x : s) n += x.R.determinant() > 0 ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("symmetry: the groups of a cube, a box and an L-block, wherever they are placed",
          "[symmetry]") {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(n01(rng), n01(rng), n01(rng), n01(rng)).normalized().toRotationMatrix();
  const Vec3 t(12.5, -3.25, 40);
  struct Case {
    cf::Polyhedron m;
    std::size_t all, rotations;
  };
  // A cube: the 48 maps of the octahedral group, 24 of them rotations. A 10 x 20 x 30 box:
  // the three half turns and the identity, and as many reflections. The L-block: its profile is
  // symmetric about x = y and its slab about its middle plane.
  const std::vector<Case> cases = {{cf::test::box(20, 20, 20, "cube"), 48, 24},
                                   {cf::test::box(10, 20, 30), 8, 4},
                                   {cf::test::small_l_block(), 4, 2}};
  for (const Case& c : cases)
    for (const cf::Polyhedron& m : {c.m, moved(c.m, R, t)}) {
      INFO(m.name());
      const auto s = symmetries(m, 1e-13 * m.size());
      CHECK(s.size() == c.all);
      CHECK(proper(s) == static_cast<int>(c.rotations));
      CHECK(s.front().R.isIdentity(0));
      for (const auto& x : s) {
        // A bijection on each kind of element that moves every vertex onto its image, and
        // every edge's ends onto the image edge's ends.
        for (auto kind :
             {cf::ElementKind::kVertex, cf::ElementKind::kEdge, cf::ElementKind::kFace}) {
          std::set<int> image(x.of(kind).begin(), x.of(kind).end());
          CHECK(image.size() == m.num_elements(kind));
        }
        for (std::size_t i = 0; i < m.num_vertices(); ++i)
          CHECK((x.R * (m.vertices()[i].p - x.c) + x.c -
                 m.vertices()[static_cast<std::size_t>(x.vertex[i])].p)
                    .norm() < kTol);
        for (std::size_t e = 0; e < m.num_edges(); ++e) {
          const auto& E = m.edges()[e];
          const auto& F = m.edges()[static_cast<std::size_t>(x.edge[e])];
          std::set<int> ends = {x.vertex[E.v0.index()], x.vertex[E.v1.index()]};
          CHECK(ends ==
                std::set<int>{static_cast<int>(F.v0.index()), static_cast<int>(F.v1.index())});
        }
      }
    }
}

TEST_CASE("symmetry: a model with no symmetry has only the identity", "[symmetry]") {
  // A box with one corner cut off by a generic plane: no map but the identity keeps it.
  const cf::Polyhedron m = cf::test::from_loops("cut box",
                                                {{0, 0, 0},
                                                 {30, 0, 0},
                                                 {30, 20, 0},
                                                 {0, 20, 0},
                                                 {0, 0, 10},
                                                 {21, 0, 10},
                                                 {30, 7, 10},
                                                 {30, 20, 10},
                                                 {0, 20, 10},
                                                 {30, 0, 4}},
                                                {{0, 3, 2, 1},
                                                 {4, 5, 6, 7, 8},
                                                 {0, 1, 9, 5, 4},
                                                 {3, 8, 7, 2},
                                                 {1, 2, 7, 6, 9},
                                                 {0, 4, 8, 3},
                                                 {5, 9, 6}});
  CHECK(symmetries(m, 1e-13 * m.size()).size() == 1);
  // Against a box: only the box's maps pair with the identity of the same hand (4 rotations).
  const PairSymmetries pair(m, cf::test::box(10, 20, 30), 1e-13 * m.size(), true);
  CHECK(pair.size_a() == 1);
  CHECK(pair.size_b() == 8);
  CHECK(pair.size() == 4);
}

TEST_CASE("symmetry: a model written as float32 is made symmetric to the exact file's tolerance",
          "[symmetry]") {
  // The hexagonal hole block (24 maps) with every coordinate rounded to float32, as a binary
  // STL holds it: symmetric only to about 1e-6 mm, so most maps are missed at 1e-13 of its size.
  const cf::Polyhedron exact = cf::tools::load_model(
      cf::test::write_file("sym_hole.off", cf::test::ngon_off(6, 25, 10.5, 0, 20)));
  cf::tools::PolygonSoup soup;
  // Through a volatile float: GCC 12.2 at -O2/-O3 (SLP vectorization) dropped the rounding of
  // (double)(float)x for two of the three coordinates when written inline.
  auto f32 = [](double x) {
    volatile float f = static_cast<float>(x);
    return static_cast<double>(f);
  };
  for (const cf::Vertex& v : exact.vertices())
    soup.points.push_back({f32(v.p.x()), f32(v.p.y()), f32(v.p.z())});
  for (const cf::Face& f : exact.faces()) {
    // Fan triangles from each loop's first corner would cross the hole: each face as its loops,
    // which the soup takes as one polygon per loop only for faces without holes.
    if (f.loops.size() > 1) continue;
    std::vector<int> poly;
    for (cf::VertexId u : f.loops[0]) poly.push_back(static_cast<int>(u.index()));
    soup.polygons.push_back(poly);
  }
  // The two annular faces: as quads between the rings (the loader merges them again).
  const int n = 6;
  for (int i = 0, j = 1; i < n; ++i, j = (i + 1) % n) {
    soup.polygons.push_back({i, j, 2 * n + j, 2 * n + i});
    soup.polygons.push_back({n + i, 3 * n + i, 3 * n + j, n + j});
  }
  const cf::tools::MeasuredModel rounded = cf::tools::measured_model_from_soup(soup, "f32 hole");
  const double strict = cf::gen::kSymmetryTol * rounded.model.size();
  REQUIRE(symmetries(exact, 1e-13 * exact.size()).size() == 24);
  CHECK(symmetries(rounded.model, strict).size() < 24);
  double moved = 0;
  const cf::Polyhedron sym = cf::gen::symmetrized(
      rounded.model, cf::gen::kSymmetryRoundings * rounded.rounding_mm, strict, &moved);
  CHECK(symmetries(sym, strict).size() == 24);
  // Each vertex moves by about the rounding: to the mean of its images, each a rounding away.
  CHECK(moved > 0);
  CHECK(moved <= 4 * rounded.rounding_mm);
  CHECK(sym.num_faces() == rounded.model.num_faces());
  // An exact model is returned as it is.
  double none = 1;
  const cf::Polyhedron same = cf::gen::symmetrized(exact, 1e-6, 1e-13 * exact.size(), &none);
  CHECK(none == 0);
  CHECK(same.vertices()[3].p == exact.vertices()[3].p);
}

TEST_CASE("symmetry: the image of a pose puts each image element where the symmetry puts it",
          "[symmetry]") {
  const cf::Polyhedron A = cf::test::box(10, 20, 30, "A");
  const cf::Polyhedron B = cf::test::small_l_block();
  const PairSymmetries sym(A, B, 1e-13 * 50, true);
  REQUIRE(sym.size_a() == 8);
  REQUIRE(sym.size_b() == 4);
  // Pairs of like hand: 4 x 2 rotations and 4 x 2 reflections.
  REQUIRE(sym.size() == 16);
  const auto sa = symmetries(A, 1e-13 * 50);
  const auto sb = symmetries(B, 1e-13 * 50);
  Pose X;
  X.R_BA = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  X.t_BA = Vec3(5, 60, -7);
  std::size_t k = 0;
  for (const auto& h : sa)
    for (const auto& g : sb) {
      if ((h.R.determinant() > 0) != (g.R.determinant() > 0)) continue;
      const Pose Y = sym.image(X, k);
      CHECK((Y.R_BA.transpose() * Y.R_BA).isIdentity(1e-12));
      CHECK(Y.R_BA.determinant() == Approx(1.0).margin(1e-12));
      // Y(h(p)) = g(X(p)) for every vertex p of A.
      for (const auto& v : A.vertices()) {
        const Vec3 hp = h.R * (v.p - h.c) + h.c;
        const Vec3 gxp = g.R * (X.apply(v.p) - g.c) + g.c;
        CHECK((Y.apply(hp) - gxp).norm() < kTol);
      }
      // The image set maps each PC's elements by the two symmetries.
      const cf::PcSet s({cf::Pc{cf::PcType::kEF, 3, 4}, cf::Pc{cf::PcType::kVF, 6, 1}});
      const cf::PcSet t = sym.image(s, k);
      CHECK(t.contains(cf::Pc{cf::PcType::kEF, h.edge[3], g.face[4]}));
      CHECK(t.contains(cf::Pc{cf::PcType::kVF, h.vertex[6], g.face[1]}));
      CHECK(!cf::gen::pcset_less(t, sym.canonical(s)));
      ++k;
    }
  CHECK(k == sym.size());
}

TEST_CASE("symmetry: canonical is the least image, the same for every member of an orbit",
          "[symmetry]") {
  // A cube (48 maps) against the L-block (4): 24 x 2 pairs of rotations, 24 x 2 of
  // reflections.
  const PairSymmetries sym(cf::test::box(10, 10, 10, "cube"), cf::test::small_l_block(), 1e-13 * 50,
                           true);
  REQUIRE(sym.size() == 96);
  const cf::Polyhedron B = cf::test::small_l_block();
  // Sets of one to three PCs of mixed types spread over both models' elements (canonical
  // tries only the maps of A that reach the least element; this checks it against all).
  std::vector<cf::PcSet> sets;
  for (int i = 0; i < 40; ++i) {
    std::vector<cf::Pc> pcs{{cf::PcType::kVF, i % 8, i % static_cast<int>(B.num_faces())}};
    if (i % 3 > 0)
      pcs.push_back({cf::PcType::kEE, (i * 5) % 12, (i * 7) % static_cast<int>(B.num_edges())});
    if (i % 3 > 1) pcs.push_back({cf::PcType::kFV, (i * 3) % 6, (i * 11) % 12});
    // Two PCs of the least type: the least image's first PC may come from either.
    if (i % 4 == 3 && pcs.size() < 3)
      pcs.push_back({cf::PcType::kVF, (i + 4) % 8, (i * 5) % static_cast<int>(B.num_faces())});
    sets.emplace_back(pcs);
  }
  for (const cf::PcSet& s : sets) {
    cf::PcSet least = s;
    for (std::size_t k = 0; k < sym.size(); ++k)
      if (cf::gen::pcset_less(sym.image(s, k), least)) least = sym.image(s, k);
    CHECK(sym.canonical(s) == least);
    for (std::size_t k = 0; k < sym.size(); ++k) CHECK(sym.canonical(sym.image(s, k)) == least);
  }
}

TEST_CASE(
    "symmetry: one search per orbit gives a graph closed under the symmetries, every witness "
    "verified",
    "[symmetry][cfgen]") {
  // A 10 mm cube against a 40 x 40 x 10 slab: 48 and 16 symmetries.
  cf::test::AnalysedPair p(cf::test::box(Vec3(-5, -5, -5), Vec3(5, 5, 5), "cube"),
                           cf::test::box(Vec3(-20, -20, -5), Vec3(20, 20, 5), "slab"));
  cf::gen::EnumerateOptions opt;
  const cf::gen::Enumeration with = enumerate(p, opt);
  opt.use_symmetry = false;
  const cf::gen::Enumeration without = enumerate(p, opt);
  CHECK(with.symmetries_a == 48);
  CHECK(with.symmetries_b == 16);
  CHECK(without.symmetries_a == 1);
  const std::set<std::string> sets_with = cf_sets(with), sets_without = cf_sets(without);
  CHECK(sets_with.size() == with.cfs.size());  // no CF twice
  CHECK(sets_without.size() == without.cfs.size());
  // Closed: every image of every CF is a CF, and its witness is verified like any other.
  const cf::gen::WitnessSearch search(p.ai, p.bi, search_for(p));
  const PairSymmetries sym(p.A, p.B, 1e-13 * search.scale(), true);
  std::size_t images = 0;
  for (const auto& r : with.cfs) {
    CHECK(search.verify(r.pcs, r.witness) >= search.params().min_clearance);
    for (std::size_t k = 0; k < sym.size(); ++k)
      images += sets_with.count(cf::to_string(sym.image(r.pcs, k)));
  }
  CHECK(images == with.cfs.size() * sym.size());
  // The same CFs as searching every set, for a fraction of the searches.
  CHECK(sets_with == sets_without);
  std::size_t searched_with = 0, searched_without = 0, by_symmetry = 0;
  for (int l = 0; l < 3; ++l) {
    searched_with += with.levels[l].candidates;
    searched_without += without.levels[l].candidates;
    by_symmetry += with.levels[l].by_symmetry;
    CHECK(without.levels[l].by_symmetry == 0);
  }
  CHECK(searched_with * 10 < searched_without);
  // Most CFs are images: an orbit of 768 pairs of maps has dozens of members.
  CHECK(by_symmetry * 10 > with.cfs.size() * 9);
}

TEST_CASE(
    "symmetry: --thorough searches every set, then closes the graph under the symmetries: on a "
    "square peg in its hole it holds every CF of both other modes",
    "[symmetry][cfgen]") {
  // A square peg (r 10 mm, 40 mm long) in a tube whose hole is 5% wider: 16 and 16 maps.
  // Searching every set leaves most orbits partial here, and one search per orbit misses
  // orbits that the per-set search meets by motion.
  const auto [peg, hole] = cf::test::ngon_peg_and_hole(4, "thorough");
  cf::test::AnalysedPair p(cf::tools::load_model(peg, {}), cf::tools::load_model(hole, {}));
  cf::gen::EnumerateOptions opt;
  const cf::gen::Enumeration orbit = enumerate(p, opt);
  opt.use_symmetry = false;
  const cf::gen::Enumeration every = enumerate(p, opt);
  opt.close_orbits = true;
  const cf::gen::Enumeration thorough = enumerate(p, opt);
  CHECK(thorough.symmetries_a == 16);
  CHECK(thorough.symmetries_b == 16);
  const std::set<std::string> s_orbit = cf_sets(orbit), s_every = cf_sets(every),
                              s_thorough = cf_sets(thorough);
  REQUIRE(s_thorough.size() == thorough.cfs.size());  // no CF twice
  // The search is the per-set one; the closure only adds, each image verified.
  for (const std::string& s : s_every) CHECK(s_thorough.count(s) == 1);
  std::size_t by_symmetry = 0, searched_every = 0, searched_thorough = 0;
  std::size_t cells_every = 0, cells_thorough = 0;
  for (int l = 0; l < 3; ++l) {
    by_symmetry += thorough.levels[l].by_symmetry;
    searched_every += every.levels[l].candidates;
    searched_thorough += thorough.levels[l].candidates;
    cells_every += every.levels[l].by_cells;
    cells_thorough += thorough.levels[l].by_cells;
  }
  CHECK(searched_thorough == searched_every);
  // The closure adds the images to what the search found; then the cells add what they find
  // among the sets still failed (a set the closure made a CF is not left to them).
  CHECK(thorough.cfs.size() - cells_thorough == every.cfs.size() - cells_every + by_symmetry);
  CHECK(by_symmetry > 0);
  const cf::gen::WitnessSearch search(p.ai, p.bi, search_for(p));
  const PairSymmetries sym(p.A, p.B, 1e-13 * search.scale(), true);
  std::size_t images = 0;
  for (const auto& r : thorough.cfs) {
    CHECK(search.verify(r.pcs, r.witness) >= search.params().min_clearance);
    for (std::size_t k = 0; k < sym.size(); ++k)
      images += s_thorough.count(cf::to_string(sym.image(r.pcs, k)));
  }
  CHECK(images == thorough.cfs.size() * sym.size());  // closed under the maps
  // On this pair it holds every CF one search per orbit finds (7,508 against 6,724 when
  // measured): a property of the pair, so a check of the completeness the option is for.
  std::size_t orbit_missing = 0;
  for (const std::string& s : s_orbit) orbit_missing += s_thorough.count(s) == 0 ? 1 : 0;
  CHECK(orbit_missing == 0);
  CHECK(thorough.cfs.size() > orbit.cfs.size());
}

TEST_CASE(
    "symmetry: error() bounds how far every map moves a vertex and turns a direction off "
    "its image element's",
    "[symmetry]") {
  // A box and the L-block turned and moved by a rigid motion: their coordinates are rounded,
  // so the maps miss by a few ulps, not by nothing.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Vec3(1, -2, 2).normalized()).toRotationMatrix();
  const cf::Polyhedron A = moved(cf::test::box(10, 20, 30, "A"), R, Vec3(3.3, -7.1, 11.9));
  const cf::Polyhedron B = moved(cf::test::small_l_block(), R, Vec3(-0.7, 2.9, 5.3));
  const double size = 50;
  const PairSymmetries sym(A, B, 1e-13 * size, true);
  REQUIRE(sym.size() == 16);
  // Measured here on their own: the largest over A's maps plus the largest over B's.
  auto measure = [](const cf::Polyhedron& m, const cf::gen::Symmetry& s, double& length,
                    double& angle) {
    for (std::size_t i = 0; i < m.num_vertices(); ++i)
      length = std::max(length, (s.R * (m.vertices()[i].p - s.c) + s.c -
                                 m.vertices()[static_cast<std::size_t>(s.vertex[i])].p)
                                    .norm());
    // The angle from the chord: acos of a dot product near 1 loses half the digits.
    for (std::size_t f = 0; f < m.num_faces(); ++f)
      angle = std::max(angle,
                       2 * std::asin(0.5 * (s.R * m.faces()[f].normal -
                                            m.faces()[static_cast<std::size_t>(s.face[f])].normal)
                                               .norm()));
  };
  double la = 0, aa = 0, lb = 0, ab = 0;
  for (std::size_t k = 0; k < sym.size(); ++k) {
    measure(A, sym.map_a(k), la, aa);
    measure(B, sym.map_b(k), lb, ab);
  }
  const cf::gen::MapError& e = sym.error();
  CHECK(e.length >= la + lb);
  CHECK(e.angle >= std::max(aa, ab));
  // Rounding of coordinates of tens of mm, with the allowance error() adds for its own
  // arithmetic (1e-14 of each model's size): far below the touch tolerance (1e-9 mm here).
  CHECK(e.length > 0);
  CHECK(e.length < 1e-11);
  CHECK(e.angle < 1e-12);
  // No symmetry: no error.
  CHECK(PairSymmetries(A, B, 1e-13 * size, false).error().length == 0);
}

TEST_CASE("symmetry: limits loosened by a map's error take in every pose of an image",
          "[symmetry][cells]") {
  cf::gen::CellSearchLimits l;
  l.touch_tol = 1e-9;
  l.margin = 4e-9;
  l.local_slack = 5e-4;
  const cf::gen::MapError e{2e-12, 3e-12};
  const cf::gen::CellSearchLimits m = cf::gen::loosened(l, e);
  // docs/certificates.md, "Images": each by at least what the checker asks.
  CHECK(m.touch_tol >= l.touch_tol + e.length);
  CHECK(m.margin <= l.margin - e.length);
  CHECK(m.rot_tol >= l.rot_tol + e.angle);
  CHECK(m.local_slack <= l.local_slack - 2 * e.angle * (1 + 1 / l.local_slack));
  CHECK(m.deep_extra >= e.length);
  CHECK(m.max_cells == l.max_cells);
  // Nothing to loosen without an error, and a margin never below 0.
  const cf::gen::CellSearchLimits same = cf::gen::loosened(l, {});
  CHECK(same.touch_tol == l.touch_tol);
  CHECK(same.local_slack == l.local_slack);
  CHECK(same.deep_extra == 0);
  CHECK(cf::gen::loosened(l, {1e-6, 0}).margin == 0);
}

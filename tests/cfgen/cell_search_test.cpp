// The decision's branch and bound over rotation space (tools/cfgen/decide/rotation_cells,
// cell_relaxation, cell_search): the cells' turn bound, their tiling, and the relaxation's
// soundness (a cell holding a witness's rotation is never refuted) on a cube against a small
// L-block; sets refuted with evidence that tiles the whole space.

#include "cfgen/decide/cell_search.hpp"
#include "analysed_pair.hpp"
#include "cfgen/decide/deep_points.hpp"
#include "cfgen/decide/witness.hpp"
#include "cfgen/generate.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>
#include <string>

namespace {

using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Vec3;
using cf::gen::CellRelaxation;
using cf::gen::CellSearchResult;
using cf::gen::RotationCell;

Vec3 axis_angle_of(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Vec3 random_in(std::mt19937& rng, const RotationCell& c) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return c.centre + c.half * Vec3(u(rng), u(rng), u(rng));
}

// Every single PC of the two models, of every type.
std::vector<Pc> all_pcs(const cf::Polyhedron& A, const cf::Polyhedron& B) {
  std::vector<Pc> out;
  for (int t = 0; t <= static_cast<int>(PcType::kEE); ++t) {
    const auto type = static_cast<PcType>(t);
    const int na = static_cast<int>(A.num_elements(cf::a_kind(type)));
    const int nb = static_cast<int>(B.num_elements(cf::b_kind(type)));
    for (int a = 0; a < na; ++a)
      for (int b = 0; b < nb; ++b) out.push_back(Pc{type, a, b});
  }
  return out;
}

}  // namespace

TEST_CASE("rotation cells: every rotation of a cell is within the turn bound of the centre's",
          "[cells]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double half : {1.5, 0.3, 1e-2, 1e-5}) {
    for (int trial = 0; trial < 200; ++trial) {
      const RotationCell cell{Vec3(u(rng), u(rng), u(rng)) * 2.0, half};
      const Mat3 R_c = cf::gen::rotation_at(cell.centre);
      const Mat3 R = cf::gen::rotation_at(random_in(rng, cell));
      const Vec3 x = Vec3(u(rng), u(rng), u(rng)) * 50.0;  // mm
      // 1e-12 relative: rounding of the two rotations' products.
      CHECK((R * x - R_c * x).norm() <= cf::gen::turn_bound(cell) * x.norm() * (1 + 1e-12));
    }
  }
  // Rodrigues agrees with the generator's axis-angle rotation.
  const Vec3 r(0.3, -1.2, 2.0);
  CHECK((cf::gen::rotation_at(r) - cf::gen::axis_angle(r.normalized(), r.norm())).norm() < 1e-14);
  CHECK(cf::gen::turn_bound({Vec3::Zero(), 10.0}) == 2.0);  // no chord is longer than 2
}

TEST_CASE("rotation cells: split tiles a cell; cells beyond the ball of radius pi are skipped",
          "[cells]") {
  std::mt19937 rng(11);
  const RotationCell parent{Vec3(0.5, -0.25, 1.0), 0.5};
  const auto kids = cf::gen::split(parent);
  double volume = 0;
  for (const RotationCell& k : kids) volume += std::pow(2 * k.half, 3);
  CHECK(volume == Approx(std::pow(2 * parent.half, 3)));
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 p = random_in(rng, parent);
    int holding = 0;
    for (const RotationCell& k : kids)
      holding += ((p - k.centre).cwiseAbs().maxCoeff() <= k.half) ? 1 : 0;
    CHECK(holding >= 1);
  }
  CHECK_FALSE(cf::gen::outside_rotation_ball(cf::gen::whole_rotation_space()));
  CHECK(cf::gen::outside_rotation_ball({Vec3(3, 3, 3), 0.5}));          // nearest point 2.5 sqrt(3)
  CHECK_FALSE(cf::gen::outside_rotation_ball({Vec3(3.5, 0, 0), 0.5}));  // touches r = (3, 0, 0)
}

TEST_CASE("cell relaxation: a cell holding a witness's rotation is never refuted", "[cells]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::small_l_block());
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  const cf::gen::DeepPoints deep(p.ai, p.bi);
  std::mt19937 rng(3);
  std::vector<std::pair<PcSet, cf::Pose>> witnesses;
  std::vector<Pc> valid;
  for (const Pc& pc : all_pcs(p.A, p.B)) {
    const PcSet s({pc});
    const cf::gen::Witness w = search.find(s, {});
    if (!w.found) continue;
    witnesses.push_back({s, w.pose});
    valid.push_back(pc);
  }
  REQUIRE(witnesses.size() > 100);
  // Pairs of valid PCs, a spread of them: those with a witness join the list.
  std::uniform_int_distribution<std::size_t> pick(0, valid.size() - 1);
  for (int trial = 0; trial < 400; ++trial) {
    PcSet s({valid[pick(rng)]});
    if (!s.insert(valid[pick(rng)])) continue;
    const cf::gen::Witness w = search.find(s, {});
    if (w.found) witnesses.push_back({s, w.pose});
  }
  INFO(witnesses.size() << " witnesses");
  std::size_t checked = 0;
  for (const auto& [s, pose] : witnesses) {
    const CellRelaxation relaxation(p.ai, p.bi, s, search.params().touch_tol);
    const Vec3 r = axis_angle_of(pose.R_BA);
    CHECK(relaxation.holds_at(pose.R_BA));
    for (double half : {1.0, 0.1, 1e-2, 1e-4}) {
      // A cell of this size with r somewhere inside it.
      std::uniform_real_distribution<double> u(-half, half);
      const RotationCell cell{r + Vec3(u(rng), u(rng), u(rng)), half};
      cf::Vec3 lo = relaxation.t_lo(), hi = relaxation.t_hi();
      const CellRelaxation::Refutation ref = relaxation.refute(cell, lo, hi, false);
      INFO(cf::to_string(s) << " half " << half);
      CHECK(ref.verdict == CellRelaxation::Verdict::kOpen);
      // The narrowed translations still hold the witness's, and no point of either solid is
      // deep inside the other over the cell.
      const Vec3 t = pose.t_BA + pose.R_BA * relaxation.pivot();
      CHECK(((t - lo).array() >= 0).all());
      CHECK(((hi - t).array() >= 0).all());
      if (!((hi - t).array() >= 0).all())
        std::cerr << "lo " << lo.transpose() << " hi " << hi.transpose() << " t " << t.transpose()
                  << " T " << relaxation.t_lo().transpose() << " / "
                  << relaxation.t_hi().transpose() << "\n";
      CHECK_FALSE(deep.find({cf::gen::rotation_at(cell.centre), cf::gen::turn_bound(cell),
                             relaxation.pivot(), lo, hi}));
      ++checked;
    }
    // With the verifier's margins, as runs decide sets: the witnesses keep them.
    cf::gen::CellSearchLimits limits;
    limits.max_cells = 500;  // enough to find most witnesses again; never a refutation
    limits.touch_tol = search.params().touch_tol;
    limits.margin = search.params().min_margin;
    limits.local_slack = search.verified_local_slack();
    const CellSearchResult found = cf::gen::search_cells(p.ai, p.bi, s, limits, &search);
    CHECK(found.outcome != CellSearchResult::Outcome::kRefuted);
    if (found.outcome == CellSearchResult::Outcome::kWitness)
      CHECK(search.verify(s, found.witness.pose) >= 0);
  }
  CHECK(checked >= 4 * 100);
}

namespace {

using cf::gen::CellNode;

// The leaves of a search's tree.
std::vector<CellNode> leaves(const cf::gen::CellTree& tree) {
  std::vector<CellNode> out;
  for (const CellNode& n : tree.nodes)
    if (n.kind == CellNode::Kind::kRefuted || n.kind == CellNode::Kind::kOutsideBall)
      out.push_back(n);
  return out;
}

// Parents come before their children; a split or narrowed node has children, a leaf none.
void check_tree(const cf::gen::CellTree& tree) {
  std::vector<int> children(tree.nodes.size(), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const int parent = tree.nodes[i].parent;
    CHECK(parent < static_cast<int>(i));
    CHECK((parent >= 0) == (i > 0));
    if (parent >= 0) ++children[static_cast<std::size_t>(parent)];
  }
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const CellNode::Kind k = tree.nodes[i].kind;
    const bool leaf = k == CellNode::Kind::kRefuted || k == CellNode::Kind::kOutsideBall;
    CHECK((children[i] == 0) == leaf);
    if (k == CellNode::Kind::kSplitTranslation) CHECK(children[i] == 2);
    if (k == CellNode::Kind::kSplitRotation) CHECK((children[i] == 2 || children[i] == 8));
  }
}

// Each refuted program's certificate, rechecked on the program rebuilt from the cell's
// evidence; the number of such cells.
std::size_t check_certificates(const cf::test::AnalysedPair& p, const PcSet& s,
                               const std::vector<CellNode>& evidence) {
  std::size_t programs = 0;
  const CellRelaxation relaxation(p.ai, p.bi, s, 1e-9);
  for (const auto& e : evidence) {
    if (e.refutation.verdict != CellRelaxation::Verdict::kProgram) continue;
    ++programs;
    // One certificate per choice of pieces (convex faces: one).
    REQUIRE(e.refutation.certificates.size() == 1);
    const cf::gen::LinearProgram lp = relaxation.program(
        e.R_c, e.turn, std::vector<int>(relaxation.slot_sizes().size(), 0), e.t_lo, e.t_hi);
    CHECK(cf::gen::farkas_gap(lp, e.refutation.certificates[0].y) < 0);
  }
  return programs;
}

// The refuted cubes cover the rotations: each random one lies in one of them.
void check_cubes_cover(const std::vector<CellNode>& evidence) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 r = random_in(rng, cf::gen::whole_rotation_space());
    bool covered = false;
    for (const auto& e : evidence)
      covered = covered || (r - e.cell.centre).cwiseAbs().maxCoeff() <= e.cell.half;
    CHECK(covered);
  }
}

// The refuted arcs tile the circle's angles [-pi, pi].
void check_arcs_cover(const std::vector<CellNode>& evidence) {
  std::vector<std::pair<double, double>> arcs;
  for (const auto& e : evidence) {
    REQUIRE(e.arc.half > 0);
    arcs.push_back({e.arc.centre - e.arc.half, e.arc.centre + e.arc.half});
  }
  std::sort(arcs.begin(), arcs.end());
  REQUIRE(!arcs.empty());
  CHECK(arcs.front().first <= -M_PI);
  CHECK(arcs.back().second >= M_PI);
  for (std::size_t k = 1; k < arcs.size(); ++k) CHECK(arcs[k].first <= arcs[k - 1].second);
}

}  // namespace

TEST_CASE(
    "cell search: sets whose contacts cannot hold together are refuted, the refuted cells "
    "tiling the rotation space or the f-f's circle",
    "[cells]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  constexpr int kBottom = 0, kTop = 1;  // faces of cf::test::box
  const cf::Polyhedron& A = p.A;
  // A's bottom and top faces both on B's top face: their normals cannot both be opposite to it.
  // A's bottom face on B's top face with A's top vertex on B's top face too: the vertex's
  // edges would point into B. With that vertex on B's bottom face instead: its edges are
  // clear of that face, but the vertex stands 10 mm above B's top face, 20 mm above the
  // bottom face (the translation programs). These have an f-f: arcs of its circle.
  const int top_vertex = cf::test::vertex_at(A, Vec3(10, 10, 10));
  for (const PcSet& s :
       {PcSet({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kFF, kTop, kTop}}),
        PcSet({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kVF, top_vertex, kTop}}),
        PcSet({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kVF, top_vertex, kBottom}})}) {
    INFO(cf::to_string(s));
    cf::gen::CellTree tree;
    const CellSearchResult r = cf::gen::search_cells(p.ai, p.bi, s, {}, nullptr, &tree);
    REQUIRE(r.outcome == CellSearchResult::Outcome::kRefuted);
    const std::vector<CellNode> evidence = leaves(tree);
    check_tree(tree);
    const std::size_t programs = check_certificates(p, s, evidence);
    check_arcs_cover(evidence);
    if (s[1] == Pc{PcType::kVF, top_vertex, kBottom}) CHECK(programs > 0);
  }
  // Without an f-f, cubes of rotation space: A's top vertex on B's top face and the vertex
  // below it on B's bottom face, from below. Local non-penetration turns the edge between
  // them upwards from the first, so the second lies above B's top face, not on its bottom.
  const int below = cf::test::vertex_at(A, Vec3(10, 10, 0));
  const PcSet s({Pc{PcType::kVF, top_vertex, kTop}, Pc{PcType::kVF, below, kBottom}});
  INFO(cf::to_string(s));
  cf::gen::CellTree tree;
  const CellSearchResult r = cf::gen::search_cells(p.ai, p.bi, s, {}, nullptr, &tree);
  REQUIRE(r.outcome == CellSearchResult::Outcome::kRefuted);
  const std::vector<CellNode> evidence = leaves(tree);
  check_tree(tree);
  CHECK(check_certificates(p, s, evidence) > 0);
  check_cubes_cover(evidence);
}

TEST_CASE(
    "deep points: a point inside the other solid by more than the cell moves it refutes "
    "the cell",
    "[cells]") {
  // A: 10 mm cube; B: 40 x 40 x 10 mm slab.
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  CHECK(cf::gen::depth_inside(p.B, Vec3(20, 20, 5)) == Approx(5));  // the slab's mid-plane
  CHECK(cf::gen::depth_inside(p.B, Vec3(1, 20, 5)) == Approx(1));   // 1 mm from the side x = 0
  CHECK(cf::gen::depth_inside(p.B, Vec3(20, 20, 10)) == 0);         // on the top face
  CHECK(cf::gen::depth_inside(p.B, Vec3(20, 20, 12)) == 0);         // above it
  const cf::gen::DeepPoints deep(p.ai, p.bi);
  // A's centre (5, 5, 5) as the pivot, put at (20, 20, 8): A's bottom reaches z = 3, inside B.
  cf::gen::PoseCell cell;
  cell.pivot = Vec3(5, 5, 5);
  cell.t_lo = cell.t_hi = Vec3(20, 20, 8);
  auto hit = deep.find(cell);
  REQUIRE(hit);
  CHECK(hit->depth > hit->reach);
  // The same with the pivot anywhere in a 2 x 2 x 1 mm box and rotations within 0.05 rad:
  // the centroid of A's bottom face, 5 mm below the pivot, is 3 mm deep at the centre pose
  // and moves at most 0.05 sqrt(3) 5 + 1.5 < 2 mm.
  cell.beta = cf::gen::turn_bound({Vec3::Zero(), 0.05});
  cell.t_lo = Vec3(19, 19, 7.5);
  cell.t_hi = Vec3(21, 21, 8.5);
  hit = deep.find(cell);
  REQUIRE(hit);
  CHECK(hit->depth > hit->reach);
  // Lifted so that A's bottom is 1 mm above B's top: nothing inside B.
  cell.beta = 0;
  cell.t_lo = cell.t_hi = Vec3(20, 20, 16);
  CHECK_FALSE(deep.find(cell));
  // Half sunk at the centre pose, but with a box of translations 12 mm high: no point is
  // surely inside (the deepest, 5 mm, can move 6 mm).
  cell.t_lo = Vec3(20, 20, 4);
  cell.t_hi = Vec3(20, 20, 16);
  CHECK_FALSE(deep.find(cell));
}

TEST_CASE(
    "cell search: on an f-f's circle, an e-e whose edges stay parallel is refuted over arcs "
    "tiling the circle, by the verifier's local slack",
    "[cells]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  constexpr int kBottom = 0, kTop = 1;  // faces of cf::test::box
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  // A's vertical edge at its origin and B's at its origin: both along z, so parallel for
  // every turn of A about the normal of the faces in contact.
  const int ea = cf::test::edge_between(p.A, cf::test::vertex_at(p.A, Vec3(0, 0, 0)),
                                        cf::test::vertex_at(p.A, Vec3(0, 0, 10)));
  const int eb = cf::test::edge_between(p.B, cf::test::vertex_at(p.B, Vec3(0, 0, 0)),
                                        cf::test::vertex_at(p.B, Vec3(0, 0, 10)));
  const PcSet s({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kEE, ea, eb}});
  cf::gen::CellSearchLimits limits;
  limits.max_cells = 200;
  limits.margin = search.params().min_margin;
  // Without the slack a degenerate touch is not ruled out: the cells stay open.
  CHECK(cf::gen::search_cells(p.ai, p.bi, s, limits).outcome !=
        CellSearchResult::Outcome::kRefuted);
  limits.local_slack = search.verified_local_slack();
  cf::gen::CellTree tree;
  const CellSearchResult r = cf::gen::search_cells(p.ai, p.bi, s, limits, &search, &tree);
  REQUIRE(r.outcome == CellSearchResult::Outcome::kRefuted);
  const std::vector<CellNode> evidence = leaves(tree);
  // The arcs refuted tile [-pi, pi]; the e-e (index 1) is the PC below the slack.
  check_arcs_cover(evidence);
  for (const auto& e : evidence) {
    CHECK(e.refutation.verdict == CellRelaxation::Verdict::kSlack);
    CHECK(e.refutation.pc == 1);
  }
  // The same set with the faces apart (no f-f) is not refuted by this argument: A's edge can
  // turn away from B's.
  const PcSet apart({Pc{PcType::kEE, ea, eb}});
  CHECK(cf::gen::search_cells(p.ai, p.bi, apart, limits, &search).outcome !=
        CellSearchResult::Outcome::kRefuted);
}

TEST_CASE(
    "cell search: a coarser resolution refutes only sets the default resolution refutes, and "
    "leaves open those that need smaller cells",
    "[cells]") {
  // The bundled peg and block with a hole, with the decision's limits (cfgen --resolution).
  const std::string dir = std::string(CF_SOURCE_DIR) + "/data/models/";
  cf::test::AnalysedPair p(cf::tools::load_model(dir + "peg.off"),
                           cf::tools::load_model(dir + "hole_block.off"));
  const cf::gen::WitnessSearch search(
      p.ai, p.bi, cf::tools::scaled_search(p.A, p.B, cf::tools::RelativeLengths{}));
  const cf::gen::CellSearchLimits fine = cf::gen::decision_limits(search, 3000);
  const cf::gen::CellSearchLimits coarse = cf::gen::decision_limits(search, 3000, 1e-2);
  // The translation's resolution is in units of D, the smaller model's diagonal.
  CHECK(fine.resolution == cf::gen::kResolution);
  CHECK(fine.scale == search.scale());
  CHECK(coarse.resolution == 1e-2);
  auto parse = [](const std::string& text) {
    PcSet s;
    std::istringstream in(text);
    for (std::string tok; in >> tok;) s.insert(*cf::pc_from_string(tok));
    return s;
  };
  // Refuted with cells down to 1.5e-3 and 7.7e-4 rad: left open by cells of 1e-2 rad.
  for (const char* text : {"v-f:5:7 e-e:3:20 e-e:9:13", "v-f:0:7 e-e:3:22 e-e:9:12"}) {
    INFO(text);
    const PcSet s = parse(text);
    const CellSearchResult r = cf::gen::search_cells(p.ai, p.bi, s, fine);
    CHECK(r.outcome == CellSearchResult::Outcome::kRefuted);
    CHECK(r.smallest_half < 1e-2);
    const CellSearchResult rc = cf::gen::search_cells(p.ai, p.bi, s, coarse);
    CHECK(rc.outcome == CellSearchResult::Outcome::kUndecided);
    CHECK(rc.smallest_half < 1e-2);
  }
  // Refuted at both: the coarse search's tree is the fine one's (the resolution only ends a
  // search), so it takes as many cells.
  for (const char* text : {"e-e:1:23 e-e:11:15", "e-e:7:13 e-e:10:23", "e-f:5:9 f-e:4:17 v-f:7:3",
                           "e-e:5:20 e-e:9:23 e-e:10:15"}) {
    INFO(text);
    const PcSet s = parse(text);
    const CellSearchResult rc = cf::gen::search_cells(p.ai, p.bi, s, coarse);
    REQUIRE(rc.outcome == CellSearchResult::Outcome::kRefuted);
    const CellSearchResult r = cf::gen::search_cells(p.ai, p.bi, s, fine);
    CHECK(r.outcome == CellSearchResult::Outcome::kRefuted);
    CHECK(r.cells == rc.cells);
  }
}

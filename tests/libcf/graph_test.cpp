// A small, geometrically real CF graph for tests: A is a 10 mm cube, B an L-shaped block
// (a floor 40 x 10 and a wall 10 x 40 in the x-y profile, y up, extruded 20 in z).
// Every witness below realises exactly its CF (checked by hand; see the comments).

#include <cf/graph.hpp>
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>

#include <cmath>

namespace cf_test {

// Axis-aligned box [0,sx] x [0,sy] x [0,sz]. Faces: 0 z=0, 1 z=sz, 2 y=0, 3 y=sy, 4 x=sx,
// 5 x=0. Edges: 0 (0,1), 1 (1,2), 2 (2,3), 3 (0,3), 4 (4,5), 5 (5,6), 6 (6,7), 7 (4,7),
// 8 (0,4), 9 (1,5), 10 (2,6), 11 (3,7).
cf::Polyhedron box(double sx, double sy, double sz) { return cf::test::box(sx, sy, sz, "cube"); }

// The small L-block of fixtures.hpp (its comment gives the face and edge indices).
cf::Polyhedron l_block() { return cf::test::small_l_block(); }

cf::Pose pose(const cf::Mat3& R, const cf::Vec3& t) {
  cf::Pose p;
  p.R_BA = R;
  p.t_BA = t;
  return p;
}

cf::Mat3 rot(double angle, const cf::Vec3& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

cf::Pc pc(cf::PcType type, int a, int b) { return cf::Pc{type, a, b}; }

/// CFs:
///  0 {f-f:2:4}            cube's y=0 face flat on the floor top, clear of the wall
///  1 {f-f:5:5}            cube's x=0 face flat on the wall, above the floor
///  2 {f-f:2:4; f-f:5:5}   in the corner (the collinear edge touch there is dominated)
///  3 {e-f:0:4}            on the floor, tipped about its edge 0 (the x axis)
///  4 {v-f:0:4}            on the floor, tipped onto its vertex 0
/// Transitions: 0<->2 and 1<->2 gain/lose, 0<->3 and 3<->4 change.
cf::CfGraph box_l_graph() {
  using cf::PcType;
  const cf::Mat3 I = cf::Mat3::Identity();
  const cf::Vec3 x(1, 0, 0), z(0, 0, 1);
  std::vector<cf::CfRecord> cfs(5);
  cfs[0].pcs = cf::PcSet({pc(PcType::kFF, 2, 4)});
  cfs[0].witness = pose(I, {20, 10, 5});
  cfs[1].pcs = cf::PcSet({pc(PcType::kFF, 5, 5)});
  cfs[1].witness = pose(I, {10, 20, 5});
  cfs[2].pcs = cf::PcSet({pc(PcType::kFF, 5, 5), pc(PcType::kFF, 2, 4)});
  cfs[2].witness = pose(I, {10, 10, 5});
  // Rotating by -0.2 rad about x lifts every point off y = 0 except the x-axis edge.
  cfs[3].pcs = cf::PcSet({pc(PcType::kEF, 0, 4)});
  cfs[3].witness = pose(rot(-0.2, x), {20, 10, 5});
  // Then 0.1 rad about z first lifts the x-axis edge too, except its vertex 0.
  cfs[4].pcs = cf::PcSet({pc(PcType::kVF, 0, 4)});
  cfs[4].witness = pose(rot(-0.2, x) * rot(0.1, z), {20, 10, 5});
  // Freedoms where they are easy to state: a face on a plane keeps 3 (2 slides, 1 spin).
  cfs[0].dof = 3;
  cfs[0].translation_dof = 2;
  cfs[0].pure_rotation = true;
  cfs[2].dof = 1;
  cfs[2].translation_dof = 1;
  cfs[2].pure_rotation = false;
  using K = cf::TransitionKind;
  auto tr = [](int f, int t, K k) { return cf::Transition{cf::CfId(f), cf::CfId(t), k}; };
  std::vector<cf::Transition> transitions = {
      tr(0, 2, K::kGain),   tr(2, 0, K::kLose),   tr(1, 2, K::kGain),   tr(2, 1, K::kLose),
      tr(0, 3, K::kChange), tr(3, 0, K::kChange), tr(3, 4, K::kChange), tr(4, 3, K::kChange)};
  return cf::CfGraph::from_parts(
      box(10, 10, 10), l_block(), std::move(cfs), std::move(transitions),
      R"({"stats":{"note":"hand-made test fixture"},"parameters":{"epsilon_mm":1.0}})");
}

}  // namespace cf_test

namespace {

using cf::CfGraph;
using cf::CfId;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::TransitionKind;
using cf_test::pc;

const std::string kGraphDir = std::string(CF_TEST_DATA_DIR) + "/graphs";
const std::string kFixture = kGraphDir + "/box_l.json";

std::string bad(const std::string& name) { return kGraphDir + "/bad/" + name; }

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh empty directory for files a test writes.
std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("cf_graph_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Exact equality of everything the graph holds (witnesses are stored with round-trip
/// precision, so exact comparison is the right test).
void check_same(const CfGraph& x, const CfGraph& y) {
  REQUIRE(x.num_cfs() == y.num_cfs());
  REQUIRE(x.num_transitions() == y.num_transitions());
  CHECK(x.model_a().name() == y.model_a().name());
  CHECK(x.model_b().num_faces() == y.model_b().num_faces());
  for (std::size_t i = 0; i < x.num_cfs(); ++i) {
    const cf::CfRecord& a = x.cf(CfId(static_cast<int>(i)));
    const cf::CfRecord& b = y.cf(CfId(static_cast<int>(i)));
    CHECK(a.pcs == b.pcs);
    CHECK(a.witness.R_BA == b.witness.R_BA);
    CHECK(a.witness.t_BA == b.witness.t_BA);
    CHECK(a.dof == b.dof);
    CHECK(a.translation_dof == b.translation_dof);
    CHECK(a.pure_rotation == b.pure_rotation);
  }
  for (std::size_t i = 0; i < x.num_transitions(); ++i) {
    CHECK(x.transition(i).from == y.transition(i).from);
    CHECK(x.transition(i).to == y.transition(i).to);
    CHECK(x.transition(i).kind == y.transition(i).kind);
  }
  CHECK(x.metadata_json() == y.metadata_json());
}

}  // namespace

TEST_CASE("PC types name their element kinds and parse back", "[graph]") {
  CHECK(std::string(cf::to_string(PcType::kVF)) == "v-f");
  CHECK(cf::a_kind(PcType::kVF) == cf::ElementKind::kVertex);
  CHECK(cf::b_kind(PcType::kVF) == cf::ElementKind::kFace);
  CHECK(cf::a_kind(PcType::kFE) == cf::ElementKind::kFace);
  CHECK(cf::b_kind(PcType::kFE) == cf::ElementKind::kEdge);
  CHECK(cf::a_kind(PcType::kEE) == cf::ElementKind::kEdge);
  for (PcType t : {PcType::kFF, PcType::kEF, PcType::kFE, PcType::kVF, PcType::kFV, PcType::kEE})
    CHECK(cf::pc_type_from_string(cf::to_string(t)) == t);
  CHECK_FALSE(cf::pc_type_from_string("v-v"));
  CHECK_FALSE(cf::pc_type_from_string("f-f "));
  CHECK(cf::to_string(pc(PcType::kEE, 3, 11)) == "e-e:3:11");
  CHECK(cf::pc_from_string("e-e:3:11") == pc(PcType::kEE, 3, 11));
  CHECK_FALSE(cf::pc_from_string("e-e:3"));
  CHECK_FALSE(cf::pc_from_string("e-e:3:-1"));
  CHECK_FALSE(cf::pc_from_string("x-e:3:1"));
  CHECK_FALSE(cf::pc_from_string("e-e:3:1x"));
  CHECK(cf::transition_kind_from_string("change") == TransitionKind::kChange);
  CHECK_FALSE(cf::transition_kind_from_string("gained"));
}

TEST_CASE("a PC set is canonical whatever the insertion order", "[graph]") {
  const Pc p1 = pc(PcType::kFF, 2, 4), p2 = pc(PcType::kVF, 0, 5), p3 = pc(PcType::kEE, 1, 1);
  const PcSet s({p2, p3, p1});
  REQUIRE(s.size() == 3);
  CHECK(s[0] == p1);  // enumerator order: f-f < v-f < e-e
  CHECK(s[1] == p2);
  CHECK(s[2] == p3);
  const std::vector<std::vector<Pc>> orders = {{p1, p2, p3}, {p1, p3, p2}, {p2, p1, p3},
                                               {p2, p3, p1}, {p3, p1, p2}, {p3, p2, p1}};
  for (const auto& order : orders) {
    PcSet t;
    for (const Pc& p : order) CHECK(t.insert(p));
    CHECK(t == s);
    CHECK(t.hash() == s.hash());
  }
  PcSet full = s;
  CHECK_FALSE(full.insert(pc(PcType::kFF, 0, 0)));  // full
  PcSet one({p1});
  CHECK_FALSE(one.insert(p1));  // already present
  CHECK(one.contains(p1));
  CHECK_FALSE(one.contains(p2));
  CHECK(one != s);
  CHECK(cf::to_string(s) == "f-f:2:4;v-f:0:5;e-e:1:1");
  CHECK(cf::to_string(PcSet()) == "");
  CHECK_THROWS_WITH(PcSet({p1, p1}), Catch::Contains("PC f-f:2:4 is repeated"));
  CHECK_THROWS_WITH(PcSet({p1, p2, p3, pc(PcType::kFF, 0, 0)}), Catch::Contains("at most 3"));
}

TEST_CASE("find answers any permutation of a CF's PCs, and nothing else", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  REQUIRE(g.num_cfs() == 5);
  CHECK(g.find(PcSet({pc(PcType::kFF, 2, 4)})) == CfId(0));
  CHECK(g.find(PcSet({pc(PcType::kFF, 2, 4), pc(PcType::kFF, 5, 5)})) == CfId(2));
  CHECK(g.find(PcSet({pc(PcType::kFF, 5, 5), pc(PcType::kFF, 2, 4)})) == CfId(2));
  CHECK(g.find(PcSet({pc(PcType::kVF, 0, 4)})) == CfId(4));
  CHECK_FALSE(g.find(PcSet({pc(PcType::kVF, 1, 4)})));
  CHECK_FALSE(g.find(PcSet({pc(PcType::kFF, 2, 4), pc(PcType::kVF, 0, 4)})));
  CHECK_FALSE(g.find(PcSet()));
  for (std::size_t i = 0; i < g.num_cfs(); ++i)
    CHECK(g.find(g.cf(CfId(static_cast<int>(i))).pcs) == CfId(static_cast<int>(i)));
}

TEST_CASE("transitions are listed per CF by target and answer adjacency", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  CHECK(g.num_transitions() == 8);
  const auto& out2 = g.out_transitions(CfId(2));
  REQUIRE(out2.size() == 2);
  CHECK(out2[0].to == CfId(0));
  CHECK(out2[0].kind == TransitionKind::kLose);
  CHECK(out2[1].to == CfId(1));
  const auto& out0 = g.out_transitions(CfId(0));
  REQUIRE(out0.size() == 2);
  CHECK(out0[0].to == CfId(2));  // gain was listed first in the file, but 2 < 3 anyway
  CHECK(out0[0].kind == TransitionKind::kGain);
  CHECK(out0[1].to == CfId(3));
  CHECK(out0[1].kind == TransitionKind::kChange);
  CHECK(g.adjacent(CfId(3), CfId(4)));
  CHECK(g.adjacent(CfId(4), CfId(3)));
  CHECK_FALSE(g.adjacent(CfId(0), CfId(4)));
  CHECK_FALSE(g.adjacent(CfId(0), CfId(1)));
  CHECK_FALSE(g.adjacent(CfId(9), CfId(1)));
  CHECK(g.transition(1).from == CfId(2));
}

// Release builds keep these checks (libcf/src/check.hpp): an id from the caller is input.
TEST_CASE("ids out of range throw instead of reading past the graph", "[graph][bad]") {
  const CfGraph g = cf_test::box_l_graph();
  CHECK_THROWS_WITH(g.cf(CfId(static_cast<int>(g.num_cfs()))),
                    Catch::Contains("CfGraph::cf: CF id 5 is not in the graph (5 CFs)"));
  CHECK_THROWS_WITH(g.cf(CfId()), Catch::Contains("CF id -1 is not in the graph"));
  CHECK_THROWS_WITH(g.out_transitions(CfId(7)),
                    Catch::Contains("CfGraph::out_transitions: CF id 7"));
  CHECK_THROWS_WITH(
      g.transition(8),
      Catch::Contains("CfGraph::transition: index 8 is not in the graph (8 transitions)"));
  CHECK_THROWS_WITH(CfGraph().cf(CfId(0)), Catch::Contains("(0 CFs)"));
}

TEST_CASE("an empty graph answers queries", "[graph]") {
  const CfGraph g;
  CHECK(g.num_cfs() == 0);
  CHECK(g.num_transitions() == 0);
  CHECK(g.metadata_json() == "{}");
  CHECK_FALSE(g.find(PcSet({pc(PcType::kFF, 0, 0)})));
  CHECK_FALSE(g.adjacent(CfId(0), CfId(1)));
}

TEST_CASE("to_json round-trips exactly and is deterministic", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  const std::string compact = g.to_json();
  const std::string pretty = g.to_json(2);
  CHECK(compact == cf_test::box_l_graph().to_json());  // same graph, same bytes
  CHECK(pretty == cf_test::box_l_graph().to_json(2));
  CHECK(compact.find('\n') == std::string::npos);
  // Top-level order: the contract's fixed members first, metadata, then the big arrays.
  CHECK(
      compact.rfind(
          R"({"format":"cf-graph","version":1,"units":"mm","parameters":{"epsilon_mm":1.0},"stats":)",
          0) == 0);
  const CfGraph h = CfGraph::from_bytes(compact, "compact", false);
  check_same(g, h);
  CHECK(h.to_json() == compact);
  const CfGraph p = CfGraph::from_bytes(pretty, "pretty", false);
  check_same(g, p);
  CHECK(p.to_json(2) == pretty);
  CHECK(g.metadata_json() ==
        R"({"parameters":{"epsilon_mm":1.0},"stats":{"note":"hand-made test fixture"}})");
  // Optional freedoms are written only when known.
  CHECK(
      compact.find(
          R"("id":0,"pcs":[{"type":"f-f","a":2,"b":4}],"witness":{"R":[[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]],"t":[20.0,10.0,5.0]},"dof":3,"translation_dof":2,"pure_rotation":true})") !=
      std::string::npos);
  CHECK(
      compact.find(
          R"({"id":1,"pcs":[{"type":"f-f","a":5,"b":5}],"witness":{"R":[[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]],"t":[10.0,20.0,5.0]}})") !=
      std::string::npos);
}

TEST_CASE("witnesses with arbitrary doubles round-trip exactly through JSON and CBOR", "[graph]") {
  // Every single PC between the cube and the L-block, each with a random rotation and
  // translation: numbers with 16-17 significant digits, tiny and huge exponents.
  std::vector<cf::CfRecord> cfs;
  std::uint64_t state = 42;
  auto uniform = [&state] {  // splitmix64 -> [0, 1)
    state += 0x9e3779b97f4a7c15ULL;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  const cf::Polyhedron a = cf_test::box(10, 10, 10), b = cf_test::l_block();
  const double scales[] = {1e-300, 1e-7, 1e-4, 1.0, 1e15, 1e17, 1e300};
  for (int t = 0; t < 6; ++t)
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 8; ++j) {
        const auto type = static_cast<PcType>(t);
        if (cf::a_kind(type) == cf::ElementKind::kFace && i >= 6) continue;
        cf::CfRecord r;
        r.pcs = PcSet({pc(type, i, j)});
        r.witness.R_BA =
            Eigen::Quaterniond(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5, uniform() - 0.5)
                .normalized()
                .toRotationMatrix();
        const double s = scales[cfs.size() % 7];
        r.witness.t_BA = cf::Vec3(s * (uniform() - 0.5), -s * uniform(), s);
        cfs.push_back(r);
      }
  const CfGraph g = CfGraph::from_parts(a, b, std::move(cfs), {});
  REQUIRE(g.num_cfs() == 288);
  check_same(g, CfGraph::from_bytes(g.to_json(), "r.json", false));
  check_same(g, CfGraph::from_bytes(g.to_json(2), "r.json", false));
  const auto dir = scratch_dir("doubles");
  g.save((dir / "r.cbor").string());
  check_same(g, CfGraph::load((dir / "r.cbor").string()));
  std::filesystem::remove_all(dir);
}

TEST_CASE("the committed fixture is the graph the code builds", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  if (std::getenv("CF_WRITE_GRAPH_FIXTURES")) g.save(kFixture);
  const CfGraph f = CfGraph::load(kFixture);
  check_same(g, f);
  CHECK(slurp(kFixture) == g.to_json(1));
}

TEST_CASE("save writes JSON or CBOR whole and load reads it back", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  const auto dir = scratch_dir("save");
  const std::string json_path = (dir / "g.json").string();
  const std::string cbor_path = (dir / "g.cbor").string();
  g.save(json_path);
  g.save(cbor_path);
  g.save(json_path);  // overwriting an existing file goes through the same rename
  check_same(g, CfGraph::load(json_path));
  check_same(g, CfGraph::load(cbor_path));
  // CBOR is smaller and holds the same document.
  CHECK(std::filesystem::file_size(cbor_path) < std::filesystem::file_size(json_path));
  // No temporary file is left behind.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  CHECK(entries == 2);
  CHECK_THROWS_WITH(
      g.save((dir / "no" / "such" / "dir.json").string()),
      Catch::Contains("writing graph '" + (dir / "no" / "such" / "dir.json").string() +
                      "': the directory '" + (dir / "no" / "such").string() + "' does not exist"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("schema validation can be skipped or made exhaustive", "[graph]") {
  cf::GraphLoadOptions none, full;
  none.validate_schema = false;
  full.full_schema_check = true;
  check_same(CfGraph::load(kFixture), CfGraph::load(kFixture, none));
  check_same(CfGraph::load(kFixture), CfGraph::load(kFixture, full));
  // Metadata is free-form to the reader; only the schema says "stats" is an object...
  CHECK_NOTHROW(CfGraph::load(bad("schema_violation.json"), none));
  // ... while every structural fault is caught without it.
  CHECK_THROWS_WITH(CfGraph::load(bad("index_out_of_range.json"), none),
                    Catch::Contains("/cfs/3/pcs/0/b"));
  CHECK_THROWS_WITH(CfGraph::load(bad("witness_extra_member.json"), none),
                    Catch::Contains("/cfs/2/witness"));
}

TEST_CASE("a written graph passes the full schema check, as JSON and as CBOR", "[graph]") {
  const CfGraph g = cf_test::box_l_graph();
  cf::GraphLoadOptions full;
  full.full_schema_check = true;
  check_same(g, CfGraph::from_bytes(g.to_json(), "g.json", false, full));
  const auto dir = scratch_dir("cbor_schema");
  const std::string cbor_path = (dir / "g.cbor").string();
  g.save(cbor_path);
  check_same(g, CfGraph::load(cbor_path, full));
  std::filesystem::remove_all(dir);
}

TEST_CASE("members are read in any order", "[graph]") {
  // box_l.json with its keys sorted, as Python's json.dump(sort_keys=True) writes it: cfs
  // come before format and models, and every PC's a and b before its type.
  const CfGraph g = cf_test::box_l_graph();
  check_same(g, CfGraph::load(kGraphDir + "/box_l_sorted.json"));
}

// ---- from_parts rejects inconsistent parts --------------------------------------------

namespace {

CfGraph build(std::vector<cf::CfRecord> cfs, std::vector<cf::Transition> tr = {},
              const std::string& meta = "{}") {
  return CfGraph::from_parts(cf_test::box(10, 10, 10), cf_test::l_block(), std::move(cfs),
                             std::move(tr), meta);
}

cf::CfRecord rec(std::vector<Pc> pcs) {
  cf::CfRecord r;
  r.pcs = PcSet(pcs);
  return r;
}

cf::Transition tr(int f, int t, TransitionKind k) { return {CfId(f), CfId(t), k}; }

}  // namespace

TEST_CASE("from_parts rejects indices out of range for the kinds the type names", "[graph]") {
  // The cube has 8 vertices, 12 edges, 6 faces; the L-block 12, 18, 8.
  CHECK_THROWS_WITH(build({rec({pc(PcType::kVF, 8, 0)})}),
                    Catch::Contains("CF 0, PC 0: v-f PC: a = 8 is not an index into the vertices "
                                    "of model A 'cube' (8 vertices)"));
  CHECK_THROWS_WITH(build({rec({pc(PcType::kFF, 0, 1)}), rec({pc(PcType::kFE, 0, 18)})}),
                    Catch::Contains("CF 1, PC 0: f-e PC: b = 18 is not an index into the edges of "
                                    "model B 'L-block' (18 edges)"));
  CHECK_NOTHROW(build({rec({pc(PcType::kEE, 11, 17)})}));
}

TEST_CASE("from_parts rejects empty, repeated and coplanar PC sets", "[graph]") {
  CHECK_THROWS_WITH(build({cf::CfRecord()}),
                    Catch::Contains("CF 0: a CF needs 1 to 3 PCs, this one has none"));
  CHECK_THROWS_WITH(build({rec({pc(PcType::kVF, 0, 4)}), rec({pc(PcType::kVF, 0, 4)})}),
                    Catch::Contains("CF 1: PC set {v-f:0:4} repeats CF 0"));
  CHECK_THROWS_WITH(build({rec({pc(PcType::kVF, 0, 4), pc(PcType::kEF, 3, 4)})}),
                    Catch::Contains("share the contact plane of B's face 4"));
  CHECK_THROWS_WITH(build({rec({pc(PcType::kFF, 2, 4), pc(PcType::kFV, 2, 3)})}),
                    Catch::Contains("share the contact plane of A's face 2"));
  // An edge of A's face 2 on an edge of B's face 4 is dominated by the faces' own f-f.
  const int ea = static_cast<int>(cf_test::box(10, 10, 10).faces()[2].edges[0].index());
  const int eb = static_cast<int>(cf_test::l_block().faces()[4].edges[0].index());
  CHECK_THROWS_WITH(
      build({rec({pc(PcType::kFF, 2, 4), pc(PcType::kEE, ea, eb)})}),
      Catch::Contains("CF 0: PC e-e:" + std::to_string(ea) + ":" + std::to_string(eb) +
                      " is dominated by its PC f-f:2:4 (both its elements lie in the other's); "
                      "a CF's PCs are principal"));
  cf::CfRecord freed = rec({pc(PcType::kVF, 0, 4)});
  freed.dof = 2;
  freed.translation_dof = 3;
  CHECK_THROWS_WITH(build({freed}), Catch::Contains("CF 0: translation_dof = 3 exceeds dof = 2"));
  freed.translation_dof = 2;
  CHECK_NOTHROW(build({freed}));
  cf::CfRecord r = rec({pc(PcType::kVF, 0, 4)});
  r.witness.R_BA *= 1.01;  // what from_parts accepts must load back: witnesses are poses
  CHECK_THROWS_WITH(build({r}), Catch::Contains("CF 0: witness R: not a rotation matrix"));
  r.witness.R_BA = cf::Mat3::Identity();
  r.witness.t_BA.x() = std::nan("");
  CHECK_THROWS_WITH(build({r}), Catch::Contains("CF 0: witness t: translation is not finite"));
  r.witness.t_BA.x() = 0;
  r.dof = 7;
  CHECK_THROWS_WITH(build({r}), Catch::Contains("CF 0: dof = 7 is not in 0..6"));
}

TEST_CASE("from_parts rejects transitions that do not fit their CFs", "[graph]") {
  // CF 3's cube edge 0 bounds the cube's face 2: e-f:0:4 neighbours f-f:2:4.
  const std::vector<cf::CfRecord> cfs = {rec({pc(PcType::kFF, 2, 4)}), rec({pc(PcType::kFF, 5, 5)}),
                                         rec({pc(PcType::kFF, 2, 4), pc(PcType::kFF, 5, 5)}),
                                         rec({pc(PcType::kEF, 0, 4)})};
  CHECK_NOTHROW(build(cfs, {tr(0, 2, TransitionKind::kGain), tr(2, 1, TransitionKind::kLose),
                            tr(0, 3, TransitionKind::kChange)}));
  CHECK_THROWS_WITH(build(cfs, {tr(0, 4, TransitionKind::kGain)}),
                    Catch::Contains("transition 0: to = 4 is not a CF id (the graph has 4 CFs)"));
  CHECK_THROWS_WITH(build(cfs, {tr(-1, 0, TransitionKind::kGain)}),
                    Catch::Contains("transition 0: from = -1 is not a CF id"));
  CHECK_THROWS_WITH(build(cfs, {tr(1, 1, TransitionKind::kChange)}),
                    Catch::Contains("from CF 1 to itself"));
  CHECK_THROWS_WITH(
      build(cfs, {tr(2, 0, TransitionKind::kGain)}),
      Catch::Contains("transition 0: kind 'gain' needs the target to be the source plus one PC: "
                      "CF 2 {f-f:2:4;f-f:5:5} -> CF 0 {f-f:2:4}"));
  CHECK_THROWS_WITH(build(cfs, {tr(0, 1, TransitionKind::kLose)}),
                    Catch::Contains("kind 'lose' needs"));
  CHECK_THROWS_WITH(build(cfs, {tr(0, 2, TransitionKind::kChange)}),
                    Catch::Contains("kind 'change' needs the same number of PCs"));
  CHECK_THROWS_WITH(build(cfs, {tr(0, 2, TransitionKind::kGain), tr(0, 3, TransitionKind::kChange),
                                tr(0, 2, TransitionKind::kGain)}),
                    Catch::Contains("transition 2: transition CF 0 -> CF 2 is listed twice"));
}

TEST_CASE("neighbouring PCs follow the boundary relations and are symmetric", "[graph]") {
  const cf::Polyhedron A = cf_test::box(10, 10, 10), B = cf_test::l_block();
  const auto nb = [&](const Pc& x) { return cf::neighbouring_pcs(x, A, B); };
  const auto has = [](const std::vector<Pc>& v, const Pc& x) {
    return std::count(v.begin(), v.end(), x) == 1;
  };
  // The cube's edge 0 joins its vertices 0 and 1 and bounds its faces 0 (z = 0) and 2 (y = 0).
  const std::vector<Pc> ff = nb(pc(PcType::kFF, 2, 4));
  CHECK(has(ff, pc(PcType::kEF, 0, 4)));
  CHECK_FALSE(has(ff, pc(PcType::kFF, 5, 5)));
  CHECK_FALSE(has(ff, pc(PcType::kVF, 0, 4)));  // two steps away, through e-f
  CHECK(std::is_sorted(ff.begin(), ff.end()));
  const std::vector<Pc> ef = nb(pc(PcType::kEF, 0, 4));
  CHECK(has(ef, pc(PcType::kFF, 0, 4)));
  CHECK(has(ef, pc(PcType::kFF, 2, 4)));
  CHECK(has(ef, pc(PcType::kVF, 0, 4)));
  CHECK(has(ef, pc(PcType::kVF, 1, 4)));
  CHECK_FALSE(has(ef, pc(PcType::kVF, 2, 4)));
  // Every PC of the pair is a neighbour of each of its neighbours.
  const PcType types[] = {PcType::kFF, PcType::kEF, PcType::kFE,
                          PcType::kVF, PcType::kFV, PcType::kEE};
  const auto count = [](const cf::Polyhedron& m, cf::ElementKind k) {
    return static_cast<int>(k == cf::ElementKind::kVertex ? m.num_vertices()
                            : k == cf::ElementKind::kEdge ? m.num_edges()
                                                          : m.num_faces());
  };
  std::size_t pairs = 0;
  for (PcType t : types)
    for (int a = 0; a < count(A, cf::a_kind(t)); ++a)
      for (int b = 0; b < count(B, cf::b_kind(t)); ++b)
        for (const Pc& y : nb(pc(t, a, b))) {
          INFO(cf::to_string(pc(t, a, b)) << " -> " << cf::to_string(y));
          CHECK(has(nb(y), pc(t, a, b)));
          ++pairs;
        }
  CHECK(pairs > 0);
}

TEST_CASE("from_parts accepts a change only where PCs are replaced by neighbouring PCs",
          "[graph]") {
  const cf::Polyhedron B = cf_test::l_block();
  // The L-block's edge 2-3 runs along the floor top (face 4) at its bottom; its other face.
  const int eb = cf::test::edge_between(B, 2, 3);
  REQUIRE(eb >= 0);
  const cf::Edge& E = B.edges()[static_cast<std::size_t>(eb)];
  const int fb2 = E.left.value() == 4 ? E.right.value() : E.left.value();
  REQUIRE((E.left.value() == 4 || E.right.value() == 4));
  const std::vector<cf::CfRecord> cfs = {
      rec({pc(PcType::kFF, 2, 4)}),                           // 0
      rec({pc(PcType::kEF, 0, 4)}),                           // 1: f-f:2:4's edge 0 on the floor
      rec({pc(PcType::kVF, 0, 4)}),                           // 2: edge 0's end on the floor
      rec({pc(PcType::kFF, 5, 5)}),                           // 3: the wall
      rec({pc(PcType::kFF, 2, 4), pc(PcType::kFF, 5, 5)}),    // 4
      rec({pc(PcType::kEF, 0, 4), pc(PcType::kFF, 5, 5)}),    // 5: 4 with one PC replaced
      rec({pc(PcType::kVF, 0, 4), pc(PcType::kFF, 5, 5)}),    // 6
      rec({pc(PcType::kVF, 0, 4), pc(PcType::kEE, 0, eb)}),   // 7: v-f:0:4 and its neighbour e-e
      rec({pc(PcType::kEF, 0, fb2), pc(PcType::kVF, 0, 4)}),  // 8: 7's e-e as its neighbour e-f
  };
  using K = TransitionKind;
  // One PC replaced, both ways; one of two replaced; and 7 <-> 8: v-f:0:4 kept while e-e:0:eb
  // becomes its neighbour e-f:0:fb2 (each PC kept or replaced by one of its neighbours, one for
  // one). (e-e:0:eb beside e-f:0:fb2 would not be a CF: the e-f dominates it.)
  CHECK_NOTHROW(build(
      cfs, {tr(0, 1, K::kChange), tr(1, 0, K::kChange), tr(1, 2, K::kChange), tr(4, 5, K::kChange),
            tr(5, 6, K::kChange), tr(7, 8, K::kChange), tr(8, 7, K::kChange)}));
  // Not neighbours: the cube's face 2 on the floor and its face 5 on the wall.
  CHECK_THROWS_WITH(
      build(cfs, {tr(0, 1, K::kChange), tr(0, 3, K::kChange)}),
      Catch::Contains("transition 1: kind 'change' needs the target to be the source with one or "
                      "more PCs replaced by neighbouring PCs, one for one: CF 0 {f-f:2:4} -> "
                      "CF 3 {f-f:5:5}"));
  // Two steps apart (f-f -> e-f -> v-f), with a PC kept.
  CHECK_THROWS_WITH(
      build(cfs, {tr(0, 2, K::kChange)}),
      Catch::Contains(
          "kind 'change' needs the target to be the source with one or more PCs "
          "replaced by neighbouring PCs, one for one: CF 0 {f-f:2:4} -> CF 2 {v-f:0:4}"));
  CHECK_THROWS_WITH(
      build(cfs, {tr(4, 6, K::kChange)}),
      Catch::Contains(
          "transition 0: kind 'change' needs the target to be the source with one or "
          "more PCs replaced by neighbouring PCs, one for one: CF 4 {f-f:2:4;f-f:5:5} -> "
          "CF 6 {f-f:5:5;v-f:0:4}"));
  // The count rule still comes first.
  CHECK_THROWS_WITH(build(cfs, {tr(0, 5, K::kChange)}),
                    Catch::Contains("kind 'change' needs the same number of PCs"));
}

TEST_CASE("from_parts rejects metadata that is not an object or that overrides the graph",
          "[graph]") {
  const std::vector<cf::CfRecord> cfs = {rec({pc(PcType::kFF, 2, 4)})};
  CHECK_THROWS_WITH(build(cfs, {}, "[1]"), Catch::Contains("metadata: expected a JSON object"));
  CHECK_THROWS_WITH(build(cfs, {}, R"({"cfs":1})"),
                    Catch::Contains("member \"cfs\" is part of the graph itself"));
  CHECK_THROWS_WITH(build(cfs, {}, "{"), Catch::Contains("metadata: not valid JSON"));
  CHECK(build(cfs, {}, "").metadata_json() == "{}");
}

// ---- load rejects bad files, naming the file and the JSON pointer ---------------------

TEST_CASE("load: a missing file", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("no_such_file.json")),
      Catch::Contains("reading '" + bad("no_such_file.json") + "': cannot open: no such file"));
}

TEST_CASE("load: a directory", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(kGraphDir),
                    Catch::Contains("reading '" + kGraphDir +
                                    "': cannot open: is a directory, not a regular file"));
}

TEST_CASE("load: a FIFO is refused at once, never read (no writer: reading would block)",
          "[graph][bad]") {
  const std::string fifo = (std::filesystem::temp_directory_path() /
                            ("cf_graph_fifo_" + std::to_string(::getpid()) + ".json"))
                               .string();
  std::remove(fifo.c_str());
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(CfGraph::load(fifo),
                    Catch::Contains("reading '" + fifo +
                                    "': cannot open: is a FIFO (named pipe), not a regular file"));
  std::remove(fifo.c_str());
}

TEST_CASE(
    "load: CBOR and JSON nesting is capped at 256 levels (100,000 used to overflow the stack)",
    "[graph][bad]") {
  // {"x": [[[...null...]]]}: a free-form member, 100,000 arrays deep.
  std::string cbor = "\xa1\x61x";
  cbor.append(100000, '\x81');
  cbor += '\xf6';
  CHECK_THROWS_WITH(
      CfGraph::from_bytes(cbor, "deep.cbor", true),
      Catch::Contains("reading 'deep.cbor': not valid CBOR: nesting deeper than 256 levels"));
  // 256 levels are fine as far as nesting goes (the file then fails for what it lacks).
  std::string ok = "\xa1\x61x";
  ok.append(255, '\x81');
  ok += '\xf6';
  CHECK_THROWS_WITH(CfGraph::from_bytes(ok, "ok.cbor", true), !Catch::Contains("nesting"));
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::string json = R"({"format": "cf-graph", "version": 1, "x":)" + deep + "}";
  CHECK_THROWS_WITH(CfGraph::from_bytes(json, "deep.json", false),
                    Catch::Contains("nesting deeper than 256 levels"));
  // Without a format the file is refused as no graph before its members are read.
  CHECK_THROWS_WITH(CfGraph::from_bytes("{\"x\":" + deep + "}", "deep.json", false),
                    Catch::Contains("reading 'deep.json' at /: missing member \"format\""));
}

TEST_CASE("load: invalid UTF-8 in a CBOR graph's strings is reported, not an internal error",
          "[graph][bad]") {
  // {"format": "\xff"}: nlohmann's dump() throws on invalid UTF-8 unless told to replace it.
  const std::string cbor =
      "\xa1\x66"
      "format"
      "\x61\xff";
  CHECK_THROWS_WITH(CfGraph::from_bytes(cbor, "utf8.cbor", true),
                    Catch::Contains("reading 'utf8.cbor' at /format: format is"));
}

TEST_CASE("load: truncated JSON gives the line and column", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("truncated.json")),
                    Catch::Contains("reading '" + bad("truncated.json") + "': not valid JSON:") &&
                        Catch::Contains("line 6, column"));
}

TEST_CASE("load: an empty file", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("empty.json")),
                    Catch::Contains("reading '" + bad("empty.json") + "': not valid JSON:"));
}

TEST_CASE("load: corrupt CBOR", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("corrupt.cbor")),
                    Catch::Contains("reading '" + bad("corrupt.cbor") + "': not valid CBOR:"));
}

TEST_CASE("load: a JSON document that is not an object", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("not_object.json")),
      Catch::Contains("reading '" + bad("not_object.json") + "' at /: expected a cf-graph object"));
}

TEST_CASE("load: wrong format and version", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("wrong_format.json")),
                    Catch::Contains("'" + bad("wrong_format.json") +
                                    "' at /format: format is \"cf-table\", expected \"cf-graph\""));
  CHECK_THROWS_WITH(CfGraph::load(bad("wrong_version.json")),
                    Catch::Contains("'" + bad("wrong_version.json") +
                                    "' at /version: version 2 is not supported"));
}

TEST_CASE("load: a value of the wrong type", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("wrong_type.json")),
      Catch::Contains("'" + bad("wrong_type.json") +
                      "' at /cfs/1/pcs/0/a: expected a non-negative integer index, got \"5\""));
}

TEST_CASE("load: a missing member", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("missing_witness.json")),
                    Catch::Contains("'" + bad("missing_witness.json") +
                                    "' at /cfs/0: missing member \"witness\""));
}

TEST_CASE("load: an element index out of range", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("index_out_of_range.json")),
                    Catch::Contains("'" + bad("index_out_of_range.json") +
                                    "' at /cfs/3/pcs/0/b: e-f PC: b = 99 is not an index into the "
                                    "faces of model B 'L-block' (8 faces)"));
}

TEST_CASE("load: an unknown PC type", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("unknown_pc_type.json")),
                    Catch::Contains("'" + bad("unknown_pc_type.json") +
                                    "' at /cfs/0/pcs/0/type: unknown PC type \"v-v\""));
}

TEST_CASE("load: a PC type that does not match the element kinds", "[graph][bad]") {
  // a = 11 is a valid edge of the cube but not a vertex: the type says vertex.
  CHECK_THROWS_WITH(CfGraph::load(bad("kind_mismatch.json")),
                    Catch::Contains("'" + bad("kind_mismatch.json") +
                                    "' at /cfs/4/pcs/0/a: v-f PC: a = 11 is not an index into the "
                                    "vertices of model A 'cube' (8 vertices)"));
}

TEST_CASE("load: a transition to a missing CF", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("missing_cf_transition.json")),
      Catch::Contains("'" + bad("missing_cf_transition.json") +
                      "' at /transitions/2/to: to = 17 is not a CF id (the graph has 5 CFs)"));
}

TEST_CASE("load: a transition whose kind does not fit its CFs", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("bad_transition_kind.json")),
      Catch::Contains("'" + bad("bad_transition_kind.json") +
                      "' at /transitions/0/kind: kind 'change' needs the same number of PCs"));
}

TEST_CASE("load: a repeated PC set and a repeated PC", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("repeated_cf.json")),
                    Catch::Contains("'" + bad("repeated_cf.json") +
                                    "' at /cfs/4: PC set {e-f:0:4} repeats CF 3"));
  CHECK_THROWS_WITH(CfGraph::load(bad("repeated_pc.json")),
                    Catch::Contains("'" + bad("repeated_pc.json") +
                                    "' at /cfs/2/pcs/1: PC f-f:2:4 is repeated in this CF"));
}

TEST_CASE("load: a CF id that is not its position", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("id_mismatch.json")),
      Catch::Contains("'" + bad("id_mismatch.json") + "' at /cfs/1/id: id 7 should be 1"));
}

TEST_CASE("load: a witness that is not a rotation", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("not_rotation.json")),
                    Catch::Contains("'" + bad("not_rotation.json") +
                                    "' at /cfs/0/witness/R: not a rotation matrix"));
}

TEST_CASE("load: a broken model", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("bad_model.json")),
      Catch::Contains("'" + bad("bad_model.json") +
                      "' at /models/B/faces/0/loops/0/1: expected a non-negative integer index"));
}

TEST_CASE("load: an unknown member in a witness", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("witness_extra_member.json")),
      Catch::Contains("'" + bad("witness_extra_member.json") +
                      "' at /cfs/2/witness: unexpected member \"q\" (a witness has R and t)"));
}

TEST_CASE("load: a CF with more than 3 PCs", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("pc_count.json")),
      Catch::Contains("'" + bad("pc_count.json") + "' at /cfs/2/pcs: a CF has 1 to 3 PCs, got 4"));
}

TEST_CASE("load: a missing top-level member", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("missing_transitions.json")),
                    Catch::Contains("'" + bad("missing_transitions.json") +
                                    "' at /: missing member \"transitions\""));
}

TEST_CASE("load: a model that breaks the model schema", "[graph][bad]") {
  CHECK_THROWS_WITH(
      CfGraph::load(bad("model_schema_violation.json")),
      Catch::Contains("'" + bad("model_schema_violation.json") +
                      "' at /models/A/faces/0/area: does not match the cf-graph schema:"));
}

TEST_CASE("load: a schema violation the reader itself would let through", "[graph][bad]") {
  CHECK_THROWS_WITH(CfGraph::load(bad("schema_violation.json")),
                    Catch::Contains("'" + bad("schema_violation.json") +
                                    "' at /stats: does not match the cf-graph schema: Value type "
                                    "not permitted by 'type' constraint."));
}

// ---- the JSON parser of the reader ----------------------------------------------------

namespace {

/// The fixture's text with `from` replaced by `to` (first occurrence).
std::string fixture_with(const std::string& from, const std::string& to) {
  std::string text = slurp(kFixture);
  const std::size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("load: a change between PCs that are not neighbours", "[graph][bad]") {
  // CF 1 {f-f:5:5} (the wall) and CF 3 {e-f:0:4} (an edge on the floor): same count, but
  // f-f:5:5 has no neighbouring PC in CF 3.
  const std::string text =
      fixture_with(R"({"from":3,"to":4,"kind":"change"})", R"({"from":1,"to":3,"kind":"change"})");
  CHECK_THROWS_WITH(
      CfGraph::from_bytes(text, "x.json", false),
      Catch::Contains(
          "reading 'x.json' at /transitions/6/kind: kind 'change' needs the target to be "
          "the source with one or more PCs replaced by neighbouring PCs, one for one: "
          "CF 1 {f-f:5:5} -> CF 3 {e-f:0:4}"));
  CHECK_NOTHROW(CfGraph::from_bytes(slurp(kFixture), "x.json", false));
}

TEST_CASE("the reader takes every JSON value form in metadata and names", "[graph][json]") {
  // Escapes, a surrogate pair, raw UTF-8, exponents, -0, integers past int64, nesting.
  const std::string meta =
      R"("stats": {"s": "tab\there \"q\" \\ \/ \u00e9 \ud83d\ude00 é", "e": 1.5e-3, "E": -2E+2, "z": -0.0,)"
      R"( "big": 18446744073709551615, "neg": -9223372036854775808, "past64": -123456789012345678901, "huge": 1e400000, "l": [true, false, null, {}, []]},)";
  const std::string text = fixture_with(R"("stats": {"note":"hand-made test fixture"},)", meta);
  // 1e400000 does not fit a double: rejected with its position.
  CHECK_THROWS_WITH(CfGraph::from_bytes(text, "m.json", false),
                    Catch::Contains("'m.json': not valid JSON: syntax error at line 6") &&
                        Catch::Contains("number out of the range of a double"));
  const CfGraph g =
      CfGraph::from_bytes(fixture_with(R"("stats": {"note":"hand-made test fixture"},)",
                                       [&] {
                                         std::string m = meta;
                                         m.replace(m.find("1e400000"), 8, "1e300");
                                         return m;
                                       }()),
                          "m.json", false);
  CHECK(g.metadata_json() ==
        "{\"parameters\":{\"epsilon_mm\":1.0},\"stats\":{\"E\":-200.0,\"big\":18446744073709551615,"
        "\"e\":0.0015,"
        "\"huge\":1e+300,\"l\":[true,false,null,{},[]],\"neg\":-9223372036854775808,\"past64\":-1."
        "2345678901234568e+20,"
        "\"s\":\"tab\\there \\\"q\\\" \\\\ / \xc3\xa9 \xf0\x9f\x98\x80 \xc3\xa9\",\"z\":-0.0}}");
  // A model name with escapes survives the round trip.
  const CfGraph n = CfGraph::from_bytes(
      fixture_with(R"("name": "cube")", R"("name": "c\u00fcbe \"1\"")"), "n.json", false);
  CHECK(n.model_a().name() ==
        "c\xc3\xbc"
        "be \"1\"");
  check_same(n, CfGraph::from_bytes(n.to_json(), "n2.json", false));
}

TEST_CASE("the reader rejects malformed JSON with the line and column", "[graph][json]") {
  struct Case {
    std::string from, to, message;
  };
  // simdjson (libcf/src/io/graph_reader.cpp) reports where it stopped: the value it could not
  // read, or the token after a structural fault.
  const std::string kStructure = "improper structure";
  const std::vector<Case> cases = {
      {R"("version": 1,)", R"("version": 01,)", "line 3, column 13 near '0': invalid number"},
      {R"("version": 1,)", R"("version": 1.,)", "line 3, column 13 near '1': invalid number"},
      {R"("version": 1,)", R"("version": 1e,)", "line 3, column 13 near '1': invalid number"},
      {R"("version": 1,)", R"("version": -,)", "line 3, column 13 near '-': invalid number"},
      // An integer past 64 bits (read as a double) must still end where the token ends.
      {R"("version": 1,)", R"("version": 91111111111111111111z1,)",
       "line 3, column 13 near '9': invalid number"},
      {R"("version": 1,)", R"("version": tru,)", "line 3, column 13 near 't': invalid literal"},
      {R"("version": 1,)", R"("version": nul,)", "line 3, column 13 near 'n': invalid literal"},
      {R"("version": 1,)", R"("version": 1,,)",
       "line 3, column 15 near ',': The JSON document has an " + kStructure},
      {R"("name": "cube")", R"("name": "cu\qbe")", "near '\"': invalid string (an unknown escape"},
      {R"("name": "cube")", R"("name": "cu\ud800be")", "unpaired UTF-16 surrogate"},
      {"{\n \"format\"", "{\n \"format\" \"x\",",
       "line 2, column 11 near '\"': The JSON document has an " + kStructure},
      {R"([[1.0,0.0,0.0])", R"([[1.0 0.0,0.0])", kStructure},
  };
  for (const Case& c : cases) {
    INFO(c.to);
    CHECK_THROWS_WITH(CfGraph::from_bytes(fixture_with(c.from, c.to), "x.json", false),
                      Catch::Contains("reading 'x.json': not valid JSON: syntax error at ") &&
                          Catch::Contains(c.message));
  }
  // Faults of simdjson's first pass over the bytes come without a position.
  const std::vector<Case> first_pass = {
      {R"("name": "cube")", "\"name\": \"cu\tbe\"", "some characters must be escaped"},
      {R"("name": "cube")",
       "\"name\": \"cu\xff"
       "be\"",
       "not valid UTF-8"},
      {R"("name": "cube")",
       "\"name\": \"cu\xc0\xaf"
       "be\"",
       "not valid UTF-8"},
      {R"("name": "cube")", R"("name": "cube)", "not valid JSON: "},
  };
  for (const Case& c : first_pass) {
    INFO(c.to);
    CHECK_THROWS_WITH(
        CfGraph::from_bytes(fixture_with(c.from, c.to), "x.json", false),
        Catch::StartsWith("reading 'x.json': not valid JSON: ") && Catch::Contains(c.message));
  }
  CHECK_THROWS_WITH(CfGraph::from_bytes(slurp(kFixture) + "x", "t.json", false),
                    Catch::Contains("unexpected content after the JSON value"));
  CHECK_THROWS_WITH(
      CfGraph::from_bytes(std::string(300, '[') + std::string(300, ']'), "d.json", false),
      Catch::Contains("line 1, column 257 near '[': nesting deeper than 256 levels"));
  CHECK_THROWS_WITH(CfGraph::from_bytes(" \n ", "w.json", false),
                    Catch::Contains("line 2, column 2 at the end of the input: empty input"));
}

TEST_CASE("load: a member named twice is refused, in JSON and in CBOR", "[graph][bad]") {
  // Readers disagree on what a repeated name means (Python's json keeps the last, this reader
  // joined two cfs arrays), so the file is refused, at the second one.
  struct Case {
    std::string from, to, pointer, name;
  };
  const std::vector<Case> cases = {
      {R"("units": "mm",)", R"("units": "mm", "units": "mm",)", "/units", "units"},
      {R"("transitions": [)", R"("cfs": [], "transitions": [)", "/cfs", "cfs"},
      {R"({"id":0,"pcs":[{"type":"f-f","a":2,"b":4}])",
       R"({"id":0,"pcs":[{"type":"f-f","a":2,"a":3,"b":4}])", "/cfs/0/pcs/0", "a"},
      {R"({"id":0,"pcs")", R"({"id":0,"id":0,"pcs")", "/cfs/0", "id"},
      {R"("t":[20.0,10.0,5.0]})", R"("t":[20.0,10.0,5.0],"t":[0,0,0]})", "/cfs/0/witness", "t"},
      {R"({"from":3,"to":4,"kind":"change"})", R"({"from":3,"to":4,"to":4,"kind":"change"})",
       "/transitions/", "to"},
      {R"("name": "cube",)", R"("name": "cube", "name": "box",)", "/models", "name"},
  };
  for (const Case& c : cases) {
    INFO(c.to);
    const std::string text = fixture_with(c.from, c.to);
    const std::string want = "member \"" + c.name + "\" appears twice in this object";
    CHECK_THROWS_WITH(
        CfGraph::from_bytes(text, "twice.json", false),
        Catch::Contains("reading 'twice.json' at " + c.pointer) && Catch::Contains(want));
  }
  // CBOR: {"format": "cf-graph", "version": 1, "format": "x"}, written byte by byte.
  const std::string cbor = std::string("\xa3\x66") + "format" + "\x68" + "cf-graph" + "\x67" +
                           "version" + "\x01\x66" + "format" + "\x61" + "x";
  CHECK_THROWS_WITH(CfGraph::from_bytes(cbor, "twice.cbor", true),
                    Catch::Contains("reading 'twice.cbor' at /format: member \"format\" appears "
                                    "twice in this object"));
}

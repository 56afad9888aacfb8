// Catch2: the certificate checker (certificate_check.hpp) on hand-made graphs and
// certificates with known answers: a 10 mm cube A = [0,10]^3 against an L-block B (the profile
// (0,0) (30,0) (30,10) (10,10) (10,20) (0,20) in x-y, extruded over z in [0,30]; up is +y).
// Each claim is accepted as written and rejected after the change that must flip it. The rule
// mirror-corners is tested on data/models' 30 mm cube and L-block and on prisms made here.

#include "certificate_check.hpp"
#include "poly_lookup.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <sstream>

using namespace oracle;
using json = nlohmann::json;
using oracle::test::edge_along;
using oracle::test::vertex_at;

namespace {

const double kPiD = 3.14159265358979323846;

// A box [0,sx]x[0,sy]x[0,sz]: faces 0 bottom z=0 (-z), 1 top (+z), 2 front y=0 (-y), 3 back
// (+y), 4 left x=0 (-x), 5 right (+x). Vertex i = (sx (i&1), sy (i>>1 &1), sz (i>>2 &1)).
json box_model(double sx, double sy, double sz) {
  json m;
  for (int i = 0; i < 8; ++i)
    m["vertices"].push_back({sx * (i & 1), sy * ((i >> 1) & 1), sz * ((i >> 2) & 1)});
  m["faces"] = json::array();
  for (auto L : std::vector<std::vector<int>>{
           {0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}})
    m["faces"].push_back({{"loops", {L}}});
  return m;
}

// A's cube [0,10]^3.
json cube_model() { return box_model(10, 10, 10); }

// B's faces: 0 bottom cap z=0 (-z), 1 top cap z=30, then the sides of the profile: 2 y=0, 3
// x=30, 4 the low top y=10, 5 the riser x=10, 6 the tower top y=tower, 7 x=0.
json lblock_model(double tower) {
  const std::vector<std::pair<double, double>> prof = {{0, 0},   {30, 0},     {30, 10},
                                                       {10, 10}, {10, tower}, {0, tower}};
  json m;
  for (double z : {0.0, 30.0})
    for (auto [x, y] : prof) m["vertices"].push_back({x, y, z});
  m["faces"] = json::array();
  m["faces"].push_back({{"loops", {{5, 4, 3, 2, 1, 0}}}});
  m["faces"].push_back({{"loops", {{6, 7, 8, 9, 10, 11}}}});
  for (int i = 0; i < 6; ++i)
    m["faces"].push_back({{"loops", {{i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i}}}});
  return m;
}

void add_edges(json& m) {
  std::set<std::pair<int, int>> es;
  for (const auto& f : m["faces"])
    for (const auto& L : f["loops"])
      for (std::size_t i = 0; i < L.size(); ++i) {
        int a = L[i], b = L[(i + 1) % L.size()];
        es.insert({std::min(a, b), std::max(a, b)});
      }
  m["edges"] = json::array();
  for (auto [a, b] : es) m["edges"].push_back({a, b});
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("certcheck_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

struct Pair {
  json doc;
  Graph G;
  double margin;
};

// The graph file of A and B (no CFs unless given), with the verifier's parameters.
Pair pair_of(json A, json B, double margin, json cfs = json::array()) {
  Pair P;
  P.margin = margin;
  add_edges(A);
  add_edges(B);
  P.doc = {{"format", "cf-graph"},           {"version", 1}, {"units", "mm"},
           {"models", {{"A", A}, {"B", B}}}, {"cfs", cfs},   {"transitions", json::array()}};
  P.doc["parameters"] = {
      {"touch_tol_mm", 1e-9}, {"min_margin_mm", margin}, {"angle_margin_rad", 1e-3}};
  const std::string path = temp_path("graph.json");
  std::ofstream(path) << P.doc.dump();
  P.G = read_graph(path);
  std::filesystem::remove(path);
  return P;
}

// The cube against the L-block.
Pair make_pair(double margin = 0.01, double tower = 20, json cfs = json::array()) {
  return pair_of(cube_model(), lblock_model(tower), margin, cfs);
}

json cert_for(const Pair& P, json sets, json pieces = json()) {
  const double size = std::max(P.G.A.diag, P.G.B.diag);
  json c = {{"format", "cf-certificates"}, {"version", 1}, {"graph", "G.json"}};
  c["tolerances"] = {{"touch_tol_mm", 1e-9},
                     {"min_margin_mm", P.margin},
                     {"local_slack", 0.5 * std::sin(1e-3)},
                     {"rounding_mm", 1e-12 * size},
                     {"off_circle_rad", 2e-8},
                     {"size_mm", size}};
  if (!pieces.is_null()) c["pieces"] = pieces;
  int rule = 0, cells = 0, thin = 0, und = 0;
  for (const auto& s : sets) {
    rule += s.contains("rule");
    cells += s.contains("cells");
    thin += s["outcome"] == "thin";
    und += s["outcome"] == "undecided";
  }
  c["summary"] = {{"sets", sets.size()},
                  {"invalid_by_rule", rule},
                  {"invalid_by_cells", cells},
                  {"thin", thin},
                  {"undecided", und}};
  c["sets"] = sets;
  return c;
}

CertificateReport run(const Pair& P, const json& cert) {
  return check_certificates(P.G, P.doc["parameters"], cert);
}

// One set, checked; the file itself must be fine.
CertSetResult one(const Pair& P, const json& set, const json& pieces = json()) {
  const CertificateReport rep = run(P, cert_for(P, json::array({set}), pieces));
  for (const auto& p : rep.file_problems) INFO("file problem: " << p);
  CHECK(rep.file_problems.empty());
  REQUIRE(rep.sets.size() == 1);
  INFO(rep.sets[0].pcs << ": " << rep.sets[0].reason);
  return rep.sets[0];
}

json rule_set(const std::string& pcs, const std::string& rule, std::vector<int> inv) {
  return {{"pcs", pcs}, {"outcome", "invalid"}, {"rule", rule}, {"pcs_involved", inv}};
}

std::string pcs_of(const std::string& t1, int a1, int b1, const std::string& t2 = "", int a2 = 0,
                   int b2 = 0) {
  std::string s = t1 + ":" + std::to_string(a1) + ":" + std::to_string(b1);
  if (!t2.empty()) s += ";" + t2 + ":" + std::to_string(a2) + ":" + std::to_string(b2);
  return s;
}

// ---- trees ----

json v3(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

struct TreeB {
  json nodes = json::array();
  Vec3 lo = Vec3::Constant(-100), hi = Vec3::Constant(100);
  int add(int parent, const json& rot, const std::string& kind, json extra = json::object(),
          const Vec3* blo = nullptr, const Vec3* bhi = nullptr) {
    const int id = static_cast<int>(nodes.size());
    json n = {{"id", id},
              {"parent", parent},
              {"rot", rot},
              {"t_lo", v3(blo ? *blo : lo)},
              {"t_hi", v3(bhi ? *bhi : hi)},
              {"kind", kind}};
    for (auto& [k, v] : extra.items()) n[k] = v;
    nodes.push_back(n);
    return id;
  }
};

json cube_rot(const Vec3& c, double h) { return {{"centre", v3(c)}, {"half", h}}; }
json arc_rot(double c, double h) { return {{"arc", {c, h}}}; }

// The eight children of cube (c, h) under parent; child (bits) gets kind_of(bits), the others
// "bounds". Returns the ids by bits (bit a set: + side on axis a).
std::vector<int> split8(TreeB& T, int parent, const Vec3& c, double h,
                        const std::function<std::string(int)>& kind_of) {
  std::vector<int> ids(8);
  for (int bits = 0; bits < 8; ++bits) {
    Vec3 cc = c;
    for (int a = 0; a < 3; ++a) cc[a] += ((bits >> a) & 1) ? h / 2 : -h / 2;
    ids[bits] = T.add(parent, cube_rot(cc, h / 2), kind_of(bits));
  }
  return ids;
}

json cells_set(const std::string& pcs, const Vec3& pivot, const TreeB& T,
               const json& circle = json()) {
  json cells = {
      {"pivot", v3(pivot)}, {"domain", circle.is_null() ? "ball" : "circle"}, {"nodes", T.nodes}};
  if (!circle.is_null()) cells["circle"] = circle;
  return {{"pcs", pcs}, {"outcome", "invalid"}, {"cells", cells}};
}

const CertNodeFailure* failure_of(const CertSetResult& r, int node) {
  for (const auto& f : r.node_fails)
    if (f.node == node) return &f;
  return nullptr;
}

// The f-f circle of A's bottom face (-z) on B's face n_B = +y: R0 turns -z onto -y.
json circle_ff(int pc) {
  return {{"pc", pc}, {"R0", {1, 0, 0, 0, 0, 1, 0, -1, 0}}, {"axis", {0, 0, -1}}};
}

// A rectangle's piece table entry: corners CCW in (u, v), every side on the boundary.
json face_entry(int face, const Vec3& n, double offset, const Vec3& U, const Vec3& V,
                const std::vector<std::vector<std::pair<double, double>>>& pieces,
                const std::vector<std::vector<bool>>& flags) {
  json e = {{"face", face}};
  e["frame"] = {{"n", v3(n)}, {"offset", offset}, {"U", v3(U)}, {"V", v3(V)}};
  e["pieces"] = json::array();
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    json p = {{"points", json::array()}, {"boundary", flags[i]}};
    for (auto [u, v] : pieces[i]) p["points"].push_back({u, v});
    e["pieces"].push_back(p);
  }
  return e;
}

// B's tower top (face 6, y = 20): U = z, V = x, so (u, v) = (z, x).
json tower_top_one_piece() {
  return face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                    {{{0, 0}, {30, 0}, {30, 10}, {0, 10}}}, {{true, true, true, true}});
}

// ---- mirror-corners: the cube and L-block of data/models ----

json mesh_model(const Mesh& m) {
  json j;
  for (const Vec3& p : m.V) j["vertices"].push_back({p.x(), p.y(), p.z()});
  j["faces"] = json::array();
  for (const auto& f : m.F) j["faces"].push_back({{"loops", {f}}});
  return j;
}

// data/models/<file> (each facet one face), each vertex at `move` of its place when given.
json off_model(const std::string& file, const std::function<Vec3(const Vec3&)>& move = {}) {
  Mesh m = read_off(std::string(CF_SOURCE_DIR) + "/data/models/" + file);
  if (move)
    for (Vec3& p : m.V) p = move(p);
  return mesh_model(m);
}

// The polygon `profile` (counter-clockwise in x-y) extruded over z in [0, depth]: faces 0 the
// bottom cap, 1 the top cap, then the sides.
json prism_model(const std::vector<Vec2>& profile, double depth) {
  Mesh m;
  const int n = static_cast<int>(profile.size());
  for (double z : {0.0, depth})
    for (const Vec2& p : profile) m.V.emplace_back(p.x(), p.y(), z);
  m.F.emplace_back();
  m.F.emplace_back();
  for (int i = 0; i < n; ++i) {
    m.F[0].push_back(n - 1 - i);
    m.F[1].push_back(n + i);
    m.F.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  }
  return mesh_model(m);
}

// The rule on the set {e-e:a1:b1; e-e:a2:b2}, pcs_involved {0, 1}.
CertSetResult mirror_rule(const Pair& P, int a1, int b1, int a2, int b2) {
  return one(P, rule_set(pcs_of("e-e", a1, b1, "e-e", a2, b2), "mirror-corners", {0, 1}));
}

// A rigid motion x -> R x + t (the identity by default); R applied alone to directions.
struct Rigid {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  Vec3 operator()(const Vec3& p) const { return R * p + t; }
};

// A generic motion: a turn by `angle` about an axis along none of x, y, z, then a shift. Its
// images of integer points are doubles, in general not exactly coplanar when the points were.
Rigid generic_motion(const Vec3& axis, double angle, const Vec3& t) {
  Rigid m;
  m.R = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  m.t = t;
  return m;
}

// The 30 mm cube (vertices (+-15, +-15, +-15)) against the L-block, whose reflex corner
// w = (20, 20, 80) has its rims along +x (on the slab top y = 20) and +y (on the wall x = 20),
// both on the end face z = 80. v = (15, 15, 15) is a corner of the cube; its edges along -x and
// -y lie on the top face z = 15. B may be another L-block, its rim `rim_y` in place of +y, and
// A another cube (`A`); the models (as given) are A and B moved by ma and mb, and so are the
// points and directions that find v, w and the edges.
struct CubeL {
  Pair P;
  int v, w, ax, ay, az, bx, by;  // v, w; A's edges from v along -x, -y, -z; B's rims +x, +y
  explicit CubeL(json B = off_model("l_block.off"), const Vec3& rim_y = Vec3(0, 1, 0),
                 const Rigid& ma = Rigid(), const Rigid& mb = Rigid(), json A = json())
      : P(pair_of(A.is_null() ? off_model("cube.off", ma) : A, B, 0.01)) {
    v = vertex_at(P.G.A, ma(Vec3(15, 15, 15)));
    w = vertex_at(P.G.B, mb(Vec3(20, 20, 80)));
    ax = edge_along(P.G.A, v, ma.R * Vec3(-1, 0, 0));
    ay = edge_along(P.G.A, v, ma.R * Vec3(0, -1, 0));
    az = -1;  // the third edge at v (down -z when the cube is not bent)
    for (int e : P.G.A.V[v].edges)
      if (e != ax && e != ay) az = e;
    bx = edge_along(P.G.B, w, mb.R * Vec3(1, 0, 0));
    by = edge_along(P.G.B, w, mb.R * rim_y);
  }
};
}  // namespace

TEST_CASE("header: format, version and unreadable files are input errors with their text") {
  Pair P = make_pair();
  json c = cert_for(P, json::array());
  c["format"] = "cf-graph";
  try {
    run(P, c);
    FAIL("no error");
  } catch (const CertificateInputError& e) {
    CHECK(std::string(e.what()) == "format is \"cf-graph\", expected \"cf-certificates\"");
  }
  c["format"] = "cf-certificates";
  c["version"] = 2;
  try {
    run(P, c);
    FAIL("no error");
  } catch (const CertificateInputError& e) {
    CHECK(std::string(e.what()) == "version is 2, expected 1");
  }
  try {
    check_certificate_files("/nonexistent/G.json", "/nonexistent/C.json");
    FAIL("no error");
  } catch (const CertificateInputError& e) {
    CHECK(std::string(e.what()) == "cannot open graph /nonexistent/G.json");
  }
  const std::string g = temp_path("g.json"), bad = temp_path("bad.json");
  std::ofstream(g) << P.doc.dump();
  std::ofstream(bad) << "{ not json";
  try {
    check_certificate_files(g, bad);
    FAIL("no error");
  } catch (const CertificateInputError& e) {
    CHECK_THAT(e.what(), Catch::StartsWith("certificate file " + bad + ": not JSON ("));
  }
  std::filesystem::remove(g);
  std::filesystem::remove(bad);
}

TEST_CASE("tolerances: missing, non-positive or stronger than the graph's are file problems") {
  Pair P = make_pair();
  json c = cert_for(P, json::array());
  c["tolerances"].erase("min_margin_mm");
  c["tolerances"]["off_circle_rad"] = 0;
  c["tolerances"]["touch_tol_mm"] = 1e-10;
  CertificateReport rep = run(P, c);
  CHECK_FALSE(rep.passed());
  std::set<std::string> got(rep.file_problems.begin(), rep.file_problems.end());
  CHECK(got.count("tolerances.min_margin_mm is missing"));
  CHECK(got.count("tolerances.off_circle_rad = 0 is not positive"));
  CHECK(got.count("tolerances.touch_tol_mm 1e-10 is below the graph's 1e-09"));
  c = cert_for(P, json::array());
  c["summary"]["sets"] = 3;
  rep = run(P, c);
  REQUIRE(rep.file_problems.size() == 1);
  CHECK(rep.file_problems[0] == "summary.sets is not 0");
  CHECK(run(P, cert_for(P, json::array())).passed());
}

TEST_CASE("rule vertex-in-two-pcs") {
  Pair P = make_pair();
  CHECK(one(P, rule_set("v-f:0:4;v-f:0:6", "vertex-in-two-pcs", {0, 1})).outcome ==
        CertOutcome::Accepted);
  CHECK(one(P, rule_set("f-v:0:3;e-e:0:3", "vertex-in-two-pcs", {0, 1})).outcome ==
        CertOutcome::Rejected);  // vertex 3 of B and edge 3 of B are different elements
  auto r = one(P, rule_set("v-f:0:4;v-f:1:6", "vertex-in-two-pcs", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason == "PCs v-f:0:4 and v-f:1:6 share no vertex");
  r = one(P, rule_set("v-f:0:4;v-f:0:6", "vertex-in-two-pcs", {0, 0}));
  CHECK(r.reason == "malformed: pcs_involved is not two distinct PCs of the set");
  r = one(P, rule_set("v-v:0:4;v-f:0:6", "vertex-in-two-pcs", {0, 1}));
  CHECK(r.reason == "malformed: \"v-v:0:4\" is not a PC type:a:b");
  r = one(P, rule_set("v-f:0:4;v-f:0:99", "vertex-in-two-pcs", {0, 1}));
  CHECK(r.reason == "malformed: \"v-f:0:99\" names an element the models do not have");
}

TEST_CASE("rule dominated-pc") {
  Pair P = make_pair();
  // A's vertex 0 is a corner of A's face 0; both PCs on B's face 4.
  CHECK(one(P, rule_set("f-f:0:4;v-f:0:4", "dominated-pc", {1, 0})).outcome ==
        CertOutcome::Accepted);
  const int e = P.G.A.edge_index(0, 1);  // an edge of A's face 0
  CHECK(one(P, rule_set(pcs_of("f-f", 0, 4, "e-f", e, 4), "dominated-pc", {1, 0})).outcome ==
        CertOutcome::Accepted);
  auto r = one(P, rule_set("f-f:0:4;v-f:7:4", "dominated-pc", {1, 0}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason == "neither of v-f:7:4 and f-f:0:4 lies in the other's closures");
}

TEST_CASE("rule one-contact-plane") {
  Pair P = make_pair();
  const int e = P.G.A.edge_index(4, 5);
  CHECK(one(P, rule_set(pcs_of("v-f", 0, 4, "e-f", e, 4), "one-contact-plane", {0, 1})).outcome ==
        CertOutcome::Accepted);
  CHECK(one(P, rule_set("f-v:0:3;f-v:0:5", "one-contact-plane", {0, 1})).outcome ==
        CertOutcome::Accepted);  // A's face 0 in both
  auto r = one(P, rule_set("v-f:0:4;v-f:1:6", "one-contact-plane", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason == "PCs v-f:0:4 and v-f:1:6 have no faces of A or of B in one plane");
}

TEST_CASE("rule heights-over-ff, with the checker's sound separation") {
  Pair P = make_pair();
  // A's bottom face on B's low top (y = 10): A's vertex 4 (depth 10 below A's face) cannot
  // reach B's face 2 (height -10 over the low top), vertex 0 (depth 0) not the tower top (10).
  CHECK(one(P, rule_set("f-f:0:4;v-f:4:2", "heights-over-ff", {0, 1})).outcome ==
        CertOutcome::Accepted);
  CHECK(one(P, rule_set("f-f:0:4;v-f:0:6", "heights-over-ff", {0, 1})).outcome ==
        CertOutcome::Accepted);
  // Vertex 4 at depth 10 reaches the tower top at height 10: the rule does not hold.
  auto r = one(P, rule_set("f-f:0:4;v-f:4:6", "heights-over-ff", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::StartsWith("depths of A's element [10, 10] and heights of B's "
                                         "[10, 10] are not more than"));
  CHECK(one(P, rule_set("f-f:0:4;v-f:4:6", "heights-over-ff", {1, 0})).reason ==
        "pcs_involved[0] is not an f-f");
  // A tower 1e-7 mm higher: more than the spec's 1e-9 size + touch_tol apart, but a witness's
  // f-f may tilt by 1e-8 rad, moving A's far points by 1e-8 diag(A) = 1.7e-7 mm.
  Pair Q = make_pair(0.01, 20 + 1e-7);
  r = one(Q, rule_set("f-f:0:4;v-f:4:6", "heights-over-ff", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  Pair S = make_pair(0.01, 20 + 1e-5);
  CHECK(one(S, rule_set("f-f:0:4;v-f:4:6", "heights-over-ff", {0, 1})).outcome ==
        CertOutcome::Accepted);
}

TEST_CASE("rule rotational-conditions") {
  Pair P = make_pair();
  const int ez = P.G.A.edge_index(0, 4), ex = P.G.A.edge_index(0, 1);
  // A's bottom face on B's low top: A's vertical edge turns to +-y, so it can never lie on the
  // tower top (normal +y); it always lies parallel to B's bottom cap (normal -z), and a
  // horizontal edge always lies parallel to the tower top: those rules do not hold.
  CHECK(one(P, rule_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), "rotational-conditions", {0, 1}))
            .outcome == CertOutcome::Accepted);
  auto r = one(P, rule_set(pcs_of("f-f", 0, 4, "e-f", ex, 6), "rotational-conditions", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::StartsWith("the conditions may all hold near theta ="));
  r = one(P, rule_set(pcs_of("f-f", 0, 4, "e-f", ez, 0), "rotational-conditions", {0, 1}));
  CHECK(r.outcome == CertOutcome::Rejected);
  // Two f-f: A's faces 0 and 1 are opposite, B's faces 4 and 7 perpendicular: impossible; A's
  // faces 0 and 2 are perpendicular like B's 4 and 7: possible.
  CHECK(one(P, rule_set("f-f:0:4;f-f:1:7", "rotational-conditions", {0, 1})).outcome ==
        CertOutcome::Accepted);
  CHECK(one(P, rule_set("f-f:0:4;f-f:2:7", "rotational-conditions", {0, 1})).outcome ==
        CertOutcome::Rejected);
  // f-e: A's top face (its normal turns to +y) against B's edge 1-2 (along y): never parallel;
  // against B's edge 3-9 (along z): always.
  CHECK(one(P, rule_set(pcs_of("f-f", 0, 4, "f-e", 1, P.G.B.edge_index(1, 2)),
                        "rotational-conditions", {0, 1}))
            .outcome == CertOutcome::Accepted);
  CHECK(one(P, rule_set(pcs_of("f-f", 0, 4, "f-e", 1, P.G.B.edge_index(3, 9)),
                        "rotational-conditions", {0, 1}))
            .outcome == CertOutcome::Rejected);
  r = one(P, rule_set(pcs_of("e-f", ex, 4, "e-f", ez, 6), "rotational-conditions", {0, 1}));
  CHECK(r.reason == "no f-f among the PCs involved: this rule does not refute sets without one");
}

namespace {
// Every corner of the cube, every ordered pair of its edges (48), against the reflex corner of
// the L at w = mb((20, 20, z)) with its rims along mb.R (+x, +y): the rule's verdicts.
struct PairCounts {
  int pairs = 0, accepted = 0, handed = 0;
};
PairCounts all_pairs(const CubeL& C, const Rigid& mb, double z) {
  const int w = vertex_at(C.P.G.B, mb(Vec3(20, 20, z)));
  const int bx = edge_along(C.P.G.B, w, mb.R * Vec3(1, 0, 0)),
            by = edge_along(C.P.G.B, w, mb.R * Vec3(0, 1, 0));
  PairCounts n;
  for (const auto& vert : C.P.G.A.V)
    for (int e1 : vert.edges)
      for (int e2 : vert.edges) {
        if (e1 == e2) continue;
        const CertSetResult r = mirror_rule(C.P, e1, bx, e2, by);
        ++n.pairs;
        n.accepted += r.outcome == CertOutcome::Accepted;
        n.handed += r.reason.find("same handedness (condition 6)") != std::string::npos;
      }
  return n;
}

// The L-block with its wall's inner top edge (20, 80, z) moved by dx along x: the rim at w
// from (20, 20, 80) along (dx, 60, 0), so c_B = dx / sqrt(dx^2 + 3600).
json wall_moved(double dx) {
  return off_model("l_block.off", [dx](const Vec3& p) {
    return p.x() == 20 && p.y() == 80 ? Vec3(20 + dx, 80, p.z()) : p;
  });
}
}  // namespace

TEST_CASE("rule mirror-corners: the cube's corner against the L's reflex corner, mirror order") {
  CubeL C;
  // a_1 = -y against b_1 = +x, a_2 = -x against b_2 = +y: det(a_1, a_2, +z) = -1 on the cube's
  // top face, det(b_1, b_2, +z) = +1 on the L's end face; the angles are equal (c_A = c_B = 0,
  // T = s^2 / 4 = 6.2e-8) and every dihedral angle is 90 degrees (x = 0): no pose with margins
  // of at least the slack (mirror_corners_theorem_test).
  CHECK(mirror_rule(C.P, C.ay, C.bx, C.ax, C.by).outcome == CertOutcome::Accepted);
  CHECK(mirror_rule(C.P, C.ax, C.by, C.ay, C.bx).outcome == CertOutcome::Accepted);
  CHECK(one(C.P, rule_set(pcs_of("e-e", C.ax, C.by, "e-e", C.ay, C.bx), "mirror-corners", {1, 0}))
            .outcome == CertOutcome::Accepted);
  // Both reflex corners of the L (rims +x, +y): half of the 48 pairs at each are mirror images.
  for (const double z : {80.0, 0.0}) {
    const PairCounts n = all_pairs(C, Rigid(), z);
    INFO("w at z = " << z);
    CHECK(n.pairs == 48);
    CHECK(n.accepted == 24);
    CHECK(n.handed == 24);
  }
}

TEST_CASE("rule mirror-corners: the models moved by generic rigid motions are still accepted") {
  // Each model turned about an axis along none of x, y, z and shifted, its coordinates the
  // doubles of those images: faces planar and angles equal only to rounding (~1e-15; none of
  // the moved cube's six faces is exactly planar, which the former exact rule rejected), which
  // the robust rule absorbs. The verdicts are those of the models in place.
  const Rigid ma = generic_motion(Vec3(1, 2, 3), 0.7, Vec3(3.3, -1.7, 2.9));
  const Rigid mb = generic_motion(Vec3(-2, 0.5, 1.25), 2.1, Vec3(-41.1, 7.3, 0.35));
  for (const bool both : {false, true}) {
    const Rigid mbb = both ? mb : Rigid();
    CubeL C(off_model("l_block.off", mbb), Vec3(0, 1, 0), ma, mbb);
    INFO((both ? "both models moved" : "the cube moved"));
    CHECK(mirror_rule(C.P, C.ay, C.bx, C.ax, C.by).outcome == CertOutcome::Accepted);
    CHECK(mirror_rule(C.P, C.ax, C.by, C.ay, C.bx).outcome == CertOutcome::Accepted);
    const CertSetResult r = mirror_rule(C.P, C.ax, C.bx, C.ay, C.by);
    CHECK_THAT(r.reason, Catch::StartsWith("the corners have the same handedness (condition 6)"));
    for (const double z : {80.0, 0.0}) {
      const PairCounts n = all_pairs(C, mbb, z);
      INFO("w at z = " << z);
      CHECK(n.pairs == 48);
      CHECK(n.accepted == 24);
      CHECK(n.handed == 24);
    }
  }
}

TEST_CASE("rule mirror-corners: the same-handed order, which has poses, is rejected") {
  CubeL C;
  // a_1 = -x against b_1 = +x, a_2 = -y against b_2 = +y: the cube's corner up in the notch
  // (docs/generator.md, "Two e-e PCs at mirror corners").
  const CertSetResult r = mirror_rule(C.P, C.ax, C.bx, C.ay, C.by);
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason ==
        "the corners have the same handedness (condition 6): det(a_1, a_2, n(G)) det(b_1, b_2, "
        "n(F)) = 1 (needs < -4e-09)");
}

TEST_CASE("rule mirror-corners: corner angles that differ by T or more are rejected") {
  // The L's wall leans: its inner top edge (20, 80, z) moved to (30, 80, z), so the rims at w
  // make 80.5 degrees (cosine 1/sqrt(37) = 0.164), the cube's corner 90.
  CubeL L(wall_moved(10), Vec3(10, 60, 0));
  CHECK(mirror_rule(L.P, L.ay, L.bx, L.ax, L.by).reason ==
        "the corners' angles differ by more than the tolerance (condition 5): |c_A - c_B| = "
        "0.164 >= T = 5.15e-08");
  // The wall moved by 1e-3 mm (c_B = 1.67e-5) and by 1e-5 mm (1.67e-7): rejected; by 1e-6 mm
  // (1.67e-8, below T = s^2 / 4 = 6.2e-8): accepted.
  CubeL M(wall_moved(1e-3), Vec3(1e-3, 60, 0));
  CHECK(mirror_rule(M.P, M.ay, M.bx, M.ax, M.by).reason ==
        "the corners' angles differ by more than the tolerance (condition 5): |c_A - c_B| = "
        "1.67e-05 >= T = 6.25e-08");
  CubeL N(wall_moved(1e-5), Vec3(1e-5, 60, 0));
  CHECK(mirror_rule(N.P, N.ay, N.bx, N.ax, N.by).reason ==
        "the corners' angles differ by more than the tolerance (condition 5): |c_A - c_B| = "
        "1.67e-07 >= T = 6.25e-08");
  CubeL K(wall_moved(1e-6), Vec3(1e-6, 60, 0));
  CHECK(mirror_rule(K.P, K.ay, K.bx, K.ax, K.by).outcome == CertOutcome::Accepted);
  // A triangular prism's corner of 53.13 degrees (cosine 3/5) at v = (0, 0, 30), its edges along
  // +x and (3, 4, 0) on the top face, against a slanted L whose notch at w = (40, 20, 80) is
  // 126.87 degrees (cosine -3/5).
  const json prism = prism_model({{0, 0}, {30, 0}, {18, 24}}, 30);
  const Pair S = pair_of(
      prism, prism_model({{-60, 0}, {120, 0}, {120, 20}, {40, 20}, {-5, 80}, {-25, 80}}, 80), 0.01);
  const int v = vertex_at(S.G.A, Vec3(0, 0, 30)), w = vertex_at(S.G.B, Vec3(40, 20, 80));
  const int a1 = edge_along(S.G.A, v, Vec3(1, 0, 0)), a2 = edge_along(S.G.A, v, Vec3(3, 4, 0));
  const int b1 = edge_along(S.G.B, w, Vec3(1, 0, 0)), b2 = edge_along(S.G.B, w, Vec3(-3, 4, 0));
  CHECK(mirror_rule(S, a1, b1, a2, b2).reason ==
        "the corners' angles differ by more than the tolerance (condition 5): |c_A - c_B| = 1.2 "
        ">= T = 2e-08");
}

TEST_CASE("rule mirror-corners: a dihedral angle below 90 degrees by the slack is rejected") {
  // The prism of the previous test: its vertical edge at v (-z) with the edge along +x, on the
  // side face y = 0; the vertical edge's dihedral angle is 53.13 degrees (x = 0.6).
  const Pair S = pair_of(
      prism_model({{0, 0}, {30, 0}, {18, 24}}, 30),
      prism_model({{-60, 0}, {120, 0}, {120, 20}, {40, 20}, {-5, 80}, {-25, 80}}, 80), 0.01);
  const int v = vertex_at(S.G.A, Vec3(0, 0, 30)), w = vertex_at(S.G.B, Vec3(40, 20, 80));
  const int a1 = edge_along(S.G.A, v, Vec3(1, 0, 0)), az = edge_along(S.G.A, v, Vec3(0, 0, -1));
  const int b1 = edge_along(S.G.B, w, Vec3(1, 0, 0)), b2 = edge_along(S.G.B, w, Vec3(-3, 4, 0));
  CHECK(mirror_rule(S, a1, b1, az, b2).reason ==
        "the dihedral angle at a_2 (edge " + std::to_string(az) +
            " of A) is below 90 degrees by as much as the slack (condition 4): x = -n(G) . n(G_2) "
            "= 0.6 >= s - 4e-09 = 0.0005");
  // The cube's face x = 15 leaned in at the bottom by theta: its edge a_1 = -y at v (with the
  // top face) has the dihedral angle 90 degrees - theta, x = sin theta. theta = 1e-3 is above
  // s = 5e-4: rejected; theta = 1e-5 is below: accepted (T = 6.1e-8 > 0 = |c_A - c_B|).
  for (const double theta : {1e-3, 1e-5}) {
    const json leaned = off_model("cube.off", [theta](const Vec3& p) {
      return p.x() == 15 && p.z() == -15 ? Vec3(15 - 30 * std::tan(theta), p.y(), p.z()) : p;
    });
    CubeL C(off_model("l_block.off"), Vec3(0, 1, 0), Rigid(), Rigid(), leaned);
    const CertSetResult r = mirror_rule(C.P, C.ay, C.bx, C.ax, C.by);
    INFO("theta = " << theta << ": " << r.reason);
    if (theta > 5e-4)
      CHECK(r.reason == "the dihedral angle at a_1 (edge " + std::to_string(C.ay) +
                            " of A) is below 90 degrees by as much as the slack (condition 4): x "
                            "= -n(G) . n(G_1) = 0.001 >= s - 4e-09 = 0.0005");
    else
      CHECK(r.outcome == CertOutcome::Accepted);
  }
}

TEST_CASE("rule mirror-corners: a convex w, a reflex edge and a reflex v are rejected") {
  CubeL C;
  // The L's convex corner (120, 20, 80): rims along -x and -y on the end face.
  const int w = vertex_at(C.P.G.B, Vec3(120, 20, 80));
  const int b1 = edge_along(C.P.G.B, w, Vec3(-1, 0, 0)),
            b2 = edge_along(C.P.G.B, w, Vec3(0, -1, 0));
  CHECK(mirror_rule(C.P, C.ay, b1, C.ax, b2).reason ==
        "w (vertex " + std::to_string(w) +
            " of B) is not a saddle (condition 3): n(F_1) . b_2 = -1 (needs > 4e-09)");
  CHECK(mirror_rule(C.P, C.ax, b1, C.ay, b2).reason ==
        "w (vertex " + std::to_string(w) +
            " of B) is not a saddle (condition 3): n(F_1) . b_2 = -1 (needs > 4e-09)");
  // The L's reflex edge from w down (-z), with the rim +x on the slab top (their common face).
  const int br = edge_along(C.P.G.B, C.w, Vec3(0, 0, -1));
  CHECK(mirror_rule(C.P, C.ay, C.bx, C.az, br).reason ==
        "b_2 (edge " + std::to_string(br) +
            " of B) is not convex (condition 1): (n(L) x n(R)) . d = -1 (needs > 1e-13)");
  // The roles swapped: the L moves (its reflex corner as v), the cube is fixed.
  const Pair S = pair_of(off_model("l_block.off"), off_model("cube.off"), 0.01);
  const int v = vertex_at(S.G.A, Vec3(20, 20, 80));
  const int wc = vertex_at(S.G.B, Vec3(15, 15, 15));
  CHECK(mirror_rule(S, edge_along(S.G.A, v, Vec3(1, 0, 0)), edge_along(S.G.B, wc, Vec3(0, -1, 0)),
                    edge_along(S.G.A, v, Vec3(0, 1, 0)), edge_along(S.G.B, wc, Vec3(-1, 0, 0)))
            .reason == "v (vertex " + std::to_string(v) +
                           " of A) is not convex (condition 2): n(G_1) . a_2 = 1 (needs < -4e-09)");
}

TEST_CASE("rule mirror-corners: faces bent within rounding are fine, malformed claims rejected") {
  // The L's end face z = 80 bent by 1e-8 mm at (0, 0, 80): inside the oracle's planarity
  // tolerance (1e-6 of the diagonal) but not exactly planar. Its normal turns by ~2e-10 rad,
  // within condition 7's 1e-9 of perpendicular to the rims, so x ~ 2e-10 and c_B is
  // unchanged: the conditions hold within their tolerances, and the mirror order is accepted,
  // the same-handed one still rejected.
  CubeL C(off_model("l_block.off",
                    [](const Vec3& p) { return p == Vec3(0, 0, 80) ? Vec3(0, 0, 80 + 1e-8) : p; }));
  CHECK(mirror_rule(C.P, C.ay, C.bx, C.ax, C.by).outcome == CertOutcome::Accepted);
  CHECK_THAT(mirror_rule(C.P, C.ax, C.bx, C.ay, C.by).reason,
             Catch::StartsWith("the corners have the same handedness (condition 6)"));
  // Not e-e, no shared vertex, no common face, one edge twice.
  CubeL D;
  auto r = one(D.P, rule_set(pcs_of("e-e", D.ay, D.bx, "e-f", D.ax, 1), "mirror-corners", {0, 1}));
  CHECK(r.reason == "PC e-f:" + std::to_string(D.ax) + ":1 (pcs_involved[1]) is not an e-e");
  const int far = D.P.G.A.edge_index(vertex_at(D.P.G.A, Vec3(-15, -15, -15)),
                                     vertex_at(D.P.G.A, Vec3(15, -15, -15)));
  CHECK(mirror_rule(D.P, D.ay, D.bx, far, D.by).reason == "A's edges " + std::to_string(D.ay) +
                                                              " and " + std::to_string(far) +
                                                              " share no end vertex");
  CHECK(mirror_rule(D.P, D.ay, D.bx, D.ay, D.by).reason ==
        "the two PCs have the same edge " + std::to_string(D.ay) + " of A");
  // A pyramid's apex has four edges: opposite ones share no face.
  const Pair Y =
      pair_of(mesh_model(make_pyramid(30, 30, 20, 0, 0)), off_model("l_block.off"), 0.01);
  const int apex = 4, e0 = Y.G.A.edge_index(apex, 0), e2 = Y.G.A.edge_index(apex, 2);
  CHECK(mirror_rule(Y, e0, D.bx, e2, D.by).reason == "A's edges " + std::to_string(e0) + " and " +
                                                         std::to_string(e2) +
                                                         " lie on no common face");
}

TEST_CASE("rule mirror-corners: a face normal tilted off an edge by 1e-6 is rejected") {
  // The L's end face z = 80 (F at w) bent by 1e-4 mm at (0, 0, 80): still inside the oracle's
  // planarity tolerance (1e-6 of the diagonal, 1.6e-4 mm), so the oracle builds it, but its
  // Newell normal turns by ~1e-6 rad towards +x and +y: n(F) . b_1 (b_1 = +x) is 1.1e-6,
  // beyond condition 7's 1e-9. The mirror order is rejected; 1e-8 mm (previous test) passes.
  CubeL C(off_model("l_block.off",
                    [](const Vec3& p) { return p == Vec3(0, 0, 80) ? Vec3(0, 0, 80 + 1e-4) : p; }));
  const CertSetResult r = mirror_rule(C.P, C.ay, C.bx, C.ax, C.by);
  INFO(r.reason);
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason ==
        "n(F) . b_1 = 1.11e-06 (condition 7: a face normal more than 1e-9 from perpendicular to "
        "the edge)");
  // A bend of the cube's top face z = 15 (G at v) at its corner (-15, -15, 15), within the
  // cube's tolerance (diagonal 52 mm): 3e-5 mm, which turns n(G) by ~1e-6: n(G) . a_1 (a_1 = -y)
  // is -5e-7.
  const json bent = off_model("cube.off", [](const Vec3& p) {
    return p == Vec3(-15, -15, 15) ? Vec3(-15, -15, 15 + 3e-5) : p;
  });
  CubeL D(off_model("l_block.off"), Vec3(0, 1, 0), Rigid(), Rigid(), bent);
  const CertSetResult q = mirror_rule(D.P, D.ay, D.bx, D.ax, D.by);
  INFO(q.reason);
  CHECK(q.reason ==
        "n(G) . a_1 = -5e-07 (condition 7: a face normal more than 1e-9 from perpendicular to the "
        "edge)");
}

TEST_CASE("finite-rotations is not certified, unknown rules and CFs of the graph are rejected") {
  json cf = {{"id", 0},
             {"pcs", {{{"type", "f-f"}, {"a", 0}, {"b", 4}}}},
             {"witness", {{"R", {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}}, {"t", {15, 10, 5}}}}};
  Pair P = make_pair(0.01, 20, json::array({cf}));
  auto r = one(P, rule_set("f-f:0:4;v-f:4:6", "finite-rotations", {0, 1}));
  CHECK(r.outcome == CertOutcome::NotCertified);
  CHECK(one(P, rule_set("f-f:0:4;v-f:4:6", "magic", {0, 1})).reason == "unknown rule \"magic\"");
  r = one(P, rule_set("f-f:0:4", "rotational-conditions", {0}));
  CHECK(r.reason == "the graph holds this set as a CF with a witness");
  CertificateReport rep =
      run(P, cert_for(P, json::array({rule_set("f-f:0:4;v-f:4:6", "finite-rotations", {0, 1}),
                                      rule_set("v-f:0:4;v-f:0:6", "vertex-in-two-pcs", {0, 1})})));
  CHECK(rep.passed());
  CHECK(rep.accepted == 1);
  CHECK(rep.not_certified == 1);
  CHECK(rep.summary_line().find("finite-rotations 0/0/1") != std::string::npos);
}

// A THIN row: A's front face (2) on B's low top (4), its left face (4) a given gap from the
// riser (5). Identity rotation, so x_B = x_A + t.
json thin_set(double gap, double claimed, double lift = 0) {
  json R = json::array(
      {json::array({1.0, 0.0, 0.0}), json::array({0.0, 1.0, 0.0}), json::array({0.0, 0.0, 1.0})});
  return {{"pcs", "f-f:2:4"},
          {"outcome", "thin"},
          {"clearance_mm", claimed},
          {"margin_mm", 0.5},
          {"pose", {{"R", R}, {"t", {10.0 + gap, 10.0 + lift, 5.0}}}}};
}

TEST_CASE("thin: the pose must realise exactly the set, as clear as claimed") {
  Pair P = make_pair();
  CHECK(one(P, thin_set(1e-3, 1e-3)).outcome == CertOutcome::Accepted);
  auto r = one(P, thin_set(0, 0));  // A's left face on the riser too
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason.rfind("the pose realises ", 0) == 0);
  CHECK(r.reason.find("f-f:4:5") != std::string::npos);
  r = one(P, thin_set(1e-3, 1e-3, -0.01));  // 0.01 mm into the low top
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason.rfind("the pose penetrates: ", 0) == 0);
  r = one(P, thin_set(1e-3, 0.5));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason == "clearance 0.001000 mm, not the 0.500000 mm claimed");
  const CertificateReport rep = run(P, cert_for(P, json::array({thin_set(1e-3, 1e-3)})));
  CHECK(rep.passed());
  CHECK(rep.accepted == 1);
  CHECK(rep.by_kind.at("thin")[static_cast<int>(CertOutcome::Accepted)] == 1);
}

TEST_CASE("cells: a rotation leaf over the whole f-f circle") {
  Pair P = make_pair();
  const int ez = P.G.A.edge_index(0, 4), ex = P.G.A.edge_index(0, 1);
  TreeB T;
  T.add(-1, arc_rot(0, kPiD), "rotation", {{"pc", 1}});
  // The vertical edge turns about itself: (R e).n_tower = 1 on the whole circle.
  auto r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), Vec3(5, 5, 5), T, circle_ff(0)));
  CHECK(r.outcome == CertOutcome::Accepted);
  CHECK(r.leaves.at("rotation")[0] == 1);
  // A horizontal edge sweeps the circle: the half-width pi is far too wide for the claim.
  r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ex, 6), Vec3(5, 5, 5), T, circle_ff(0)));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::Contains("node 0: rotation: PC 1 (e-f:"));
  // An axis that is not A's face normal, or too small an off-circle allowance, leaves
  // rotations of the f-f out of the circle's cells.
  json bad = circle_ff(0);
  bad["axis"] = {0, 1e-6, -1};
  r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), Vec3(5, 5, 5), T, bad));
  CHECK_THAT(r.reason, Catch::StartsWith("tree: off_circle_rad 2e-08 does not cover"));
  bad = circle_ff(0);
  bad["R0"] = {1, 0, 0, 0, 0, 1, 0, 1, 0};  // a reflection that also turns -z onto -y
  r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), Vec3(5, 5, 5), T, bad));
  CHECK(r.reason == "tree: circle.R0 is not a rotation (det <= 0)");
  // The root must be the whole circle.
  TreeB half;
  half.add(-1, arc_rot(0, kPiD / 2), "rotation", {{"pc", 1}});
  r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), Vec3(5, 5, 5), half, circle_ff(0)));
  CHECK_THAT(r.reason, Catch::Contains("does not cover the circle"));
  // The root box must hold every translation the PCs allow.
  TreeB small;
  small.lo = Vec3(0, 0, 0);
  small.hi = Vec3(20, 20, 20);
  small.add(-1, arc_rot(0, kPiD), "rotation", {{"pc", 1}});
  r = one(P, cells_set(pcs_of("f-f", 0, 4, "e-f", ez, 6), Vec3(5, 5, 5), small, circle_ff(0)));
  CHECK_THAT(r.reason, Catch::Contains("does not hold the pivot's reachable translations"));
}

TEST_CASE("cells: split-rotation tiling, bounds and outside-ball leaves") {
  Pair P = make_pair();
  // A's vertices 0 and 1 (10 mm apart) on B's faces x = 0 and x = 30: no translation fits.
  const std::string pcs = "v-f:0:7;v-f:1:3";
  const Vec3 pivot(5, 0, 0);
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "split-rotation");
  auto kids = split8(T, root, Vec3::Zero(), kPiD, [](int b) {
    return b == 7 ? std::string("split-rotation") : std::string("bounds");
  });
  const Vec3 c1 = Vec3::Constant(kPiD / 2);
  auto g2 = split8(T, kids[7], c1, kPiD / 2, [](int b) {
    return b == 7 ? std::string("split-rotation") : std::string("bounds");
  });
  const Vec3 c2 = Vec3::Constant(3 * kPiD / 4);
  auto g3 = split8(T, g2[7], c2, kPiD / 4, [](int b) {
    return b == 0 ? std::string("bounds") : std::string("outside-ball");
  });
  auto r = one(P, cells_set(pcs, pivot, T));
  CHECK(r.outcome == CertOutcome::Accepted);
  CHECK(r.leaves.at("outside-ball")[0] == 7);
  // The cube [pi/2, 3 pi/4]^3 reaches the ball: not outside it.
  TreeB U = T;
  U.nodes[g3[0]]["kind"] = "outside-ball";
  r = one(P, cells_set(pcs, pivot, U));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::StartsWith("node " + std::to_string(g3[0]) +
                                         ": outside-ball: the cube (grown by "));
  CHECK_THAT(r.reason, Catch::EndsWith(") reaches the ball |r| <= pi"));
  // A tree missing one child does not tile the domain.
  TreeB M = T;
  M.nodes.erase(M.nodes.begin() + kids[3]);
  r = one(P, cells_set(pcs, pivot, M));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason == "node 0: split-rotation: 7 children, a split-rotation has 8");
  // A child that is not a dyadic half.
  TreeB D = T;
  D.nodes[kids[2]]["rot"]["centre"][0] = 1.0;
  CHECK_THAT(one(P, cells_set(pcs, pivot, D)).reason, Catch::Contains("is not a dyadic half"));
  // A bounds leaf where the PCs do fit somewhere is rejected.
  TreeB B1;
  B1.add(-1, cube_rot(Vec3::Zero(), kPiD), "bounds");
  CHECK(one(P, cells_set(pcs, pivot, B1)).outcome == CertOutcome::Accepted);
  r = one(P, cells_set("v-f:0:7;v-f:1:5", pivot, B1));
  CHECK(r.reason ==
        "node 0: bounds: the root box is not empty and no edge of the set is "
        "shorter than 2 min_margin_mm");
}

TEST_CASE("cells: split-translation and narrow must tile the box") {
  Pair P = make_pair();
  const std::string pcs = "v-f:0:7;v-f:1:3";
  const Vec3 pivot(5, 0, 0);
  const json rot = cube_rot(Vec3::Zero(), kPiD);
  TreeB T;
  const int root = T.add(-1, rot, "split-translation", {{"axis", 1}, {"at", 3.0}});
  Vec3 hi1 = T.hi, lo2 = T.lo;
  hi1.y() = 3;
  lo2.y() = 3;
  T.add(root, rot, "bounds", json::object(), &T.lo, &hi1);
  const int nar = T.add(root, rot, "narrow", json::object(), &lo2, &T.hi);
  // The narrow node's box [lo2, hi]: a child box and slabs around it.
  Vec3 clo(-50, 10, -100), chi(50, 100, 100);
  T.add(nar, rot, "bounds", json::object(), &clo, &chi);
  Vec3 s1lo = lo2, s1hi(-50, 100, 100);        // x below the child
  Vec3 s2lo(50, 3, -100), s2hi = T.hi;         // x above
  Vec3 s3lo(-50, 3, -100), s3hi(50, 10, 100);  // y below
  T.add(nar, rot, "bounds", json::object(), &s1lo, &s1hi);
  T.add(nar, rot, "bounds", json::object(), &s2lo, &s2hi);
  const int s3 = T.add(nar, rot, "bounds", json::object(), &s3lo, &s3hi);
  CHECK(one(P, cells_set(pcs, pivot, T)).outcome == CertOutcome::Accepted);
  TreeB M = T;
  M.nodes.erase(M.nodes.begin() + s3);
  auto r = one(P, cells_set(pcs, pivot, M));
  CHECK(r.reason == "node " + std::to_string(nar) +
                        ": narrow: the children do not cover the box: [-50,50]x[3,10]x[-100,100] "
                        "is left out");
  TreeB W = T;
  W.nodes[root]["at"] = 4.0;
  CHECK(one(P, cells_set(pcs, pivot, W)).reason ==
        "node 0: split-translation: the children are not the box cut at 4 across axis 1");
}

TEST_CASE("cells: a program leaf with hand-derived Farkas multipliers") {
  // A's vertex 7 on B's tower top (x in [0, 10]) with a 6 mm margin: 2 x 6 > 10, so no contact
  // point fits. Pivot = the vertex: W = touch + rounding. Rows: n.z <= 20 + W, -n.z <= -20 +
  // W, then the sides: -x <= -6 + W, z <= 24 + W, x <= 4 + W, -z <= -6 + W. y = 1 on the two
  // x rows: 0 > -2 + 2 W.
  Pair P = make_pair(6.0);
  const json pieces = {{"B", {tower_top_one_piece()}}};
  TreeB T;
  T.lo = Vec3(-1, 19, -1);
  T.hi = Vec3(11, 21, 31);
  const json y = {0, 0, 1, 0, 1, 0};
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "program",
                         {{"farkas", {{{"choice", {0}}, {"y", y}}}}});
  const Vec3 pivot(10, 10, 10);
  auto r = one(P, cells_set("v-f:7:6", pivot, T), pieces);
  CHECK(r.outcome == CertOutcome::Accepted);
  CHECK(r.leaves.at("program")[0] == 1);
  // One multiplier changed: (-1 + 0.5) x over the box goes down to -5.5, not above -4 + 1.5 W.
  TreeB C = T;
  C.nodes[root]["farkas"][0]["y"] = {0, 0, 1, 0, 0.5, 0};
  r = one(P, cells_set("v-f:7:6", pivot, C), pieces);
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::StartsWith("node 0: program: choice [0]: Farkas gap -1.5"));
  C.nodes[root]["farkas"][0]["y"] = {0, 0, 1, 0, -1, 0};
  CHECK(one(P, cells_set("v-f:7:6", pivot, C), pieces).reason ==
        "node 0: program: choice [0]: multiplier 4 is -1 (must be >= 0)");
  C.nodes[root]["farkas"][0]["y"] = {0, 0, 1, 0, 1};
  CHECK(one(P, cells_set("v-f:7:6", pivot, C), pieces).reason ==
        "node 0: program: choice [0]: y has 5 multipliers for 6 rows");
  C.nodes[root]["farkas"] = json::array();
  CHECK(one(P, cells_set("v-f:7:6", pivot, C), pieces).reason ==
        "node 0: program: choice [0] has no multipliers");
  CHECK(one(P, cells_set("v-f:7:6", pivot, T)).reason ==
        "node 0: program: no pieces for face 6 of B");
  // The margin removed (4 mm: 2 x 4 < 10, a contact point fits): the same y fails.
  Pair Q = make_pair(4.0);
  r = one(Q, cells_set("v-f:7:6", pivot, T), pieces);
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::Contains("Farkas gap -2"));
}

TEST_CASE("programs: an A edge's widening is beta's chord, not its largest end") {
  // A's edge 0-1 (x = (10 s, 0, 0)) on B's tower top (y = 20, x in [0, 10]), pivot vertex 0,
  // a cube of half 1 / (10 sqrt 3) at the identity: beta(x_0 - p) = 0, beta(x_1 - p) = 1, so
  // W = touch + rounding + s (the old rows: + 1 for every s). With t_y >= 20.5 and t_x >= 8,
  // row 0 is t_y - s <= 20 + W0 and row 4 (x <= 10 - m) t_x + 9 s <= 10 - m + W0: 9 row 0 +
  // row 4 leaves 0 s and 192.5 > 189.99 + 10 W0. With W the largest end the same sum is 192.5
  // + 10 s > 199.99 + 10 W0, not a contradiction (a contact point needs s >= 0.5 here, where
  // the turn moves it by 0.5, and then lies past x = 10 - m).
  Pair P = make_pair();
  const json pieces = {{"B", {tower_top_one_piece()}}};
  const int ex = P.G.A.edge_index(0, 1);
  const std::string pcs = pcs_of("e-f", ex, 6);
  const json rot = cube_rot(Vec3::Zero(), 1 / (10 * std::sqrt(3.0)));
  const Vec3 lo(8, 20.5, 5), hi(9, 21, 6);
  const json y = {9, 0, 0, 0, 1, 0};
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  const int prog =
      T.add(root, rot, "program", {{"farkas", {{{"choice", {0}}, {"y", y}}}}}, &lo, &hi);
  auto r = one(P, cells_set(pcs, Vec3(0, 0, 0), T), pieces);
  CHECK_FALSE(failure_of(r, prog));
  // The chord runs from x_0 (s = 0) to x_1: about vertex 1 the widening is 1 - s, and the
  // same multipliers leave 20 s - 17.5 of the gap.
  r = one(P, cells_set(pcs, Vec3(10, 0, 0), T), pieces);
  const CertNodeFailure* f = failure_of(r, prog);
  REQUIRE(f);
  CHECK_THAT(f->why, Catch::StartsWith("program: choice [0]: Farkas gap -17.4"));
  // Row 0 alone carries the chord's slope: t_y - s goes down to 20.5 - 0.999 over the box,
  // 0.499 below 20 + W0 (with the largest end, t_y <= 21 + W0: 0.5 below).
  TreeB U = T;
  U.nodes[prog]["farkas"][0]["y"] = {1, 0, 0, 0, 0, 0};
  r = one(P, cells_set(pcs, Vec3(0, 0, 0), U), pieces);
  f = failure_of(r, prog);
  REQUIRE(f);
  CHECK_THAT(f->why, Catch::StartsWith("program: choice [0]: Farkas gap -0.499"));
}

TEST_CASE("cells: a wrongly flagged diagonal does not make a false program pass") {
  // The tower top split at x = 5 into two pieces; their shared side at x = 5 is a diagonal.
  // With a 3 mm margin a contact point fits (x in [3, 7]), but flagging the diagonal as
  // boundary would give x <= 2 in piece 0 and x >= 8 in piece 1.
  Pair P = make_pair(3.0);
  const json face =
      face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                 {{{0, 0}, {30, 0}, {30, 5}, {0, 5}}, {{0, 5}, {30, 5}, {30, 10}, {0, 10}}},
                 {{true, true, true, true}, {true, true, true, true}});
  const json pieces = {{"B", {face}}};
  TreeB T;
  T.lo = Vec3(-1, 19, -1);
  T.hi = Vec3(11, 21, 31);
  const json y = {0, 0, 1, 0, 1, 0};
  T.add(-1, cube_rot(Vec3::Zero(), kPiD), "program",
        {{"farkas", {{{"choice", {0}}, {"y", y}}, {{"choice", {1}}, {"y", y}}}}});
  CertificateReport rep =
      run(P, cert_for(P, json::array({cells_set("v-f:7:6", Vec3(10, 10, 10), T)}), pieces));
  REQUIRE(rep.sets.size() == 1);
  CHECK(rep.sets[0].outcome == CertOutcome::Rejected);
  CHECK_THAT(rep.sets[0].reason, Catch::StartsWith("node 0: program: choice [0]: Farkas gap -"));
  REQUIRE(rep.warnings.size() == 2);
  CHECK(rep.warnings[0] ==
        "face 6 of B: piece 0 side 2 is flagged on the face's boundary but lies off it; the "
        "checker uses its own decision");
}

TEST_CASE("pieces: frames, convexity and tiling are checked") {
  Pair P = make_pair();
  auto problems = [&](const json& face) {
    return run(P, cert_for(P, json::array(), {{"B", {face}}})).file_problems;
  };
  CHECK(problems(tower_top_one_piece()).empty());
  json f = tower_top_one_piece();
  f["frame"]["V"] = {-1, 0, 0};
  auto p = problems(f);
  REQUIRE(p.size() == 1);
  CHECK(p[0] == "pieces: face 6 of B: frame is not orthonormal with U x V = n (defect 2)");
  f = tower_top_one_piece();
  f["frame"]["offset"] = 20.5;
  CHECK(problems(f)[0] == "pieces: face 6 of B: frame offset is 0.5 mm off the face's plane");
  // One of two pieces missing: the diagonal at x = 5 is not shared.
  f = face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                 {{{0, 0}, {30, 0}, {30, 5}, {0, 5}}}, {{true, true, false, true}});
  CHECK(problems(f)[0] ==
        "pieces: face 6 of B: side 2 of piece 0 is neither on the face's "
        "boundary nor shared with another piece");
  f = face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                 {{{0, 0}, {30, 0}, {30, 10}, {0, 10}}, {{0, 0}, {30, 0}, {30, 5}, {0, 5}}},
                 {{true, true, true, true}, {true, true, false, true}});
  CHECK(problems(f)[0] == "pieces: face 6 of B: pieces 0 and 1 overlap (by 5 mm)");
  f = face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                 {{{0, 0}, {0, 10}, {30, 10}, {30, 0}}}, {{true, true, true, true}});
  CHECK(problems(f)[0] ==
        "pieces: face 6 of B: piece 0 is not convex and counter-clockwise at corner 1");
  f = face_entry(6, Vec3(0, 1, 0), 20, Vec3(0, 0, 1), Vec3(1, 0, 0),
                 {{{0, 0}, {31, 0}, {31, 10}, {0, 10}}}, {{true, true, true, true}});
  CHECK(problems(f)[0] == "pieces: face 6 of B: piece 0 has a corner 1 mm outside the face");
}

TEST_CASE("programs: the spec's full margin is not implied at a reflex corner of a face") {
  // B's bottom cap (face 0, the L) split from the reflex corner (10, 10) to (0, 0). The point
  // (10 - 0.8 m, 10 - 0.8 m) is 1.13 m from the boundary (its nearest point is the reflex
  // corner), yet it violates the row y <= 10 - m of piece 0 and x <= 10 - m of piece 1. A
  // program over a box around it is feasible for a real contact; with the spec's margins the
  // multipliers below would "prove" otherwise. The checker's margins, reduced near the reflex
  // corner, do not let them.
  Pair P = make_pair();
  const double m = P.margin;
  // Frame: n = -z, offset 0, U = x, V = -y: (u, v) = (x, -y).
  const json face = face_entry(
      0, Vec3(0, 0, -1), 0, Vec3(1, 0, 0), Vec3(0, -1, 0),
      {{{0, 0}, {10, -10}, {30, -10}, {30, 0}}, {{0, 0}, {0, -20}, {10, -20}, {10, -10}}},
      {{false, true, true, true}, {true, true, true, false}});
  const json pieces = {{"B", {face}}};
  TreeB T;
  const json rot = cube_rot(Vec3::Zero(), kPiD);
  const int root = T.add(-1, rot, "narrow");
  const double c = 10 - 0.8 * m, d = 0.05 * m;
  const Vec3 lo(c - d, c - d, -d), hi(c + d, c + d, d);
  // Rows: n.z twice, then piece 0's sides (the second is y <= 10 - m), or piece 1's (the third
  // is x <= 10 - m).
  const int prog = T.add(root, rot, "program",
                         {{"farkas",
                           {{{"choice", {0}}, {"y", {0, 0, 0, 1, 0, 0}}},
                            {{"choice", {1}}, {"y", {0, 0, 0, 0, 1, 0}}}}}},
                         &lo, &hi);
  const CertSetResult r = one(P, cells_set("v-f:7:0", Vec3(10, 10, 10), T), pieces);
  const CertNodeFailure* f = failure_of(r, prog);
  REQUIRE(f);
  CHECK_THAT(f->why, Catch::StartsWith("program: choice [0]: Farkas gap -"));
  // The same multipliers over a box 0.9 m.. inside in y (piece 0) are fine: the reduced
  // margin there is sin(45 deg) m = 0.707 m.
  TreeB T2;
  const int root2 = T2.add(-1, rot, "narrow");
  const Vec3 lo2(20, 10 - 0.5 * m, -d), hi2(20.1, 10 - 0.4 * m, d);
  const int p2 = T2.add(root2, rot, "program",
                        {{"farkas",
                          {{{"choice", {0}}, {"y", {0, 0, 0, 1, 0, 0}}},
                           {{"choice", {1}}, {"y", {0, 0, 0, 0, 0, 1}}}}}},
                        &lo2, &hi2);
  const CertSetResult r2 = one(P, cells_set("v-f:7:0", Vec3(10, 10, 10), T2), pieces);
  CHECK_FALSE(failure_of(r2, p2));
}

TEST_CASE("cells: an f-f program over the whole circle (A's face narrower than 2 m)") {
  // A's bottom face (10 x 10) with a 6 mm margin: u >= 6 and u <= 4 in A's piece.
  Pair P = make_pair(6.0);
  const json a0 = face_entry(0, Vec3(0, 0, -1), 0, Vec3(1, 0, 0), Vec3(0, -1, 0),
                             {{{0, 0}, {0, -10}, {10, -10}, {10, 0}}}, {{true, true, true, true}});
  const json b4 = face_entry(4, Vec3(0, 1, 0), 10, Vec3(0, 0, 1), Vec3(1, 0, 0),
                             {{{0, 10}, {30, 10}, {30, 30}, {0, 30}}}, {{true, true, true, true}});
  const json pieces = {{"A", {a0}}, {"B", {b4}}};
  TreeB T;
  // Rows: A's piece (u >= 6, -v <= 4, u <= 4, v <= -6), then B's face (2 + 4 rows).
  const json y = {1, 0, 1, 0, 0, 0, 0, 0, 0, 0};
  const int root =
      T.add(-1, arc_rot(0, kPiD), "program", {{"farkas", {{{"choice", {0, 0}}, {"y", y}}}}});
  auto r = one(P, cells_set("f-f:0:4", Vec3(5, 5, 5), T, circle_ff(0)), pieces);
  CHECK(r.outcome == CertOutcome::Accepted);
  T.nodes[root]["farkas"][0]["y"] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  r = one(P, cells_set("f-f:0:4", Vec3(5, 5, 5), T, circle_ff(0)), pieces);
  CHECK(r.outcome == CertOutcome::Rejected);
}

TEST_CASE("cells: rotation leaves refute only when the turn bound allows") {
  Pair P = make_pair();
  const int ex = P.G.A.edge_index(0, 1);
  const std::string pcs = pcs_of("e-f", ex, 3);  // A's x edge on B's face x = 30
  // Depth 3 under the corner (+,+,+): the cube of centre (pi/8)(1,1,1), half pi/8:
  // (R_c x).x = 0.852 > sqrt(3) pi / 8 = 0.680.
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "split-rotation");
  auto k1 = split8(T, root, Vec3::Zero(), kPiD, [](int b) {
    return b == 7 ? std::string("split-rotation") : std::string("bounds");
  });
  auto k2 = split8(T, k1[7], Vec3::Constant(kPiD / 2), kPiD / 2, [](int b) {
    return b == 0 ? std::string("split-rotation") : std::string("bounds");
  });
  auto k3 = split8(T, k2[0], Vec3::Constant(kPiD / 4), kPiD / 4,
                   [](int b) { return b == 0 ? std::string("rotation") : std::string("bounds"); });
  T.nodes[k3[0]]["pc"] = 0;
  auto r = one(P, cells_set(pcs, Vec3(5, 0, 0), T));
  CHECK_FALSE(failure_of(r, k3[0]));
  // Its parent as the leaf (half pi/4): 0.473 < 1.36.
  TreeB W = T;
  W.nodes.erase(W.nodes.begin() + k3[0], W.nodes.end());
  W.nodes[k2[0]]["kind"] = "rotation";
  W.nodes[k2[0]]["pc"] = 0;
  r = one(P, cells_set(pcs, Vec3(5, 0, 0), W));
  const CertNodeFailure* f = failure_of(r, k2[0]);
  REQUIRE(f);
  CHECK_THAT(f->why, Catch::StartsWith("rotation: PC 0 (e-f:"));
}

TEST_CASE("cells: cone and local-slack leaves") {
  Pair P = make_pair();
  // A's vertex 0 (rays +x, +y, +z) on B's low top (normal +y), turned by 90 deg about x: the
  // ray +z points down (-y).
  TreeB T;
  const json rot = cube_rot(Vec3(kPiD / 2, 0, 0), 0.1);
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  const int cone = T.add(root, rot, "cone", {{"pc", 0}, {"direction", {0, 0, 1}}});
  const int cone_bad = T.add(root, rot, "cone", {{"pc", 0}, {"direction", {0, 1, 0}}});
  const int cone_odd = T.add(root, rot, "cone", {{"pc", 0}, {"direction", {0.6, 0.8, 0}}});
  const int slack = T.add(root, rot, "local-slack", {{"pc", 0}});
  // Turned so that (1,1,1)/sqrt(3) points up: every ray 0.577 up, far above the slack.
  const Vec3 ax = Vec3(-1, 0, 1).normalized() * std::acos(1 / std::sqrt(3.0));
  const int slack_bad = T.add(root, cube_rot(ax, 0.01), "local-slack", {{"pc", 0}});
  auto r = one(P, cells_set("v-f:0:4", Vec3(0, 0, 0), T));
  CHECK_FALSE(failure_of(r, cone));
  CHECK_FALSE(failure_of(r, slack));
  REQUIRE(failure_of(r, cone_bad));
  CHECK_THAT(failure_of(r, cone_bad)->why, Catch::StartsWith("cone: PC 0 (v-f:0:4): the "
                                                             "direction's height"));
  REQUIRE(failure_of(r, cone_odd));
  CHECK(failure_of(r, cone_odd)->why ==
        "cone: PC 0 (v-f:0:4): direction 0.6,0.8,0 is not a tangent direction of its element");
  REQUIRE(failure_of(r, slack_bad));
  CHECK_THAT(failure_of(r, slack_bad)->why, Catch::Contains("is not below local_slack"));
}

namespace {

// The verifier's e-e local margin at R (docs/certificates.md, "The local margin"), both edges
// taken as convex.
double ee_margin(const Mat3& R, const cert::EeNode& g) {
  const Vec3 N = (R * g.eA).cross(g.eB);
  const double s = N.norm();
  if (s < 1e-9) return -1;
  double best = -1e300;
  for (double sg : {1.0, -1.0}) {
    const Vec3 n = sg * N / s;
    best = std::max(best, std::min({-g.wB[0].dot(n), -g.wB[1].dot(n), (R * g.wA[0]).dot(n),
                                    (R * g.wA[1]).dot(n)}));
  }
  return std::min(s, best);
}

Mat3 rot_of(const Vec3& r) {
  const double th = r.norm();
  return th > 0 ? Mat3(Eigen::AngleAxisd(th, r / th)) : Mat3::Identity();
}

// An e-e of the test's models over the cube of axis-angle vectors (c, h), with the turn bound
// of a cube, min(sqrt(3) h, 2) per unit length.
cert::EeNode ee_node(const Graph& G, int ea, int eb, const Vec3& c, double h) {
  cert::EeNode g;
  g.M = rot_of(c);
  g.eA = G.A.E[ea].dir;
  g.eB = G.B.E[eb].dir;
  const double bu = std::min(std::sqrt(3.0) * h, 2.0);
  for (int i = 0; i < 2; ++i) {
    g.wA[i] = G.A.E[ea].m[i];
    g.wB[i] = G.B.E[eb].m[i];
    g.beta_w[i] = bu;
  }
  g.beta_e = bu;
  return g;
}

}  // namespace

TEST_CASE("cells: an e-e local-slack leaf where the edges turn parallel") {
  Pair P = make_pair();
  const double slack = 0.5 * std::sin(1e-3), h = 0.01;
  // A's edge 0-1 and B's edge 0-1 both run along x at the identity, each solid's wedge on the
  // +y +z side: the solids overlap along the edges at every rotation near the identity.
  const int a01 = P.G.A.edge_index(0, 1), b01 = P.G.B.edge_index(0, 1);
  // A's edge 6-7 (top back, along x) has its wedge on the -y -z side: a real contact.
  const int a67 = P.G.A.edge_index(6, 7);
  const std::string same = pcs_of("e-e", a01, b01), facing = pcs_of("e-e", a67, b01);
  const Vec3 off(0.004, -0.003, 0.002);  // the cube (off, h) holds the identity too
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  const int at_id = T.add(root, cube_rot(Vec3::Zero(), h), "local-slack", {{"pc", 0}});
  const int near_id = T.add(root, cube_rot(off, h), "local-slack", {{"pc", 0}});
  auto r = one(P, cells_set(same, Vec3(5, 5, 5), T));
  CHECK_FALSE(failure_of(r, at_id));
  CHECK_FALSE(failure_of(r, near_id));
  // Without the normal's range the checker's bound at s_c = 0 is s_c + beta(e_A) = sqrt(3) h
  // whatever the wedges (the normal's direction is not bounded there), above the slack: the
  // facing pair, whose range bound is large, reports exactly that.
  CHECK(std::sqrt(3.0) * h > slack);
  r = one(P, cells_set(facing, Vec3(5, 5, 5), T));
  REQUIRE(failure_of(r, at_id));
  CHECK_THAT(failure_of(r, at_id)->why,
             Catch::Contains("bound of the local margin over the node, 0.01732050807") &&
                 Catch::Contains("is not below local_slack"));
  // The bound, and the verifier's margin at rotations of the nodes (none is non-penetrating).
  for (const Vec3& c : {Vec3(Vec3::Zero()), off}) {
    const cert::EeNode g = ee_node(P.G, a01, b01, c, h);
    const double u = cert::ee_normal_bound(g);
    CHECK(u < -0.6);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(-1, 1);
    for (int k = 0; k < 200; ++k) {
      const Vec3 rr = c + h * Vec3(U(rng), U(rng), U(rng));
      CHECK(ee_margin(rot_of(rr), g) <= u + 1e-12);
    }
  }
  CHECK(cert::ee_normal_bound(ee_node(P.G, a67, b01, Vec3::Zero(), h)) > slack);
}

TEST_CASE("e-e bound by the normal's range: never below the verifier's margin in random cells") {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> U(-1, 1), U01(0, 1);
  auto unit = [&] {
    Vec3 v;
    do v = Vec3(U(rng), U(rng), U(rng));
    while (v.norm() < 0.1 || v.norm() > 1);
    return v.normalized();
  };
  auto perp = [&](const Vec3& e) {  // a random unit vector perpendicular to e
    Vec3 v;
    do {
      v = unit();
      v -= e * e.dot(v);
    } while (v.norm() < 0.1);
    return v.normalized();
  };
  int samples = 0, parallel = 0, tight = 0;
  double worst = -1e300;
  for (int cell = 0; cell < 400; ++cell) {
    const Vec3 c = kPiD * Vec3(U(rng), U(rng), U(rng));
    const double h = 1e-3 * std::pow(300.0, U01(rng));  // 1e-3 .. 0.3, log-uniform
    cert::EeNode g;
    g.M = rot_of(c);
    g.eA = unit();
    // Half of the cells: B's edge within about h of M e_A (a quarter: exactly M e_A), so that
    // the edges turn parallel in or near the cell.
    g.eB = cell % 2 ? Vec3((g.M * g.eA + 2 * h * U01(rng) * unit()).normalized()) : unit();
    if (cell % 4 == 3) g.eB = g.M * g.eA;
    for (int i = 0; i < 2; ++i) {
      g.wA[i] = perp(g.eA);
      g.wB[i] = perp(g.eB);
    }
    const double bu = std::min(std::sqrt(3.0) * h, 2.0);
    g.beta_e = g.beta_w[0] = g.beta_w[1] = bu;
    const double u = cert::ee_normal_bound(g);
    parallel += (g.M * g.eA).cross(g.eB).norm() <= bu;
    // The cube's 8 corners and 12 points inside it, then a climb from the highest of them
    // towards the cube's largest margin.
    double top = -1e300;
    Vec3 at = Vec3::Zero();
    auto sample = [&](const Vec3& d) {
      const double m = ee_margin(rot_of(c + h * d), g);
      if (m > top) top = m, at = d;
      worst = std::max(worst, m - u);
      ++samples;
      INFO("cell " << cell << " h " << h << " d " << d.transpose());
      REQUIRE(m <= u + 1e-12);
    };
    for (int k = 0; k < 20; ++k) {
      Vec3 d;
      for (int a = 0; a < 3; ++a) d[a] = k < 8 ? ((k >> a) & 1 ? 1.0 : -1.0) : U(rng);
      sample(d);
    }
    for (int k = 0; k < 40; ++k) {
      const double step = 0.5 * std::pow(0.85, k);
      sample((at + step * Vec3(U(rng), U(rng), U(rng))).cwiseMax(-1).cwiseMin(1));
    }
    tight += u - top < 2 * bu;  // the bound within 2 beta of the highest margin found
  }
  INFO("samples " << samples << ", cells with s_c <= beta " << parallel << ", tight " << tight
                  << ", largest margin - bound " << worst);
  CHECK(samples == 24000);
  CHECK(parallel > 50);
  CHECK(tight > 200);
}

namespace {

// A = the 10 mm cube, B = a 40 x 40 x 10 slab (box_model: face 1 is its top, z = 10).
Pair cube_on_slab() { return pair_of(cube_model(), box_model(40, 40, 10), 0.01); }

json fo_entry(const std::vector<int>& signs, const std::vector<double>& y) {
  return {{"signs", signs}, {"y", y}};
}

// The verifier's v-f local margin at R: the least of (R d) . n_B over A's vertex's rays, and 1.
double vf_margin(const Mat3& R, const Poly& A, int v, const Vec3& nB) {
  double m = 1;
  for (int e : A.V[v].edges) {
    const int o = A.E[e].v0 == v ? A.E[e].v1 : A.E[e].v0;
    m = std::min(m, (R * (A.V[o].p - A.V[v].p).normalized()).dot(nB));
  }
  return m;
}

const char* const kFarkasFails =
    "Farkas gap 0 <= 0 (min over the box of (sum y a).z does not exceed sum y b)";

}  // namespace

TEST_CASE("cells: first-order leaves: two corners' rays along one edge on a slab") {
  Pair P = cube_on_slab();
  const double slack = 0.5 * std::sin(1e-3), h = 0.01 / std::sqrt(3.0);
  // A's vertices 0 and 1 on B's top (n_B = +z). Their rays in ascending order of edge index:
  // vertex 0 +x, +y, +z (edges 0-1, 0-2, 0-4); vertex 1 -x, +y, +z (edges 0-1, 1-3, 1-5). At
  // R_c = I, "turned at least (d, z, s)" is the row -(d x z).v <= d.z + gamma - s: rows 0
  // (d = +x) v_y <= gamma - s and 3 (d = -x) -v_y <= gamma - s, whose sum 0 <= 2 (gamma - s)
  // fails while gamma = 1 - cos(sqrt(3) h) is below s. Rows 1 and 4 are -v_x <= gamma - s,
  // rows 2 and 5 (d = +z) 0 <= 1 + gamma - s.
  REQUIRE(1 - std::cos(0.01) < slack);
  const std::string pcs = "v-f:0:1;v-f:1:1";
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  auto leaf = [&](double half, const json& farkas) {
    return T.add(root, cube_rot(Vec3::Zero(), half), "first-order", {{"farkas", farkas}});
  };
  const std::vector<double> y = {1, 0, 0, 1, 0, 0};
  const int ok = leaf(h, json::array({fo_entry({}, y)}));
  const int zeros = leaf(h, json::array({fo_entry({}, {0, 0, 0, 0, 0, 0})}));
  const int one_row = leaf(h, json::array({fo_entry({}, {1, 0, 0, 0, 0, 0})}));
  const int rays_x = leaf(h, json::array({fo_entry({}, {0, 1, 0, 0, 1, 0})}));
  const int short_y = leaf(h, json::array({fo_entry({}, {1, 0, 0, 1, 0})}));
  const int negative = leaf(h, json::array({fo_entry({}, {1, 0, 0, 1, -1, 0})}));
  const int extra_entry = leaf(h, json::array({fo_entry({}, y), fo_entry({}, y)}));
  const int signs_for_none = leaf(h, json::array({fo_entry({1}, y)}));
  // gamma = 1 - cos(0.05) = 1.25e-3 is above s: the same rows no longer contradict.
  const int coarse = leaf(0.05 / std::sqrt(3.0), json::array({fo_entry({}, y)}));
  // theta_max = sqrt(3) 0.5 = 0.866 >= pi/4 = 0.785: no leaf may be written there.
  const int wide = leaf(0.5, json::array({fo_entry({}, y)}));
  // Just below pi/4 the first-order rows are weak (gamma = 0.29): refuted by the Farkas check.
  const int near_limit = leaf(0.45, json::array({fo_entry({}, y)}));
  auto r = one(P, cells_set(pcs, Vec3(5, 5, 0), T));
  CHECK_FALSE(failure_of(r, ok));
  CHECK(r.leaves.at("first-order")[0] == 1);
  auto why = [&](int id) {
    const CertNodeFailure* f = failure_of(r, id);
    return f ? f->why : std::string("(accepted)");
  };
  CHECK(why(zeros) == std::string("first-order: signs []: ") + kFarkasFails);
  // v_y >= -rho = -0.01 over the box, not above gamma - s = -4.5e-4.
  CHECK_THAT(why(one_row), Catch::StartsWith("first-order: signs []: Farkas gap -0.0095"));
  CHECK_THAT(why(rays_x), Catch::StartsWith("first-order: signs []: Farkas gap -0.019"));
  CHECK(why(short_y) == "first-order: signs []: y has 5 multipliers for 6 rows");
  CHECK(why(negative) == "first-order: signs []: multiplier 4 is -1 (must be >= 0)");
  CHECK(why(extra_entry) ==
        "first-order: farkas has 2 entries, the set's 0 e-e PCs make 1 choices of signs");
  CHECK(why(signs_for_none) ==
        "first-order: entry 0: signs [1], expected [] (one per e-e PC, the first counting "
        "fastest, +1 first)");
  CHECK_THAT(why(coarse), Catch::StartsWith("first-order: signs []: Farkas gap -0.00149"));
  CHECK_THAT(why(wide), Catch::StartsWith("first-order: theta_max = sqrt(3) h = 0.866025") &&
                            Catch::EndsWith(" is not below pi/4"));
  CHECK_THAT(why(near_limit), Catch::StartsWith("first-order: signs []: Farkas gap -"));
  CHECK(r.leaves.at("first-order")[1] == 10);

  // Only cube nodes: an arc of the f-f circle of A's bottom on B's top (R0 = I, axis n_A).
  const json circle = {{"pc", 0}, {"R0", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"axis", {0, 0, -1}}};
  TreeB C;
  C.add(-1, arc_rot(0, kPiD), "first-order", {{"farkas", json::array({fo_entry({}, {})})}});
  r = one(P, cells_set("f-f:0:1", Vec3(5, 5, 0), C, circle));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason ==
        "node 0: first-order: a first-order leaf needs a cube of rotations (domain \"ball\"), "
        "not an arc");
}

TEST_CASE("cells: first-order leaves with an e-e: one program per sign of its normal") {
  Pair P = cube_on_slab();
  const double slack = 0.5 * std::sin(1e-3), h = 0.01 / std::sqrt(3.0);
  const int ea = P.G.A.edge_index(0, 1), eb = P.G.B.edge_index(4, 6);
  // The into-face directions toward each edge's left face (its loop runs the edge from
  // edges[e][0] to edges[e][1]), then its right face. B's edge 4-6 (x = 0, z = 10, along +y):
  // left face 4 (x = 0), w_B1 = -z; right face 1 (top), w_B2 = +x. A's edge 0-1 (along +x):
  // left face 2 (front), w_A1 = +z; right face 0 (bottom), w_A2 = +y.
  REQUIRE(P.G.B.E[eb].face[0] == 4);
  REQUIRE(P.G.B.E[eb].face[1] == 1);
  REQUIRE(P.G.A.E[ea].face[0] == 2);
  REQUIRE(P.G.A.E[ea].face[1] == 0);
  CHECK((P.G.B.E[eb].m[0] - Vec3(0, 0, -1)).norm() < 1e-15);
  CHECK((P.G.A.E[ea].m[0] - Vec3(0, 0, 1)).norm() < 1e-15);
  const std::string ee = pcs_of("e-e", ea, eb);
  const std::string pcs = "v-f:1:1;" + ee;
  // Rows at R_c = I (b' = +y, m = e_A x b' = +z, c = 0, tau = s (1 - rho - gamma)): the v-f
  // (rays -x, +y, +z) 0: -v_y <= gamma - s, 1: -v_x <= gamma - s, 2: 0 <= 1 + gamma - s; the
  // e-e's B rows 3 (w = -z): 0 <= sigma + gamma - tau, 4 (w = +x): sigma v_y <= gamma - tau;
  // its A rows 5 (w = +z): 0 <= sigma + K - tau, 6 (w = +y): -sigma v_x <= K - tau. sigma = +1:
  // rows 0 and 4 add up to 0 <= 2 gamma - s - tau; sigma = -1: row 3 alone is 0 <= -1 + ...
  const std::vector<double> y_plus = {1, 0, 0, 0, 1, 0, 0}, y_minus = {0, 0, 0, 1, 0, 0, 0};
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  auto leaf = [&](const json& farkas) {
    return T.add(root, cube_rot(Vec3::Zero(), h), "first-order", {{"farkas", farkas}});
  };
  const int ok = leaf(json::array({fo_entry({1}, y_plus), fo_entry({-1}, y_minus)}));
  const int swapped = leaf(json::array({fo_entry({-1}, y_minus), fo_entry({1}, y_plus)}));
  const int too_long = leaf(json::array({fo_entry({1, 1}, y_plus), fo_entry({-1, 1}, y_minus)}));
  const int one_entry = leaf(json::array({fo_entry({1}, y_plus)}));
  const int zeros =
      leaf(json::array({fo_entry({1}, y_plus), fo_entry({-1}, std::vector<double>(7, 0))}));
  // With B's directions in the other order (right face first) the same sums would pair row 0
  // with the -z row: the checker's order is the left face's first.
  const int right_first =
      leaf(json::array({fo_entry({1}, {1, 0, 0, 1, 0, 0, 0}), fo_entry({-1}, y_minus)}));
  auto r = one(P, cells_set(pcs, Vec3(5, 5, 0), T));
  auto why = [&](int id) {
    const CertNodeFailure* f = failure_of(r, id);
    return f ? f->why : std::string("(accepted)");
  };
  CHECK(why(ok) == "(accepted)");
  const std::string order =
      "(one per e-e PC [PC 1 (" + ee + ")], the first counting fastest, +1 first)";
  CHECK(why(swapped) == "first-order: entry 0: signs [-1], expected [1] " + order);
  CHECK(why(too_long) == "first-order: entry 0: signs [1,1], expected [1] " + order);
  CHECK(why(one_entry) ==
        "first-order: farkas has 1 entries, the set's 1 e-e PCs make 2 choices of signs");
  CHECK(why(zeros) == std::string("first-order: signs [-1]: ") + kFarkasFails);
  CHECK_THAT(why(right_first), Catch::StartsWith("first-order: signs [1]: Farkas gap -"));

  // The claim itself: at no rotation of the node do both PCs keep the slack (the e-e's
  // normal may point either way; its margin takes the better one).
  const cert::EeNode g = ee_node(P.G, ea, eb, Vec3::Zero(), h);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  double best = -1;
  for (int k = 0; k < 2000; ++k) {
    const Mat3 R = rot_of(h * Vec3(U(rng), U(rng), U(rng)));
    best = std::max(best, std::min(vf_margin(R, P.G.A, 1, Vec3(0, 0, 1)), ee_margin(R, g)));
  }
  CHECK(best < slack);
}

TEST_CASE("cells: deep leaves") {
  Pair P = make_pair();
  // A's vertex 0, pivot A's centre: at the identity with t_c = (25, 10, 20) its image
  // (20, 5, 15) is 5 mm inside B's lower bar.
  TreeB T;
  const int root = T.add(-1, cube_rot(Vec3::Zero(), kPiD), "narrow");
  const json rot = cube_rot(Vec3::Zero(), 0.01);
  const Vec3 lo(24.9, 9.9, 19.9), hi(25.1, 10.1, 20.1);
  const json deep = {{"of", "A"}, {"point", {0, 0, 0}}};
  const int ok = T.add(root, rot, "deep", deep, &lo, &hi);
  const Vec3 lo2(24.9, 24.9, 19.9), hi2(25.1, 25.1, 20.1);  // image (20, 20, 15): above B
  const int out = T.add(root, rot, "deep", deep, &lo2, &hi2);
  const int centre = T.add(root, rot, "deep", {{"of", "A"}, {"point", {5, 5, 5}}}, &lo, &hi);
  // B's vertex 0 (the origin), t_c = 0: its preimage is A's centre, 5 mm deep.
  const Vec3 lo3(-0.1, -0.1, -0.1), hi3(0.1, 0.1, 0.1);
  const int okb = T.add(root, rot, "deep", {{"of", "B"}, {"point", {0, 0, 0}}}, &lo3, &hi3);
  auto r = one(P, cells_set("v-f:7:6", Vec3(5, 5, 5), T));
  CHECK_FALSE(failure_of(r, ok));
  CHECK_FALSE(failure_of(r, okb));
  REQUIRE(failure_of(r, out));
  CHECK_THAT(failure_of(r, out)->why, Catch::StartsWith("deep: the point's image is"));
  REQUIRE(failure_of(r, centre));
  CHECK(failure_of(r, centre)->why == "deep: the point is 5 mm from A's boundary");
  // A tree's deep_extra_mm: 5 mm deep is not deeper than 6 mm more than the node's reach.
  json deeper = cells_set("v-f:7:6", Vec3(5, 5, 5), T);
  deeper["cells"]["tolerances"] = {{"deep_extra_mm", 6.0}};
  r = one(P, deeper);
  REQUIRE(failure_of(r, ok));
  CHECK_THAT(failure_of(r, ok)->why, Catch::StartsWith("deep: the point's image is"));
  deeper["cells"]["tolerances"] = {{"deep_extra_mm", 1.0}};
  CHECK_FALSE(failure_of(one(P, deeper), ok));
}

TEST_CASE("tolerances: rot_tol_rad, 1e-8 when absent, never below it, half off_circle_rad") {
  Pair P = make_pair();
  json c = cert_for(P, json::array());
  CHECK(run(P, c).passed());  // an older file, without rot_tol_rad
  c["tolerances"]["rot_tol_rad"] = 1e-8;
  CHECK(run(P, c).passed());
  c["tolerances"]["rot_tol_rad"] = 1e-9;
  CertificateReport rep = run(P, c);
  REQUIRE(rep.file_problems.size() == 1);
  CHECK(rep.file_problems[0] == "tolerances.rot_tol_rad 1e-09 is below the verifier's 1e-08");
  c["tolerances"]["rot_tol_rad"] = 2e-8;
  rep = run(P, c);
  REQUIRE(rep.file_problems.size() == 1);
  CHECK(rep.file_problems[0] ==
        "tolerances.off_circle_rad 2e-08 is less than twice rot_tol_rad 2e-08");
}

namespace {

// The f-f circle set whose e-f edge stays vertical: one rotation leaf refutes the whole circle
// (as in "cells: a rotation leaf over the whole f-f circle"); edge (0, 4) by default.
json vertical_edge_set(const Pair& P, int v0 = 0, int v1 = 4, const json& tolerances = json()) {
  TreeB T;
  T.add(-1, arc_rot(0, kPiD), "rotation", {{"pc", 1}});
  json s = cells_set(pcs_of("f-f", 0, 4, "e-f", P.G.A.edge_index(v0, v1), 6), Vec3(5, 5, 5), T,
                     circle_ff(0));
  if (!tolerances.is_null()) s["cells"]["tolerances"] = tolerances;
  return s;
}

}  // namespace

TEST_CASE("cells: a tree's own tolerances, at least as loose as the file's") {
  Pair P = make_pair();
  CHECK(one(P, vertical_edge_set(P, 0, 4, json::object())).outcome == CertOutcome::Accepted);
  // Tighter than the file's, each way: refused before the tree is looked at.
  auto r = one(P, vertical_edge_set(P, 0, 4, {{"touch_tol_mm", 1e-10}}));
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK(r.reason ==
        "tree: cells.tolerances.touch_tol_mm 1e-10 is tighter than the file's 1e-09 (it must be "
        "no smaller)");
  r = one(P, vertical_edge_set(P, 0, 4, {{"min_margin_mm", 0.02}}));
  CHECK(r.reason ==
        "tree: cells.tolerances.min_margin_mm 0.02 is tighter than the file's 0.01 (it must be "
        "no larger)");
  r = one(P, vertical_edge_set(P, 0, 4, {{"local_slack", 0.1}}));
  CHECK_THAT(r.reason, Catch::StartsWith("tree: cells.tolerances.local_slack 0.1 is tighter"));
  r = one(P, vertical_edge_set(P, 0, 4, {{"rot_tol_rad", 5e-9}}));
  CHECK_THAT(r.reason, Catch::StartsWith("tree: cells.tolerances.rot_tol_rad 5e-09 is tighter"));
  r = one(P, vertical_edge_set(P, 0, 4, {{"off_circle_rad", 1e-8}}));
  CHECK_THAT(r.reason, Catch::StartsWith("tree: cells.tolerances.off_circle_rad 1e-08 is tighter"));
  r = one(P, vertical_edge_set(P, 0, 4, {{"deep_extra_mm", -1}}));
  CHECK(r.reason == "tree: cells.tolerances.deep_extra_mm -1 is negative");
  r = one(P, vertical_edge_set(P, 0, 4, {{"rot_tol_rad", 0.1}, {"off_circle_rad", 0.15}}));
  CHECK(r.reason ==
        "tree: cells.tolerances: off_circle_rad 0.15 is less than twice rot_tol_rad 0.1");
  r = one(P, vertical_edge_set(P, 0, 4, {{"rounding_mm", 1}}));
  CHECK(r.reason == "tree: cells.tolerances.rounding_mm is not a tree tolerance");
  // The leaves use the tree's values: the edge's condition, 1 on the whole circle, exceeds
  // off_circle 0.2 + rot_tol 0.1 but not 1.2 + 0.6.
  CHECK(
      one(P, vertical_edge_set(P, 0, 4, {{"rot_tol_rad", 0.1}, {"off_circle_rad", 0.2}})).outcome ==
      CertOutcome::Accepted);
  r = one(P, vertical_edge_set(P, 0, 4, {{"rot_tol_rad", 0.6}, {"off_circle_rad", 1.2}}));
  CHECK_THAT(r.reason, Catch::Contains("(turn bound + rot_tol_rad 0.6)"));
  // The file's rot_tol_rad too.
  json c = cert_for(P, json::array({vertical_edge_set(P)}));
  c["tolerances"]["rot_tol_rad"] = 0.6;
  c["tolerances"]["off_circle_rad"] = 1.2;
  CHECK(run(P, c).rejected == 1);
}

TEST_CASE("cells: a tree's min_margin_mm replaces the file's in its programs") {
  // As in "cells: a program leaf with hand-derived Farkas multipliers": a 6 mm margin leaves no
  // contact point on the 10 mm wide face; the tree's 4 mm does, and the same y fails.
  Pair P = make_pair(6.0);
  const json pieces = {{"B", {tower_top_one_piece()}}};
  TreeB T;
  T.lo = Vec3(-1, 19, -1);
  T.hi = Vec3(11, 21, 31);
  T.add(-1, cube_rot(Vec3::Zero(), kPiD), "program",
        {{"farkas", {{{"choice", {0}}, {"y", {0, 0, 1, 0, 1, 0}}}}}});
  json s = cells_set("v-f:7:6", Vec3(10, 10, 10), T);
  CHECK(one(P, s, pieces).outcome == CertOutcome::Accepted);
  s["cells"]["tolerances"] = {{"min_margin_mm", 4.0}};
  auto r = one(P, s, pieces);
  CHECK(r.outcome == CertOutcome::Rejected);
  CHECK_THAT(r.reason, Catch::Contains("Farkas gap -2"));
}

namespace {

json map_json(const Mat3& R, const Vec3& c) {
  json r = json::array();
  for (int i = 0; i < 9; ++i) r.push_back(R(i / 3, i % 3));
  return {{"R", r}, {"c", v3(c)}};
}

json image_set(const std::string& pcs, const std::string& of, const Mat3& H, const Vec3& cA,
               const Mat3& G = Mat3::Identity(), const Vec3& cB = Vec3::Zero()) {
  return {{"pcs", pcs},
          {"outcome", "invalid"},
          {"image_of", {{"pcs", of}, {"A", map_json(H, cA)}, {"B", map_json(G, cB)}}}};
}

// A turn about z by theta (the cube's quarter turn about its centre maps (x, y) to (10 - y, x)).
Mat3 turn_z(double theta) {
  Mat3 R;
  R << std::cos(theta), -std::sin(theta), 0, std::sin(theta), std::cos(theta), 0, 0, 0, 1;
  return R;
}

Mat3 quarter_z() {
  Mat3 R;
  R << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // exactly
  return R;
}

const CertSetResult& result_of(const CertificateReport& rep, const std::string& pcs) {
  for (const auto& s : rep.sets)
    if (s.pcs == pcs) return s;
  throw std::runtime_error("no set " + pcs);
}

}  // namespace

TEST_CASE("images: an exact symmetry's image of an accepted set is accepted, in either order") {
  Pair P = make_pair();
  const Vec3 cA(5, 5, 5);
  const std::string D = pcs_of("f-f", 0, 4, "e-f", P.G.A.edge_index(0, 4), 6);
  // The quarter turn takes vertex 0 to 1 and 4 to 5: the vertical edge (0, 4) to (1, 5).
  const std::string E = pcs_of("f-f", 0, 4, "e-f", P.G.A.edge_index(1, 5), 6);
  for (bool image_first : {true, false}) {
    json sets = json::array({vertical_edge_set(P)});
    sets.insert(image_first ? sets.begin() : sets.end(), image_set(E, D, quarter_z(), cA));
    const CertificateReport rep = run(P, cert_for(P, sets));
    for (const auto& l : rep.rejection_lines()) INFO(l);
    CHECK(rep.passed());
    CHECK(rep.accepted == 2);
    CHECK(result_of(rep, E).kind == "image");
    CHECK(rep.by_kind.at("image")[static_cast<int>(CertOutcome::Accepted)] == 1);
    CHECK_THAT(rep.summary_line(), Catch::Contains(" image 1/0/0"));
  }
  // A reflection of each model: A's bottom face to its top, B onto itself by z -> 30 - z.
  const Mat3 M = Vec3(1, 1, -1).asDiagonal();
  const std::string F = pcs_of("f-f", 1, 4, "e-f", P.G.A.edge_index(0, 4), 6);
  CertificateReport rep = run(
      P,
      cert_for(P, json::array({vertical_edge_set(P), image_set(F, D, M, cA, M, Vec3(0, 0, 15))})));
  for (const auto& l : rep.rejection_lines()) INFO(l);
  CHECK(rep.accepted == 2);
  // One reflection and one rotation: g X h^-1 would not be a rotation.
  rep = run(P, cert_for(P, json::array({vertical_edge_set(P),
                                        image_set(F, D, M, cA, Mat3::Identity(), Vec3::Zero())})));
  CHECK(result_of(rep, F).reason ==
        "A.R and B.R are not both rotations or both reflections (det signs -1, 1)");
  // The summary's image count, when the file gives one.
  json c = cert_for(P, json::array({vertical_edge_set(P), image_set(E, D, quarter_z(), cA)}));
  c["summary"]["invalid_as_image"] = 1;
  CHECK(run(P, c).passed());
  c["summary"]["invalid_as_image"] = 2;
  rep = run(P, c);
  REQUIRE(rep.file_problems.size() == 1);
  CHECK(rep.file_problems[0] == "summary.invalid_as_image is not 1");
}

TEST_CASE("images: maps that are not symmetries, wrong images and decided sets are rejected") {
  Pair P = make_pair();
  const Vec3 cA(5, 5, 5);
  const int e04 = P.G.A.edge_index(0, 4), e15 = P.G.A.edge_index(1, 5),
            e37 = P.G.A.edge_index(3, 7);
  const std::string D = pcs_of("f-f", 0, 4, "e-f", e04, 6);
  const std::string E = pcs_of("f-f", 0, 4, "e-f", e15, 6);
  auto check = [&](json sets, const std::string& pcs) {
    const CertificateReport rep = run(P, cert_for(P, sets));
    const CertSetResult& r = result_of(rep, pcs);
    INFO(pcs << ": " << r.reason);
    CHECK(r.outcome == CertOutcome::Rejected);
    return r.reason;
  };
  // An eighth turn takes no vertex of the cube near a vertex.
  CHECK_THAT(check({vertical_edge_set(P), image_set(E, D, turn_z(kPiD / 4), cA)}, E),
             Catch::StartsWith("not a symmetry: A"));
  // The quarter turn about another centre moves the cube off itself.
  CHECK_THAT(check({vertical_edge_set(P), image_set(E, D, quarter_z(), Vec3(5, 6, 5))}, E),
             Catch::Contains("mm from its nearest vertex, more than"));
  // A matrix that is not orthogonal.
  CHECK_THAT(check({vertical_edge_set(P), image_set(E, D, 1.001 * quarter_z(), cA)}, E),
             Catch::StartsWith("not a symmetry: A.R is not orthogonal (|R^T R - I| = 0.003465"));
  // A set that is not the image: the quarter turn takes (0, 4) to (1, 5), not (3, 7).
  const std::string W = pcs_of("f-f", 0, 4, "e-f", e37, 6);
  CHECK(check({vertical_edge_set(P), image_set(W, D, quarter_z(), cA)}, W) ==
        "the set is not the image of {" + D + "}: the maps take it to {" + E + "}");
  // The decided set missing, rejected, invalid by a rule or itself an image.
  CHECK(check({image_set(E, D, quarter_z(), cA)}, E) ==
        "the decided set {" + D + "} is not listed in the file");
  json bad = vertical_edge_set(P);
  bad["cells"]["tolerances"] = {{"touch_tol_mm", 1e-10}};
  CHECK(check({bad, image_set(E, D, quarter_z(), cA)}, E) ==
        "the decided set {" + D + "} (set 0) is not accepted");
  CHECK(check({rule_set(D, "heights-over-ff", {0, 1}), image_set(E, D, quarter_z(), cA)}, E) ==
        "the decided set {" + D + "} (set 0) is not invalid by cells (heights-over-ff)");
  CHECK(check({vertical_edge_set(P), image_set(E, D, quarter_z(), cA),
               image_set(W, E, quarter_z(), cA)},
              W) == "the decided set {" + E +
                        "} (set 1) is itself an image: an image of an "
                        "image is refused");
}

TEST_CASE("images: the decided tree must be looser by what the maps miss") {
  Pair P = make_pair();
  const Vec3 cA(5, 5, 5);
  const std::string D = pcs_of("f-f", 0, 4, "e-f", P.G.A.edge_index(0, 4), 6);
  const std::string E = pcs_of("f-f", 0, 4, "e-f", P.G.A.edge_index(1, 5), 6);
  // A quarter turn off by 1e-10 rad: the cube's corners miss by 5 sqrt(2) 1e-10 = 7.07e-10 mm
  // and its side faces' normals and edges turn by 1e-10 rad. The file's off_circle_rad is 3e-8
  // here, so that twice rot_tol_rad does not imply its loosening.
  const json img = image_set(E, D, turn_z(kPiD / 2 + 1e-10), cA);
  const double slack = 0.5 * std::sin(1e-3);
  const json loose = {{"touch_tol_mm", 1.8e-9},      {"min_margin_mm", 0.0099},
                      {"rot_tol_rad", 1.02e-8},      {"off_circle_rad", 3.03e-8},
                      {"local_slack", slack - 1e-6}, {"deep_extra_mm", 8e-10}};
  auto verdict = [&](const json& tolerances) {
    json c = cert_for(P, json::array({vertical_edge_set(P, 0, 4, tolerances), img}));
    c["tolerances"]["off_circle_rad"] = 3e-8;
    const CertificateReport rep = run(P, c);
    CHECK(result_of(rep, D).outcome == CertOutcome::Accepted);
    return result_of(rep, E);
  };
  CHECK(verdict(loose).outcome == CertOutcome::Accepted);
  // Without loosening, or too little on any one tolerance.
  CHECK_THAT(verdict(json()).reason, Catch::StartsWith("the decided set {" + D +
                                                       "} (set 0)'s tree has touch_tol_mm 1e-09, "
                                                       "not >= 1.707"));
  const std::vector<std::pair<std::string, double>> tight = {
      {"touch_tol_mm", 1.7e-9},    {"min_margin_mm", 0.01 - 7e-10}, {"rot_tol_rad", 1.0099e-8},
      {"off_circle_rad", 3.01e-8}, {"local_slack", slack - 3e-7},   {"deep_extra_mm", 7e-10}};
  for (const auto& [key, value] : tight) {
    json t = loose;
    t[key] = value;
    const CertSetResult r = verdict(t);
    INFO(key << ": " << r.reason);
    CHECK(r.outcome == CertOutcome::Rejected);
    CHECK_THAT(r.reason, Catch::Contains("'s tree has " + key + " "));
  }
  // The spec's "(or 0)": no margin at all is loose enough.
  json t = loose;
  t["min_margin_mm"] = 0;
  CHECK(verdict(t).outcome == CertOutcome::Accepted);
  // With a file margin below eps, 0 leaves contact points up to eps - margin outside their
  // elements: the checker then asks for touch_tol_mm + 2 eps.
  Pair Q = make_pair(1e-10);
  json c = cert_for(Q, json::array({vertical_edge_set(Q, 0, 4, t), img}));
  c["tolerances"]["off_circle_rad"] = 3e-8;
  CHECK_THAT(result_of(run(Q, c), E).reason,
             Catch::Contains("'s tree has touch_tol_mm 1.8e-09, not >= 2.414"));
  t["touch_tol_mm"] = 2.5e-9;
  c = cert_for(Q, json::array({vertical_edge_set(Q, 0, 4, t), img}));
  c["tolerances"]["off_circle_rad"] = 3e-8;
  CHECK(run(Q, c).passed());
}

#ifdef CF_ORACLE_CERTCHECK
TEST_CASE("oracle_certcheck: summary, rejections and exit codes") {
  Pair P = make_pair();
  const std::string g = temp_path("cli_g.json"), c = temp_path("cli_c.json"),
                    o = temp_path("cli_out.txt");
  std::ofstream(g) << P.doc.dump();
  auto run_cli = [&](const json& cert, std::string* out) {
    std::ofstream(c) << cert.dump();
    const std::string cmd =
        std::string(CF_ORACLE_CERTCHECK) + " " + g + " " + c + " > " + o + " 2>&1";
    const int st = std::system(cmd.c_str());
    std::ifstream in(o);
    std::stringstream ss;
    ss << in.rdbuf();
    *out = ss.str();
    return WEXITSTATUS(st);
  };
  std::string out;
  CHECK(
      run_cli(cert_for(P, json::array({rule_set("v-f:0:4;v-f:0:6", "vertex-in-two-pcs", {0, 1})})),
              &out) == 0);
  CHECK_THAT(out, Catch::StartsWith("sets 1, accepted 1, rejected 0, not certified 0, "
                                    "undecided 0 | by kind"));
  CHECK(
      run_cli(cert_for(P, json::array({rule_set("v-f:0:4;v-f:1:6", "vertex-in-two-pcs", {0, 1})})),
              &out) == 1);
  CHECK_THAT(out, Catch::Contains("REJECTED set 0 {v-f:0:4;v-f:1:6} vertex-in-two-pcs: PCs "
                                  "v-f:0:4 and v-f:1:6 share no vertex"));
  std::ofstream(c) << "[1, 2";
  const int st = std::system(
      (std::string(CF_ORACLE_CERTCHECK) + " " + g + " " + c + " > " + o + " 2>&1").c_str());
  CHECK(WEXITSTATUS(st) == 2);
  std::ifstream in(o);
  std::string line;
  std::getline(in, line);
  CHECK_THAT(line, Catch::StartsWith("oracle_certcheck: certificate file " + c + ": not JSON"));
  for (const auto& p : {g, c, o}) std::filesystem::remove(p);
}
#endif

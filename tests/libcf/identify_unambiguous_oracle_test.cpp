// Identification at unambiguous poses: 100% (issue 42, item 2).
//
// The independent oracle (tests/oracle) samples poses by exact first contacts and compliant
// walks on each model pair (oracle::Sampler with fixed seeds and round counts: deterministic)
// and classifies every pose it reaches with its own geometry. A pose counts when the oracle
// accepts it (a valid CF: interiors disjoint, 1-3 non-degenerate PCs on distinct planes,
// nothing near-degenerate), when it is unambiguous (oracle::check_unambiguous) and when the
// graph holds its CF (the graph as the oracle reads it). At every such pose the run time, from
// a cold start (a fresh CfState: no previous CF), must
//  - identify exactly that CF (a miss is printed with the pose, the oracle's CF, the run
//    time's, and every contact it detected: distance, misfit, fit, plane, dominated), and
//  - detect nothing but readings of the CF's touches (its PCs and pairs they dominate): every
//    other pair is farther apart than the band, so a contact there ("stray") is one the
//    CF must account for although nothing touches; a vertex beside a face, below its plane
//    and more than epsilon from it, read as sunk into it is how a wrong CF won (docs/runtime.md,
//    "Tests per type").
//
// Unambiguous (tests/oracle/unambiguous.hpp): every e-e PC crosses at an angle beyond its
// near-parallel tolerance plus the angular margin, and every element pair of a PC type that no
// PC of the CF dominates is farther apart than epsilon plus the distance margin, or is an e-f,
// f-e or f-f pair tilted beyond its angular tolerance (docs/runtime.md's atan(eps / L),
// clamped) plus the angular margin. The margins are kDistMargin and kAngMargin below.
//
// The pairs: the bundled cube / L-block, cube / corner block and peg / hole graphs
// (data/graphs), the recall test's eight oracle pairs (fixture oracle_samples, kept in
// CF_ORACLE_KEEP_DIR) and three pairs of the oracle's extra families, a pyramid, a wedge and an
// n-gon prism against a ramp step with a V-groove (fixture oracle_extra_graphs, kept in
// CF_ORACLE_EXTRA_DIR). The oracle decides everything (poses, CFs, unambiguity, the graph's
// CFs, which contacts are readings of the CF); libcf is only the code under test (cf::detect
// and cf::identify on a CfModel with default parameters).
//
// Environment, for exploring (the defaults are the test): CF_UNAMBIGUOUS_ROUNDS (sampler
// rounds per pair), CF_UNAMBIGUOUS_EPS and CF_UNAMBIGUOUS_DEPTH (epsilon_mm and
// deepest_contact_mm; the property needs deepest_contact_mm <= epsilon_mm, see
// docs/runtime.md), CF_UNAMBIGUOUS_DIST_MARGIN (mm) and CF_UNAMBIGUOUS_ANG_MARGIN (share),
// CF_ORACLE_KEEP_DIR and CF_ORACLE_EXTRA_DIR (where the pairs are).

#include <cf/graph.hpp>
#include <cf/model.hpp>
#include <cf/params.hpp>
#include <cf/servo.hpp>
#include <cf/state.hpp>

#include "classify.hpp"
#include "graph.hpp"
#include "oracle_kept.hpp"
#include "oracle_pose.hpp"
#include "sampler.hpp"
#include "unambiguous.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// The floor: at least this many unambiguous poses whose CF is in the graph, over all
// pairs together.
constexpr long kMinPoses = 10000;
constexpr std::size_t kMaxPrinted = 10;  // stray contacts printed per pair (every miss is)

// The margins of "unambiguous" (tests/oracle/unambiguous.hpp).
// Distance: 5% of epsilon (0.05 mm at the default 1 mm). The oracle's distances are exact to
// rounding (~1e-12 mm) and the run time's are the same Euclidean heights, gaps and segment
// distances, so any margin above rounding would do for a pair the run time reads along the
// same line; 5% also covers the one it reads differently (a contact's distance along the
// contact normal against the elements' distance) up to a twentieth of the band, and still
// keeps in the sample the many poses whose next contact is a fraction of a millimetre beyond
// the band (a larger margin drops them and adds nothing).
constexpr double kDistMargin = 0.05;  // share of epsilon
// Angle: 10% of the pair's angular tolerance. The tolerance depends on the extent L of the
// contact region, which the oracle computes with its own clipping; the two can differ where a
// clipped end falls on a face's boundary (the run time's boundary slack, 1e-9 of the model
// size), far below 10%. A pair within 10% of its tolerance is in the hysteresis band of
// docs/runtime.md (dominance_fit), where both readings stand by design.
constexpr double kAngMargin = 0.1;  // share of the angular tolerance

// A fixed seed per pair from its name (FNV-1a: the same on every platform).
std::uint64_t seed_of(const std::string& name, std::uint64_t base) {
  std::uint64_t h = 1469598103934665603ull;
  for (const char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return base + h % 1000;
}

struct PairSpec {
  std::string name;
  fs::path graph;
  std::uint64_t seed = 1;  // the sampler's
  long rounds = 0;
};

struct Hit {
  oracle::Pose X;
  oracle::CfKey key;
  std::string how;
};

struct PairResult {
  std::string name;
  long accepted = 0, unambiguous = 0, in_graph = 0, exact = 0;
  std::set<oracle::CfKey> cfs;  // distinct CFs among the counted poses
  std::map<std::string, long> reasons;
  std::vector<std::string> misses;
  long stray = 0;  // poses where a contact other than a reading of the CF's PCs was detected
  std::vector<std::string> strays;
  double seconds = 0;
};

std::string fmt(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string pose_text(const oracle::Pose& X) {
  std::string s;
  for (int i = 0; i < 9; ++i) s += (i ? "," : "") + fmt(X.R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) s += "," + fmt(X.t(i));
  return s;
}

std::string describe(const PairSpec& spec, const Hit& h, const cf::Identification& id) {
  std::ostringstream o;
  o << spec.name << ": oracle {" << oracle::key_string(h.key) << "}, libcf "
    << (id.has_cf() ? "{" + cf::to_string(id.pcs) + "}" : std::string("none")) << " ("
    << cf::to_string(id.status) << ", " << id.contacts.size() << " contacts, "
    << id.contacts.num_planes() << " planes) via " << h.how << "\n    pose R,t = " << pose_text(h.X)
    << "\n";
  for (const cf::ContactPc& c : id.contacts) {
    char b[200];
    std::snprintf(b, sizeof b, "    %-10s d=%+.6f misfit=%.6f fit=%.3f plane=%d%s\n",
                  cf::to_string(c.pc).c_str(), c.distance, c.misfit, c.fit,
                  static_cast<int>(c.plane), c.dominated ? " dominated" : "");
    o << b;
  }
  return o.str();
}

// Whether the run time's contact `pc` is one of the CF's PCs or a pair one of them dominates
// (its elements in the closures of the PC's): another reading of the same touch.
bool reading_of(const oracle::Poly& A, const oracle::Poly& B, const oracle::CfKey& cf,
                const cf::Pc& pc) {
  oracle::PcType type;
  if (!oracle::parse_type(cf::to_string(pc.type), &type)) return false;
  for (const oracle::Pc& q : cf)
    if (A.in_closure(oracle::kind_a(type), pc.a, oracle::kind_a(q.type), q.a) &&
        B.in_closure(oracle::kind_b(type), pc.b, oracle::kind_b(q.type), q.b))
      return true;
  return false;
}

PairResult run_pair(const PairSpec& spec) {
  const auto t0 = std::chrono::steady_clock::now();
  PairResult r;
  r.name = spec.name;
  // The oracle's reading of the graph: its models and its CFs' PC sets.
  const oracle::Graph G = oracle::read_graph(spec.graph.string());
  std::set<oracle::CfKey> in_graph;
  for (const oracle::GraphCf& c : G.cfs) in_graph.insert(c.key);
  const oracle::Classifier C(G.A, G.B, oracle::default_tolerances(G.A, G.B));
  // The code under test.
  const cf::CfGraph graph = cf::CfGraph::load(spec.graph.string());
  cf::Params params;  // the defaults; CF_UNAMBIGUOUS_EPS, _DEPTH (mm) try another band
  if (const char* e = std::getenv("CF_UNAMBIGUOUS_EPS")) params.epsilon_mm = std::atof(e);
  if (const char* e = std::getenv("CF_UNAMBIGUOUS_DEPTH"))
    params.detection.deepest_contact_mm = std::atof(e);
  const cf::CfModel model(graph, params);
  oracle::BandParams band;
  band.eps = model.params().epsilon_mm;
  band.min_tol = model.params().detection.min_angular_tolerance_rad;
  band.max_tol = model.params().detection.max_angular_tolerance_rad;
  band.dist_margin = kDistMargin * band.eps;
  band.ang_margin = kAngMargin;
  if (const char* e = std::getenv("CF_UNAMBIGUOUS_DIST_MARGIN")) band.dist_margin = std::atof(e);
  if (const char* e = std::getenv("CF_UNAMBIGUOUS_ANG_MARGIN")) band.ang_margin = std::atof(e);

  std::vector<Hit> hits;
  oracle::SamplerOptions so;
  so.seed = spec.seed;
  so.max_rounds = spec.rounds;
  so.budget_s = 1e9;  // the rounds decide: deterministic
  so.on_accept = [&](const oracle::Pose& X, const oracle::Verdict& V, const std::string& how) {
    ++r.accepted;
    const oracle::CfKey key = V.key();
    const oracle::Ambiguity a = oracle::check_unambiguous(G.A, G.B, X, key, band);
    if (!a.unambiguous) {
      // "e-f:3:4 within the band at angle ..." -> "e-f within the band at angle"
      std::string kind = a.why.substr(0, 3);
      const std::size_t sp = a.why.find(' ');
      std::string what = sp == std::string::npos ? "" : a.why.substr(sp);
      const std::size_t num = what.find_first_of("0123456789-");
      if (num != std::string::npos) what = what.substr(0, num);
      ++r.reasons[kind + what];
      return;
    }
    ++r.unambiguous;
    if (!in_graph.count(key)) return;
    hits.push_back(Hit{X, key, how});
  };
  oracle::Sampler S(C, so);
  S.run();

  for (const Hit& h : hits) {
    ++r.in_graph;
    r.cfs.insert(h.key);
    cf::CfState state(model);  // a cold start: no previous CF
    const cf::Identification& id =
        cf::identify(model, state, cf::detect(model, state, cf::test::to_cf(h.X)));
    if (id.has_cf() && cf::test::to_oracle(id.pcs) == h.key)
      ++r.exact;
    else
      r.misses.push_back("  MISS " + describe(spec, h, id));
    // Nothing but readings of the CF's touches may be detected (the header).
    for (const cf::ContactPc& c : id.contacts)
      if (!reading_of(G.A, G.B, h.key, c.pc)) {
        ++r.stray;
        if (r.strays.size() < kMaxPrinted)
          r.strays.push_back("  STRAY " + cf::to_string(c.pc) + " at " + fmt(c.distance) +
                             " mm: " + describe(spec, h, id));
        break;
      }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

long rounds_override() {
  const char* e = std::getenv("CF_UNAMBIGUOUS_ROUNDS");
  return e != nullptr ? std::atol(e) : 0;
}

}  // namespace

TEST_CASE("identification from a cold start at every unambiguous pose the oracle samples",
          "[identify][oracle]") {
  const long over = rounds_override();
  std::vector<PairSpec> specs;
  const fs::path data = fs::path(CF_SOURCE_DIR) / "data" / "graphs";
  specs.push_back({"cube/L-block", data / "cube_l_block.json", 101, 4000});
  specs.push_back({"cube/corner block", data / "cube_corner_block.json", 102, 4000});
  specs.push_back({"peg/hole", data / "peg_hole_block.json", 103, 4000});
  const fs::path kept = cf::test::kept_oracle_dir(CF_ORACLE_KEEP_DIR);
  const std::vector<fs::path> seeds = cf::test::kept_oracle_pairs(kept);
  INFO("no oracle pairs in " << kept.string()
                             << ": run the recall test first (ctest runs it as a fixture)");
  REQUIRE(!seeds.empty());
  for (const fs::path& d : seeds)
    specs.push_back({"oracle " + d.filename().string(), d / "G.json",
                     seed_of(d.filename().string(), 200), 3000});
  const char* extra_env = std::getenv("CF_ORACLE_EXTRA_DIR");
  const fs::path extra = extra_env != nullptr ? fs::path(extra_env) : fs::path(CF_ORACLE_EXTRA_DIR);
  std::vector<fs::path> extras;
  if (fs::is_directory(extra))
    for (const auto& e : fs::directory_iterator(extra))
      if (fs::exists(e.path() / "G.json")) extras.push_back(e.path());
  std::sort(extras.begin(), extras.end());
  INFO("no extra pairs in " << extra.string()
                            << ": run identify_extra_graphs first (ctest runs it as a fixture)");
  REQUIRE(!extras.empty());
  for (const fs::path& d : extras)
    specs.push_back({"oracle " + d.filename().string(), d / "G.json",
                     seed_of(d.filename().string(), 300), 3000});
  if (over > 0)
    for (PairSpec& s : specs) s.rounds = over;

  long all = 0, all_exact = 0, all_stray = 0;
  std::map<std::string, long> reasons;
  for (const PairSpec& s : specs) {
    const PairResult r = run_pair(s);
    char b[320];
    std::snprintf(b, sizeof b,
                  "%-28s %5ld rounds: %6ld poses, %6ld unambiguous, %6ld in graph (%4zu CFs), "
                  "%6ld identified exactly, %ld with a stray contact (%.1f s)\n",
                  r.name.c_str(), s.rounds, r.accepted, r.unambiguous, r.in_graph, r.cfs.size(),
                  r.exact, r.stray, r.seconds);
    std::cout << b;
    for (const std::string& m : r.misses) std::cout << m;
    for (const std::string& m : r.strays) std::cout << m;
    for (const auto& [k, n] : r.reasons) reasons[k] += n;
    all += r.in_graph;
    all_exact += r.exact;
    CAPTURE(r.name, r.in_graph, r.exact);
    CHECK(r.in_graph > 0);
    CHECK(r.exact == r.in_graph);
    CHECK(r.stray == 0);
    all_stray += r.stray;
  }
  std::cout << "ambiguous poses by the first reason the oracle found:\n";
  for (const auto& [k, n] : reasons) std::cout << "  " << k << ": " << n << "\n";
  std::cout << "all pairs: " << all_exact << " of " << all
            << " unambiguous poses in the graph identified exactly, " << all_stray
            << " with a stray contact\n"
            << std::flush;
  CHECK(all >= kMinPoses);
  CHECK(all_exact == all);
}

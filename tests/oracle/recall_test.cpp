// Recall of cfgen against the independent oracle on fixed seeds (tests/oracle/README.md).
// For each seed: generate the pair, run cfgen, re-verify every witness (all must be sound),
// sample valid CFs independently and require every sampled CF to be in the graph. Misses are
// printed with the seed, the pair, the PC list and the pose where the oracle realised them;
// reproduce one with `oracle_recall --seed N --keep DIR`.
//
// Environment: ORACLE_ROUNDS (sampler rounds per pair, default 8000, about 3 s),
// ORACLE_BUDGET (cap on the sampler's seconds, default 15), ORACLE_THREADS (cfgen -j, default 2).

#include "recall.hpp"
#include "certificate_check.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <iostream>
#include <string>

#ifndef CF_CFGEN
#error "CF_CFGEN must name the cfgen binary"
#endif

namespace {

// The completeness issue's acceptance level (its aim is 100%). Every fixed seed has no miss
// today (468 to 1235 sampled CFs each); the floor leaves room for a sampler change, not for
// a generator that gets worse (docs/performance.md lists each seed's figures).
constexpr double kMinRecallPercent = 99.5;

void run_seed(std::uint64_t seed) {
  oracle::RecallOptions o;
  o.cfgen = CF_CFGEN;
  o.budget_s = 15.0;        // a cap only: the sampler stops after sampler_rounds rounds,
  o.sampler_rounds = 8000;  // which takes about 3 s and makes the run deterministic
  o.threads = 2;
#ifdef CF_ORACLE_KEEP_DIR
  o.keep_dir = CF_ORACLE_KEEP_DIR;  // pair, graph and samples.csv for identify_oracle_test
#endif
  if (const char* b = std::getenv("ORACLE_BUDGET")) o.budget_s = std::atof(b);
  if (const char* k = std::getenv("ORACLE_ROUNDS")) o.sampler_rounds = std::atol(k);
  if (const char* j = std::getenv("ORACLE_THREADS")) o.threads = std::atoi(j);
  // Every certificate of invalidity cfgen wrote is rechecked by the independent checker.
  oracle::CertificateReport certificates;
  o.inspect = [&](const oracle::RecallResult& run) {
    certificates = oracle::check_certificate_files(run.graph_path, run.cert_path);
  };
  oracle::RecallResult r = oracle::run_recall_seed(seed, o);
  std::cout << r.line() << "\n  sampler: " << r.sampler_stats.str() << "\n"
            << r.details() << std::flush;
  INFO(r.line());
  REQUIRE(r.ok);
  CHECK(r.model_problems.empty());
  CHECK(r.check.unsound == 0);
  // Every witness must be sound, exactly. Recall, the share of the CFs the sampler realises
  // that are in the graph, must reach kMinRecallPercent; every miss is printed above with its
  // pose so that it can be chased.
  CHECK(r.recall() >= kMinRecallPercent);
  std::cout << "  certificates: " << certificates.summary_line() << "\n";
  for (const std::string& line : certificates.rejection_lines()) std::cout << "  " << line << "\n";
  CHECK(certificates.passed());
  CHECK(certificates.sets.size() > 0);
}

}  // namespace

// Fixed seeds: small pairs, one per pairing whose cfgen run is short (pairing = seed % 12):
// 127 wedge against L-section, 44 tiny wedge against stairs, 11 box against L-section,
// 171 box on stairs, 144 triangular peg in triangular hole, 126 box against T-section,
// 1 box in corner block, 14 triangular prism in U-channel. The other pairings (cube in square
// hole, L-part against U-channel, A wider than the pocket, L-part against corner/stairs) make
// cfgen run for minutes; scripts/recall-soak.sh covers them.
#define ORACLE_SEED(N) \
  TEST_CASE("recall on seed " #N, "[oracle][recall]") { run_seed(N); }

ORACLE_SEED(127)
ORACLE_SEED(44)
ORACLE_SEED(11)
ORACLE_SEED(171)
ORACLE_SEED(144)
ORACLE_SEED(126)
ORACLE_SEED(1)
ORACLE_SEED(14)

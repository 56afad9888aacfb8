// oracle_recall: recall of cfgen against the independent oracle on one model pair.
//
//   oracle_recall --seed N [--cfgen PATH] [--budget SECONDS] [--keep DIR] [-j THREADS]
//                 [--sampler-seed K] [--rounds K] [--pose R00,..,R22,tx,ty,tz]... [--quiet]
//                 [--cfgen-timeout S] [--extra K]
//   oracle_recall A.off B.off [same options]
//
// --extra K takes the pair of seed N from the pairings outside the seeded cycle
// (oracle::make_extra_pair: 0 pyramid, 1 wedge, 2 n-gon prism, each against a ramp step).
//
// --pose classifies that pose of A with the oracle and says whether the graph holds its CF
// (every reported miss prints such a recheck command line).
//
// Prints one line (seed, counts, recall, unsound witnesses, description), then the details:
// every miss with its PC list, the pose where the oracle realised it and how it got there,
// and every unsound or marginal witness. Exit status: 0 no miss and no unsound witness,
// 1 misses or unsound witnesses, 2 usage error or a run that failed.

#include "certificate_check.hpp"
#include "recall.hpp"
#include "shapes.hpp"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#ifndef CF_CFGEN
#define CF_CFGEN "cfgen"
#endif

namespace {
void usage() {
  std::puts(
      "usage: oracle_recall --seed N [--cfgen PATH] [--budget SECONDS] [--keep DIR] [-j THREADS]\n"
      "                     [--sampler-seed K] [--rounds K] [--pose R00,..,R22,tx,ty,tz]... "
      "[--quiet]\n"
      "       oracle_recall A.off B.off [options]\n"
      "Generates the model pair of seed N (or takes A.off, B.off), runs cfgen on it, re-verifies\n"
      "every witness of the graph and samples valid CFs independently; prints the CFs the graph\n"
      "misses. --budget: sampler seconds (default 3). --keep: keep models, graph and cfgen log in\n"
      "DIR/seed_N. --rounds: stop the sampler after K rounds (deterministic with a large budget).\n"
      "--cfgen-timeout S: give up on cfgen after S seconds (status 2).\n"
      "--pose: classify this pose of A (x_B = R x_A + t) and say whether the graph holds its CF.\n"
      "--extra K: with --seed N, the pair of seed N of extra pairing K (0 pyramid, 1 wedge,\n"
      "2 n-gon prism, each against a ramp step), kept in DIR/extra_K_seed_N.\n"
      "--quiet: only the summary line. Environment: CF_CFGEN_PATH overrides the cfgen binary.");
}
}  // namespace

int main(int argc, char** argv) {
  oracle::RecallOptions o;
  o.cfgen = CF_CFGEN;
  if (const char* e = std::getenv("CF_CFGEN_PATH")) o.cfgen = e;
  bool quiet = false;
  oracle::PairArgs pair;
  std::vector<std::string> files;
  try {
    for (int i = 1; i < argc; ++i) {
      std::string a = argv[i];
      auto val = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        usage();
        return 0;
      } else if (pair.take(a, val)) {  // --seed, --extra
      } else if (a == "--cfgen") {
        o.cfgen = val();
      } else if (a == "--budget") {
        o.budget_s = std::stod(val());
        if (!(o.budget_s >= 0 && o.budget_s < 1e6))
          throw std::runtime_error("--budget out of range");
      } else if (a == "--keep") {
        o.keep_dir = val();
      } else if (a == "-j" || a == "--threads") {
        o.threads = std::stoi(val());
      } else if (a == "--sampler-seed") {
        o.sampler_seed = std::stoull(val());
      } else if (a == "--cfgen-timeout") {
        o.cfgen_timeout_s = std::stod(val());
      } else if (a == "--rounds") {
        o.sampler_rounds = std::stol(val());
      } else if (a == "--pose") {
        oracle::Pose X;
        if (!oracle::parse_pose_arg(val(), &X))
          throw std::runtime_error("--pose needs 12 numbers R00,...,R22,tx,ty,tz (R a rotation)");
        o.check_poses.push_back(X);
      } else if (a == "--quiet" || a == "-q") {
        quiet = true;
      } else if (!a.empty() && a[0] == '-') {
        throw std::runtime_error("unknown option " + a);
      } else {
        files.push_back(a);
      }
    }
    if (pair.have_seed == !files.empty() || (!files.empty() && files.size() != 2))
      throw std::runtime_error("give either --seed N or two model files");
    pair.check();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oracle_recall: %s\n", e.what());
    return 2;
  }
  // cfgen's certificates of invalidity, rechecked while its files exist.
  oracle::CertificateReport certificates;
  std::string certificate_error;
  o.inspect = [&](const oracle::RecallResult& run) {
    try {
      certificates = oracle::check_certificate_files(run.graph_path, run.cert_path);
    } catch (const std::exception& e) {
      certificate_error = e.what();
    }
  };
  oracle::RecallResult r = !pair.have_seed   ? oracle::run_recall_files(files[0], files[1], o)
                           : pair.extra >= 0 ? oracle::run_recall_extra(pair.extra, pair.seed, o)
                                             : oracle::run_recall_seed(pair.seed, o);
  std::cout << r.line() << "\n";
  if (r.ok)
    std::cout << "  certificates: "
              << (certificate_error.empty() ? certificates.summary_line() : certificate_error)
              << "\n";
  for (const std::string& line : certificates.rejection_lines()) std::cout << "  " << line << "\n";
  if (!quiet) {
    std::cout << "  sampler: " << r.sampler_stats.str() << "\n";
    std::cout << r.details();
  }
  std::cout.flush();
  if (!r.ok || !certificate_error.empty()) return 2;
  return (r.misses.empty() && r.check.unsound == 0 && certificates.passed()) ? 0 : 1;
}

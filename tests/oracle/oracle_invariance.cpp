// oracle_invariance: whether cfgen's graph of a model pair depends only on the solids.
//
//   oracle_invariance --seed N [--extra K] [--motion-seed M] [--float32] [--cfgen PATH]
//                     [-j THREADS] [--keep DIR] [--list K] [-- CFGEN_OPTIONS...]
//
// Writes the oracle's pair of seed N, and a copy with each model moved by its own random
// rigid motion and renumbered (vertices, facets, each facet's first vertex), with --float32
// as binary STL with float32 coordinates (facets triangulated), runs cfgen on
// both and compares the CF sets through the map between the graphs' elements. Prints one
// line (seed, both counts, the sets only one graph holds, how many of those have a witness
// the oracle finds sound, so that the other run missed a CF, cfgen's times, the pair), then
// up to K of those sets each way, in the first graph's numbering. Exit status: 0 the same CFs,
// 1 not, 2 usage error or a run that failed.

#include "invariance.hpp"

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
      "usage: oracle_invariance --seed N [--extra K] [--motion-seed M] [--float32]\n"
      "                         [--cfgen PATH] [-j THREADS] [--keep DIR] [--list K]\n"
      "                         [-- CFGEN_OPTIONS...]\n"
      "Runs cfgen on the oracle's pair of seed N and on a copy with each model moved by a\n"
      "random rigid motion and renumbered (from --motion-seed, default 1), with --float32\n"
      "written as binary STL with float32 coordinates (17-digit OFF otherwise), and compares the\n"
      "CF sets through the map between the two graphs' elements. --keep: keep the models,\n"
      "graphs and cfgen logs in DIR. --list: print up to K differing sets each way (default\n"
      "10). Options after -- go to both cfgen runs. Exit 0 when the CF sets are the same, 1\n"
      "when they differ, 2 on a usage error or a failed run. Environment: CF_CFGEN_PATH\n"
      "overrides the cfgen binary.");
}

void print_sets(const char* label, const std::vector<oracle::CfKey>& sets, int limit) {
  for (int i = 0; i < static_cast<int>(sets.size()) && i < limit; ++i)
    std::cout << "  " << label << " " << oracle::key_string(sets[i]) << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  oracle::InvarianceOptions o;
  o.cfgen = CF_CFGEN;
  if (const char* e = std::getenv("CF_CFGEN_PATH")) o.cfgen = e;
  oracle::PairArgs pair;
  int list = 10;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto val = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        usage();
        return 0;
      } else if (pair.take(a, val)) {  // --seed, --extra
      } else if (a == "--motion-seed") {
        o.motion_seed = std::stoull(val());
      } else if (a == "--float32") {
        o.float32_stl = true;
      } else if (a == "--cfgen") {
        o.cfgen = val();
      } else if (a == "-j" || a == "--threads") {
        o.threads = std::stoi(val());
      } else if (a == "--keep") {
        o.keep_dir = val();
      } else if (a == "--list") {
        list = std::stoi(val());
      } else if (a == "--") {
        o.cfgen_args.assign(argv + i + 1, argv + argc);
        break;
      } else {
        throw std::runtime_error("unknown argument " + a);
      }
    }
    if (!pair.have_seed) throw std::runtime_error("give --seed N");
    pair.check();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oracle_invariance: %s\n", e.what());
    return 2;
  }
  const oracle::InvarianceResult r =
      oracle::run_invariance(pair.extra >= 0 ? oracle::make_extra_pair(pair.extra, pair.seed)
                                             : oracle::make_pair(pair.seed),
                             o);
  std::printf("seed=%llu %s", static_cast<unsigned long long>(pair.seed),
              !r.ok      ? "FAILED"
              : r.same() ? "same"
                         : "DIFFERENT");
  if (r.ok)
    std::printf(" cfs=%d moved=%d only_first=%zu only_moved=%zu sound=%d+%d", r.first_cfs,
                r.moved_cfs, r.only_first.size(), r.only_moved.size(), r.sound_first,
                r.sound_moved);
  std::printf(" cfgen=%.1fs+%.1fs | %s\n", r.first_s, r.moved_s, r.desc.c_str());
  if (!r.ok) {
    std::cout << "  " << r.error << "\n";
    return 2;
  }
  print_sets("only first:", r.only_first, list);
  print_sets("only moved:", r.only_moved, list);
  return r.same() ? 0 : 1;
}

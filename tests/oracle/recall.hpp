#pragma once
// Independent test oracle: one recall run on a model pair. Writes the pair (generated from a
// seed, or given files), runs cfgen on it, rebuilds the featured models from the graph, checks
// the models against the meshes, re-verifies every witness, samples valid CFs independently
// and reports the sampled CFs the graph lacks.

#include "graph.hpp"
#include "sampler.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace oracle {

struct RecallResult;

struct RecallOptions {
  std::string cfgen;               // path of the cfgen binary
  double budget_s = 3.0;           // sampler time per pair
  int threads = 2;                 // cfgen -j
  double cfgen_timeout_s = 0;      // >0: kill cfgen after this long and report the run as failed
  std::string keep_dir;            // keep the models and the graph here ("" = temporary, removed)
  std::uint64_t sampler_seed = 0;  // 0: derived from the pair's seed
  int max_printed_misses = 30;
  long sampler_rounds = 0;  // >0: stop the sampler after this many rounds (deterministic)
  std::vector<Pose>
      check_poses;  // classify these poses of A and say whether the graph holds the CF
  /// Called once a run worked, while its files (models, graph, certificate file) still exist.
  std::function<void(const RecallResult&)> inspect;
};

struct Miss {
  CfKey key;
  Sample sample;
};

struct RecallResult {
  bool ok = false;  // the run itself worked (cfgen ran, graph read)
  std::string error;
  std::uint64_t seed = 0;
  bool from_seed = false;
  int extra = -1;  // >= 0: the pair is make_extra_pair(extra, seed)
  std::string desc;
  std::string a_path, b_path, graph_path;
  std::string cert_path;  // cfgen's certificate file (docs/certificates.md), beside the graph
  int graph_cfs = 0;
  int sampled = 0;
  int found = 0;  // sampled and in the graph
  std::vector<Miss> misses;
  /// Sampled CFs the graph lists as THIN (stats.thin_sets), whose best oracle pose is not as
  /// clear as the graph's min_clearance_mm either: known to the generator, not misses.
  std::vector<Miss> thin;
  int unstable = 0;  // sampled CFs whose PCs change between tol/10 and tol*10 (dropped)
  int suspect = 0;   // misses the Monte-Carlo check contradicts (dropped, printed)
  std::vector<Miss> suspects;
  std::vector<std::string> pose_reports;  // for RecallOptions::check_poses
  CheckReport check;
  std::vector<std::string> model_problems;  // graph models vs the meshes
  double cfgen_s = 0, sampler_s = 0, check_s = 0;
  SamplerStats sampler_stats;

  /// Per cent of the sampled CFs the graph holds or lists as THIN.
  double recall() const {
    return sampled ? 100.0 * (found + static_cast<double>(thin.size())) / sampled : 100.0;
  }
  std::string line() const;     // one line: seed, description, counts, recall, unsound
  std::string details() const;  // misses (PC lists, poses), unsound witnesses, model problems
};

/// A pose as 12 comma-separated numbers (R row by row, then t), and back (false when malformed
/// or not a rotation).
std::string pose_arg(const Pose& X);
bool parse_pose_arg(const std::string& a, Pose* X);

/// Signature of a CF for grouping: "2:e-f+v-f".
std::string signature(const CfKey& k);

/// Runs a program (args[0], its path) with its standard output and error to `log`; returns its
/// exit status: -1 when it could not start or did not exit normally, -2 when it was killed
/// after timeout_s seconds (timeout_s > 0).
int run_program(const std::vector<std::string>& args, const std::string& log, double timeout_s = 0);

RecallResult run_recall_seed(std::uint64_t seed, const RecallOptions& o);
/// The pair make_extra_pair(which, seed) (kept as DIR/extra_<which>_seed_<seed>).
RecallResult run_recall_extra(int which, std::uint64_t seed, const RecallOptions& o);
RecallResult run_recall_files(const std::string& a_off, const std::string& b_off,
                              const RecallOptions& o);

}  // namespace oracle

#include "cfgen/generate.hpp"

#include "cfgen/certificate_file.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/enumerate/symmetry.hpp"
#include "cfgen/execute/progress.hpp"
#include "cfgen/execute/shard.hpp"
#include "cfgen/execute/stop.hpp"
#include "mesh/model_loader.hpp"

#include <cf/file_io.hpp>

#include <cf/graph.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <tuple>
#include <utility>

#include <csignal>

#include <unistd.h>

namespace cf::tools {

std::string conflicting_lengths(const RelativeLengths& rel, bool python_names) {
  if (rel.good_clearance >= rel.min_clearance) return "";
  const char* good = python_names ? "good_clearance" : "--good-clearance";
  const char* min = python_names ? "min_clearance" : "--min-clearance";
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%s %g is below %s %g: a witness is kept only when its clearance reaches %s, "
                "and the search stops at %s, so no witness would be kept; give %s at least %s "
                "(defaults: %g and %g x D)",
                good, rel.good_clearance, min, rel.min_clearance, min, good, good, min,
                RelativeLengths{}.good_clearance, RelativeLengths{}.min_clearance);
  return buf;
}

double length_scale(const Polyhedron& A, const Polyhedron& B) {
  return std::min((A.bbox_max() - A.bbox_min()).norm(), (B.bbox_max() - B.bbox_min()).norm());
}

void symmetrize(MeasuredModel& a, MeasuredModel& b) {
  const double strict = gen::kSymmetryTol * std::max(a.model.size(), b.model.size());
  for (MeasuredModel* m : {&a, &b}) {
    double moved = 0;
    m->model = gen::symmetrized(m->model, gen::kSymmetryRoundings * m->rounding_mm, strict, &moved);
    m->deviation_mm += moved;  // the faces moved by at most as much as their corners
  }
}

gen::SearchParams scaled_search(const Polyhedron& A, const Polyhedron& B,
                                const RelativeLengths& rel, gen::SearchParams base) {
  const double D = length_scale(A, B);
  base.touch_tol =
      std::max(rel.touch_tol * D, kTouchPerPrecision * (model_precision(A) + model_precision(B)));
  base.min_clearance = rel.min_clearance * D;
  base.good_clearance = rel.good_clearance * D;
  base.min_margin = rel.min_margin * D;
  return base;
}

namespace {

// The exit status of a run stopped on request, after saying what was kept.
int stopped_status(const GenerateArgs& args, const std::string& checkpoint_dir) {
  const int sig = gen::stop_signal();
  std::cerr << "cfgen: stopped"
            << (sig == SIGTERM  ? " (SIGTERM)"
                : sig == SIGINT ? " (SIGINT)"
                                : "")
            << "; ";
  if (args.estimate)
    std::cerr << "no estimate printed\n";
  else if (checkpoint_dir.empty())
    std::cerr << "nothing kept (--checkpoint DIR keeps finished work); '" << args.out_path
              << "' not written\n";
  else
    std::cerr << "finished chunks are kept in '" << checkpoint_dir
              << "': the same command resumes from them\n";
  // 128 + the signal, as a shell reports a process the signal ended.
  return 128 + (sig ? sig : SIGINT);
}

// The graph's "meta" record: statistics, the parameters and the generator (docs/graph-format.md).
nlohmann::json graph_meta(const gen::Enumeration& e, const GenerateArgs& args,
                          const gen::SearchParams& s, const gen::EnumerateOptions& opt, double diag,
                          const Polyhedron& A, const Polyhedron& B, const MeasuredModel& ma,
                          const MeasuredModel& mb) {
  nlohmann::json meta;
  nlohmann::json by_count = nlohmann::json::object(), by_type = nlohmann::json::object();
  for (const CfRecord& r : e.cfs) {
    by_count[std::to_string(r.pcs.size())] = by_count.value(std::to_string(r.pcs.size()), 0) + 1;
    for (const Pc& pc : r.pcs)
      by_type[to_string(pc.type)] = by_type.value(to_string(pc.type), 0) + 1;
  }
  nlohmann::json by_kind = nlohmann::json::object();
  for (const Transition& t : e.transitions)
    by_kind[to_string(t.kind)] = by_kind.value(to_string(t.kind), 0) + 1;
  nlohmann::json levels = nlohmann::json::array();
  for (const auto& l : e.levels)
    levels.push_back({{"candidates", l.candidates},
                      {"valid", l.valid},
                      {"found_by_motion", l.by_motion},
                      {"found_by_symmetry", l.by_symmetry},
                      {"found_by_neighbours", l.by_neighbours},
                      {"found_by_cells", l.by_cells}});
  // The undecided sets, in canonical order; only the first kUndecidedListed are listed, so
  // that a pair with many keeps a file of reasonable size (the count is always exact).
  constexpr std::size_t kUndecidedListed = 100;
  nlohmann::json undecided = nlohmann::json::array();
  for (std::size_t i = 0; i < e.undecided.size() && i < kUndecidedListed; ++i)
    undecided.push_back(to_string(e.undecided[i]));
  // Every THIN set, with its pose: they are few (about 2% of the CFs of an n-gon peg and hole).
  nlohmann::json thin = nlohmann::json::array();
  for (const auto& [pcs, w] : e.thin) thin.push_back(thin_set_json(pcs, w));
  meta["stats"] = {{"cfs", e.cfs.size()},
                   {"cfs_by_pc_count", by_count},
                   {"pcs_by_type", by_type},
                   {"transitions", e.transitions.size()},
                   {"transitions_by_kind", by_kind},
                   {"levels", levels},
                   {"symmetries", {{"A", e.symmetries_a}, {"B", e.symmetries_b}}},
                   {"min_witness_clearance_mm", e.cfs.empty() ? 0.0 : e.min_clearance},
                   {"min_witness_margin_mm", e.cfs.empty() ? 0.0 : e.min_margin},
                   {"refuted_over_cells", e.refuted_over_cells},
                   {"undecided", e.undecided.size()},
                   {"undecided_sets", undecided},
                   {"thin", e.thin.size()},
                   {"thin_sets", thin}};
  // Timing goes to stderr, not into the file, so that the same input gives the same bytes.
  meta["parameters"] = {
      {"length_scale_mm", diag},
      {"touch_tol_rel", args.rel.touch_tol},
      {"min_clearance_rel", args.rel.min_clearance},
      {"good_clearance_rel", args.rel.good_clearance},
      {"min_margin_rel", args.rel.min_margin},
      {"touch_tol_mm", s.touch_tol},
      {"precision_mm", {{"A", ma.precision_mm}, {"B", mb.precision_mm}}},
      {"rounding_mm", {{"A", ma.rounding_mm}, {"B", mb.rounding_mm}}},
      {"planarity_mm", {{"A", model_precision(A)}, {"B", model_precision(B)}}},
      {"deviation_mm", {{"A", ma.deviation_mm}, {"B", mb.deviation_mm}}},
      {"coplanar_rel_tol",
       {{"A", args.load_a.coplanar_rel_tol}, {"B", args.load_b.coplanar_rel_tol}}},
      {"crease_angle_deg",
       {{"A", args.load_a.crease_angle_deg}, {"B", args.load_b.crease_angle_deg}}},
      {"min_clearance_mm", s.min_clearance},
      {"good_clearance_mm", s.good_clearance},
      {"min_margin_mm", s.min_margin},
      {"angle_margin_rad", s.angle_margin},
      {"theta_samples", s.theta_samples},
      {"max_rotations", s.max_rotations},
      {"max_pcs", opt.max_pcs},
      {"symmetry", opt.use_symmetry}};
  if (args.thorough)
    meta["parameters"]["thorough"] = true;  // absent otherwise: the same bytes as before
  if (args.cube_cells > 0) meta["parameters"]["cube_cells"] = args.cube_cells;  // likewise
  if (args.resolution != gen::kResolution)  // likewise; the default is gen::kResolution
    meta["parameters"]["resolution_rad"] = args.resolution;
  meta["generator"] = {{"name", "cfgen"}, {"a_model", args.a_path}, {"b_model", args.b_path}};
  // Coordinates are stored in mm; the unit each model file was read in (docs/spec.md, section 2).
  meta["source_units"] = {{"A", args.load_a.units}, {"B", args.load_b.units}};

  return meta;
}

// "3678" for a count, "~12,000" (two significant digits) for a prediction.
std::string about(double x, bool exact = false) {
  if (exact) return std::to_string(std::llround(x));
  if (x < 10) return "~" + std::to_string(std::llround(x));
  const double p = std::pow(10.0, std::floor(std::log10(x)) - 1);
  std::string digits = std::to_string(std::llround(std::round(x / p) * p));
  for (int i = static_cast<int>(digits.size()) - 3; i > 0; i -= 3)
    digits.insert(static_cast<std::size_t>(i), ",");
  return "~" + digits;
}

void print_estimate(std::ostream& os, const gen::RunEstimate& e, int max_pcs) {
  std::size_t decided = 0;
  for (int l = 0; l < max_pcs; ++l) {
    const gen::LevelEstimate& v = e.levels[l];
    decided += v.sampled;
    os << "level " << l + 1 << ": " << about(v.candidates, v.exact) << " candidate sets in "
       << about(v.orbits, v.exact) << " orbits" << (v.exact ? " (counted)" : "") << ", "
       << about(v.valid) << " valid, " << about(v.tasks) << " searches\n";
  }
  os << "graph: " << about(e.cfs) << " CFs, " << about(e.transitions) << " transitions\n";
  os << "time: " << gen::human_duration(e.seconds) << " on " << e.threads << " thread"
     << (e.threads == 1 ? "" : "s") << " (" << gen::human_duration(e.cpu_seconds) << " on one)\n";
  os << "peak memory: " << about(e.peak_bytes / 1e6) << " MB\n";
  os << "predicted from " << decided << " sets decided in " << gen::human_duration(e.sample_seconds)
     << "; its errors on the pairs measured: docs/performance.md, \"Estimates\"\n";
}

// The run predicted with the search and options of the run, on its threads, from `samples`
// orbits a level.
gen::RunEstimate predict(const gen::WitnessSearch& ws, const gen::EnumerateOptions& opt,
                         const GenerateArgs& args, std::size_t samples) {
  gen::ExecuteOptions exec;
  exec.threads = args.threads;
  exec.stop = args.stop;
  gen::Executor executor([&ws](const gen::Task& t) { return gen::decide(ws, t); }, exec);
  return gen::estimate(ws, opt, executor, executor.threads(), samples);
}

// Where a run keeps its checkpoint, and how long it is predicted to take.
struct RunPlan {
  std::string checkpoint_dir;       // empty: none
  bool default_checkpoint = false;  // GRAPH.json.ckpt, removed once the graph is written
  double predicted = 0;             // s, 0: not predicted
};

// A long run keeps a checkpoint unless told not to, and a checkpoint left by an interrupted
// run of the same command is taken up whatever the prediction. The prediction also gives
// the progress line the time left of the whole run.
// @throws gen::Stopped when a signal stops the prediction.
RunPlan plan_run(const gen::WitnessSearch& ws, const gen::EnumerateOptions& opt,
                 const GenerateArgs& args, bool writes) {
  RunPlan plan;
  plan.checkpoint_dir = args.checkpoint_dir;
  const bool may_keep = writes && plan.checkpoint_dir.empty() && !args.no_checkpoint &&
                        args.shard.count == 0 && !args.out_path.empty();
  if (writes && (may_keep || !args.quiet))
    plan.predicted = predict(ws, opt, args, gen::kRunPredictionSamples).seconds;
  if (!may_keep) return plan;
  const std::string dir = args.out_path + ".ckpt";
  std::error_code ec;
  const bool left = std::filesystem::exists(std::filesystem::path(dir) / "checkpoint.json", ec);
  if (left || plan.predicted > kDefaultCheckpointSeconds)
    plan.checkpoint_dir = dir, plan.default_checkpoint = true;
  return plan;
}

// The graph is not written into the checkpoint directory, which a run reads, rewrites and
// removes on success (`--checkpoint ck -o ck/checkpoint.json` wrote the graph over it).
void check_outside_checkpoint(const std::string& out_path, const std::string& checkpoint_dir,
                              const char* what) {
  if (checkpoint_dir.empty()) return;
  const std::string dir = canonical_path(checkpoint_dir), out = canonical_path(out_path);
  if (out.size() > dir.size() && out.compare(0, dir.size(), dir) == 0 && out[dir.size()] == '/')
    throw Error(std::string(what) + " '" + out_path + "': is inside the checkpoint directory '" +
                checkpoint_dir + "', which the run rewrites and removes; write it elsewhere");
}

// An output path checked before the work (docs/spec.md, section 5b): not a device, FIFO or
// directory, not an input nor one of `others`, not inside the checkpoint directory.
void check_output(const std::string& path, const std::vector<std::string>& inputs,
                  const std::string& checkpoint_dir, const char* what,
                  const std::vector<std::string>& others) {
  check_output_path(path, inputs, what, others);
  check_outside_checkpoint(path, checkpoint_dir, what);
}

// A model small or large against the paper's epsilon, in the unit its option sets.
void warn_sizes(const Polyhedron& A, const Polyhedron& B) {
  for (const auto& [m, which, option] :
       {std::tuple{&A, "A", "--units-a"}, std::tuple{&B, "B", "--units-b"}})
    if (const std::string w = size_warning(*m, which, option); !w.empty())
      std::cerr << "cfgen: warning: " << w << '\n';
}

// What a run that wrote its graph says: a graph without CFs, and unless quiet its counts.
void report_written(const GenerateArgs& args, const gen::Enumeration& e, const Polyhedron& A,
                    const Polyhedron& B, std::size_t n_cfs, std::size_t n_tr, double seconds) {
  if (n_cfs == 0)
    std::cerr << "cfgen: warning: the graph has no CF: A (" << A.size() << " mm across) and B ("
              << B.size()
              << " mm across) never touch in a valid contact formation; are the models' units "
                 "right (--units)?\n";
  if (!args.quiet)
    std::cerr << "cfgen: " << n_cfs << " CFs (" << e.levels[0].valid << " + " << e.levels[1].valid
              << " + " << e.levels[2].valid << "), " << n_tr << " transitions, " << seconds
              << " s -> " << args.out_path << '\n';
}

// The enumeration's options from the command line's; `writes`: this process writes the graph
// (the other shards stop after the last stage), `certifies` its certificates too.
gen::EnumerateOptions enumerate_options(const GenerateArgs& args, bool writes, bool certifies) {
  gen::EnumerateOptions opt;
  opt.max_pcs = args.max_pcs;
  opt.use_symmetry = args.symmetry && !args.thorough;
  opt.close_orbits = args.thorough;
  opt.cube_cells = args.cube_cells;
  opt.resolution = args.resolution;
  opt.records = writes;
  opt.certificates = certifies;
  return opt;
}

// How the run's stages are executed: threads, shards, the checkpoint (none when
// checkpoint_dir is empty), the stop request.
gen::ExecuteOptions execute_options(const GenerateArgs& args, const std::string& checkpoint_dir,
                                    const std::vector<std::string>& inputs) {
  gen::ExecuteOptions exec;
  exec.threads = args.threads;
  exec.shard = args.shard;
  exec.shard_patience = args.shard_patience;
  // Another shard's chunk is a file to look for (a stat each), another rank's a message.
  exec.shard_poll = args.share.load ? 0.005 : 0.05;  // s
  if (!checkpoint_dir.empty())
    exec.checkpoint = open_checkpoint(checkpoint_dir, run_fingerprint(args), inputs);
  exec.checkpoint = gen::either(exec.checkpoint, args.share);
  exec.stop = args.stop;
  return exec;
}

// What an MPI rank or a shard took from the others and waited for them.
void report_sharing(const GenerateArgs& args, const gen::Executor& executor, bool writes) {
  if (args.share.load)
    std::cerr << "cfgen: rank " << args.shard.index << " of " << args.shard.count << ": took "
              << executor.shared_chunks() << " chunks from the other ranks, waited "
              << executor.waited_seconds() << " s for them\n";
  else if (args.shard.count > 0)
    std::cerr << "cfgen: shard " << args.shard.index << "/" << args.shard.count << ": took "
              << executor.shared_chunks() << " chunks from the other shards, waited "
              << executor.waited_seconds() << " s for them, computed "
              << executor.taken_over_chunks() << " of theirs that did not come"
              << (writes ? "" : "; shard 0 writes the graph") << '\n';
}

}  // namespace

int run_generate(const GenerateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  // The output path is checked before the work: not a device, FIFO or directory, not one of
  // the models (docs/spec.md, section 5b).
  const std::vector<std::string> inputs{args.a_path, args.b_path};
  // Of K shards, shard 0 writes the graph.
  const bool writes = !args.estimate && args.shard.index == 0;
  const bool to_file = writes && !args.out_path.empty();
  const bool certifies = writes && !args.certificates_path.empty();
  if (to_file) check_output(args.out_path, inputs, args.checkpoint_dir, "writing graph", {});
  if (certifies)
    check_output(args.certificates_path, inputs, args.checkpoint_dir, "writing certificates",
                 to_file ? std::vector<std::string>{args.out_path} : std::vector<std::string>{});
  MeasuredModel ma = load_measured_model(args.a_path, args.load_a);
  MeasuredModel mb = load_measured_model(args.b_path, args.load_b);
  symmetrize(ma, mb);  // whether or not the search uses the maps: one model, one graph
  const Polyhedron& A = ma.model;
  const Polyhedron& B = mb.model;
  // The other ranks of an MPI run say nothing that rank 0 says.
  if (!args.share.load || args.shard.index == 0) warn_sizes(A, B);
  const gen::ModelInfo ai = gen::analyse_model(A, ma.precision_mm);
  const gen::ModelInfo bi = gen::analyse_model(B, mb.precision_mm);

  // Lengths scale with the smaller model (RelativeLengths).
  const double diag = length_scale(A, B);
  const gen::SearchParams search = scaled_search(A, B, args.rel, args.search);
  const gen::EnumerateOptions opt = enumerate_options(args, writes, certifies);
  const gen::WitnessSearch ws(ai, bi, search);
  if (args.estimate) {
    try {
      print_estimate(std::cout, predict(ws, opt, args, gen::kEstimateSamples), opt.max_pcs);
    } catch (const gen::Stopped&) {
      return stopped_status(args, "");
    }
    std::cout.flush();
    if (!std::cout) throw Error("writing the estimate to stdout failed");
    return 0;
  }
  RunPlan plan;
  try {
    plan = plan_run(ws, opt, args, writes);
  } catch (const gen::Stopped&) {
    return stopped_status(args, "");
  }
  const std::string& checkpoint_dir = plan.checkpoint_dir;
  const bool default_checkpoint = plan.default_checkpoint;
  const double predicted = plan.predicted;
  gen::ExecuteOptions exec = execute_options(args, checkpoint_dir, inputs);
  const bool terminal = isatty(STDERR_FILENO) != 0;
  gen::ProgressPrinter printer(std::cerr, terminal);
  if (!args.quiet)
    exec.progress = [&](const gen::ProgressEvent& ev) {
      // On a terminal, only runs over a couple of seconds get the updating line.
      if (terminal && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) return;
      printer(ev);
    };
  if (!args.quiet && default_checkpoint)
    std::cerr << "cfgen: predicted " << gen::human_duration(predicted)
              << "; finished work is kept in '" << checkpoint_dir
              << "' until the graph is written (--no-checkpoint: not kept)\n";
  printer.set_run(predicted);
  gen::Executor executor([&ws](const gen::Task& t) { return gen::decide(ws, t); }, exec);
  gen::Enumeration e;
  try {
    e = gen::enumerate(ws, opt, executor);
  } catch (const gen::Stopped&) {
    printer.finish();
    return stopped_status(args, checkpoint_dir);
  }
  printer.finish();
  if (executor.resumed_chunks() > 0 && !args.quiet)
    std::cerr << "cfgen: checkpoint '" << checkpoint_dir << "': resumed "
              << executor.resumed_chunks() << " finished chunks\n";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!args.quiet) report_sharing(args, executor, writes);
  if (!writes) return 0;

  const nlohmann::json meta = graph_meta(e, args, search, opt, diag, A, B, ma, mb);
  const std::size_t n_cfs = e.cfs.size(), n_tr = e.transitions.size();
  // Moved, not copied: a large graph's records and transitions are hundreds of MB.
  CfGraph graph =
      CfGraph::from_parts(A, B, std::move(e.cfs), std::move(e.transitions), meta.dump());
  if (to_file) {
    check_output_path(args.out_path, inputs, "writing graph");
    graph.save(args.out_path);
  }
  if (certifies) write_certificates(args.certificates_path, inputs, args.out_path, e, ws);
  if (args.graph_out) *args.graph_out = std::move(graph);
  if (default_checkpoint) remove_checkpoint(checkpoint_dir);
  report_written(args, e, A, B, n_cfs, n_tr, seconds);
  return 0;
}

}  // namespace cf::tools

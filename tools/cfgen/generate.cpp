#include "cfgen/generate.hpp"

#include "cfgen/enumerate.hpp"
#include "cfgen/progress.hpp"
#include "cfgen/shard.hpp"
#include "mesh/model_loader.hpp"

#include <cf/file_io.hpp>

#include <cf/graph.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <thread>
#include <tuple>
#include <utility>

#include <unistd.h>

namespace cf::tools {

double length_scale(const Polyhedron& A, const Polyhedron& B) {
  return std::min((A.bbox_max() - A.bbox_min()).norm(), (B.bbox_max() - B.bbox_min()).norm());
}

gen::SearchParams scaled_search(const Polyhedron& A, const Polyhedron& B, const RelativeLengths& rel,
                                gen::SearchParams base) {
  const double D = length_scale(A, B);
  base.touch_tol = rel.touch_tol * D;
  base.min_clearance = rel.min_clearance * D;
  base.good_clearance = rel.good_clearance * D;
  base.min_margin = rel.min_margin * D;
  return base;
}

int run_generate(const GenerateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  // The output path is checked before the work: not a device, FIFO or directory, not one of
  // the models (SPEC section 5b).
  const std::vector<std::string> inputs{args.a_path, args.b_path};
  const bool sharded = args.shard.count > 0;
  if (!args.serve) check_output_path(args.out_path, inputs, sharded ? "writing shard part" : "writing graph");
  const std::string fingerprint = sharded ? run_fingerprint(args) : std::string();
  const Polyhedron A = load_model(args.a_path, args.load_a);
  const Polyhedron B = load_model(args.b_path, args.load_b);
  if (!args.serve)
    for (const auto& [m, which, option] : {std::tuple{&A, "A", "--units-a"}, std::tuple{&B, "B", "--units-b"}})
      if (const std::string w = size_warning(*m, which, option); !w.empty()) std::cerr << "cfgen: warning: " << w << '\n';
  const gen::ModelInfo ai = gen::analyse_model(A);
  const gen::ModelInfo bi = gen::analyse_model(B);
  if (args.serve) return args.serve(gen::WitnessSearch(ai, bi, scaled_search(A, B, args.rel, args.search)), args.threads);

  gen::EnumerateOptions opt;
  opt.threads = args.threads;
  // Lengths scale with the smaller model (RelativeLengths).
  const double diag = length_scale(A, B);
  opt.search = scaled_search(A, B, args.rel, args.search);
  opt.max_pcs = args.max_pcs;
  opt.use_symmetry = args.symmetry && !args.thorough;
  opt.close_orbits = args.thorough;
  opt.shard = args.shard;
  std::size_t resumed_chunks = 0;
  if (!args.checkpoint_dir.empty()) {
    opt.checkpoint = open_checkpoint(args.checkpoint_dir, run_fingerprint(args), inputs);
    auto load = opt.checkpoint.load;
    opt.checkpoint.load = [load, &resumed_chunks](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
                                                  std::vector<gen::TaskResult>& out) {
      const bool kept = load(stage, chunk, tasks, out);
      resumed_chunks += kept ? 1 : 0;
      return kept;
    };
  }
  opt.first_pairs = args.first_pairs;
  opt.distribute = args.distribute;
  const bool terminal = isatty(STDERR_FILENO) != 0;
  gen::ProgressPrinter printer(std::cerr, terminal);
  if (!args.quiet)
    opt.progress = [&](const gen::ProgressEvent& ev) {
      // On a terminal, only runs over a couple of seconds get the updating line.
      if (terminal && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) return;
      printer(ev);
    };
  gen::Enumeration e = gen::enumerate(ai, bi, opt);
  printer.finish();
  if (resumed_chunks > 0 && !args.quiet)
    std::cerr << "cfgen: checkpoint '" << args.checkpoint_dir << "': resumed " << resumed_chunks
              << " finished chunks\n";
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (sharded) {
    ShardPart part;
    part.args = args;
    part.args.a_path = std::filesystem::absolute(args.a_path).lexically_normal().string();
    part.args.b_path = std::filesystem::absolute(args.b_path).lexically_normal().string();
    part.a_given = args.a_path;
    part.b_given = args.b_path;
    part.fingerprint = fingerprint;
    part.index = args.shard.index;
    part.count = args.shard.count;
    part.candidates = e.first_pair_candidates;
    part.results = e.shard_results;
    write_part(args.out_path, part);
    if (!args.quiet)
      std::cerr << "cfgen: shard " << part.index << "/" << part.count << ": " << part.results.size() << " of "
                << part.candidates << " level-2 candidates, " << seconds << " s -> " << args.out_path << '\n';
    return 0;
  }

  nlohmann::json meta;
  nlohmann::json by_count = nlohmann::json::object(), by_type = nlohmann::json::object();
  for (const CfRecord& r : e.cfs) {
    by_count[std::to_string(r.pcs.size())] = by_count.value(std::to_string(r.pcs.size()), 0) + 1;
    for (const Pc& pc : r.pcs) by_type[to_string(pc.type)] = by_type.value(to_string(pc.type), 0) + 1;
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
                      {"found_by_neighbours", l.by_neighbours}});
  // The undecided sets, in canonical order; only the first kUndecidedListed are listed, so
  // that a pair with many keeps a file of reasonable size (the count is always exact).
  constexpr std::size_t kUndecidedListed = 100;
  nlohmann::json undecided = nlohmann::json::array();
  for (std::size_t i = 0; i < e.undecided.size() && i < kUndecidedListed; ++i)
    undecided.push_back(to_string(e.undecided[i]));
  meta["stats"] = {{"cfs", e.cfs.size()},
                   {"cfs_by_pc_count", by_count},
                   {"pcs_by_type", by_type},
                   {"transitions", e.transitions.size()},
                   {"transitions_by_kind", by_kind},
                   {"levels", levels},
                   {"symmetries", {{"A", e.symmetries_a}, {"B", e.symmetries_b}}},
                   {"min_witness_clearance_mm", e.cfs.empty() ? 0.0 : e.min_clearance},
                   {"min_witness_margin_mm", e.cfs.empty() ? 0.0 : e.min_margin},
                   {"undecided", e.undecided.size()},
                   {"undecided_sets", undecided}};
  // Timing goes to stderr, not into the file, so that the same input gives the same bytes.
  const auto& s = opt.search;
  meta["parameters"] = {{"length_scale_mm", diag},
                        {"touch_tol_rel", args.rel.touch_tol},
                        {"min_clearance_rel", args.rel.min_clearance},
                        {"good_clearance_rel", args.rel.good_clearance},
                        {"min_margin_rel", args.rel.min_margin},
                        {"touch_tol_mm", s.touch_tol},
                        {"min_clearance_mm", s.min_clearance},
                        {"good_clearance_mm", s.good_clearance},
                        {"min_margin_mm", s.min_margin},
                        {"angle_margin_rad", s.angle_margin},
                        {"theta_samples", s.theta_samples},
                        {"max_rotations", s.max_rotations},
                        {"max_pcs", opt.max_pcs},
                        {"symmetry", opt.use_symmetry}};
  if (args.thorough) meta["parameters"]["thorough"] = true;  // absent otherwise: the same bytes as before
  meta["generator"] = {{"name", "cfgen"},
                       {"a_model", args.a_label.empty() ? args.a_path : args.a_label},
                       {"b_model", args.b_label.empty() ? args.b_path : args.b_label}};
  // Coordinates are stored in mm; the unit each model file was read in (SPEC section 2).
  meta["source_units"] = {{"A", args.load_a.units}, {"B", args.load_b.units}};

  const std::size_t n_cfs = e.cfs.size(), n_tr = e.transitions.size();
  // Moved, not copied: a large graph's records and transitions are hundreds of MB.
  const CfGraph graph = CfGraph::from_parts(A, B, std::move(e.cfs), std::move(e.transitions), meta.dump());
  check_output_path(args.out_path, inputs, "writing graph");
  graph.save(args.out_path);
  if (n_cfs == 0)
    std::cerr << "cfgen: warning: the graph has no CF: A (" << A.size() << " mm across) and B (" << B.size()
              << " mm across) never touch in a valid contact formation; are the models' units right (--units)?\n";
  if (!args.quiet)
    std::cerr << "cfgen: " << n_cfs << " CFs (" << e.levels[0].valid << " + " << e.levels[1].valid
              << " + " << e.levels[2].valid << "), " << n_tr << " transitions, " << seconds
              << " s -> " << args.out_path << '\n';
  return 0;
}

}  // namespace cf::tools

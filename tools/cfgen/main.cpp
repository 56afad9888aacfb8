// cfgen: builds CF graphs (docs/spec.md, section 5b) and prints the features of a model.
//   cfgen --features MODEL                 the model object (docs/spec.md, section 5) as JSON on
//   stdout cfgen A_MODEL B_MODEL --estimate       the run predicted, on stdout cfgen A_MODEL
//   B_MODEL -o GRAPH.json    the CF graph of A against B cfgen A_MODEL B_MODEL -o GRAPH.json
//   --checkpoint DIR --shard i/K   one of K processes

#include "cfgen/execute/shard.hpp"
#include "cfgen/execute/stop.hpp"
#include "cfgen/generate.hpp"
#ifdef CF_HAVE_MPI
#include "cfgen/execute/mpi_run.hpp"
#endif
#include "cli_checks.hpp"
#include "mesh/model_loader.hpp"
#include "safe_stderr.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <exception>
#include <iostream>
#include <new>
#include <string>

namespace {

int print_features(const std::string& path, const cf::tools::LoadOptions& opt) {
  const cf::tools::MeasuredModel m = cf::tools::load_measured_model(path, opt);
  if (const std::string w = cf::tools::size_warning(m.model, "", "--units"); !w.empty())
    std::cerr << "cfgen: warning: " << w << '\n';
  nlohmann::json j = nlohmann::json::parse(cf::to_json(m.model));
  j["measures"] = {{"precision_mm", m.precision_mm},
                   {"rounding_mm", m.rounding_mm},
                   {"deviation_mm", m.deviation_mm},
                   {"coplanar_rel_tol", opt.coplanar_rel_tol},
                   {"crease_angle_deg", opt.crease_angle_deg}};
  std::cout << j.dump(2) << '\n';
  std::cout.flush();
  if (!std::cout) throw cf::Error("writing the features to stdout failed");
  return 0;
}

// The witness search's tolerances and limits (docs/generator.md explains each), added to
// `added`.
void add_search_options(CLI::App& app, cf::tools::GenerateArgs& gen,
                        std::vector<CLI::Option*>& added) {
  auto& sp = gen.search;
  // Lengths of the search are relative to the smaller model's bounding-box diagonal D, so
  // that a pair scaled by any factor gives the same graph up to scale.
  added.push_back(app.add_option("--touch-tol", gen.rel.touch_tol,
                                 "x D: element pairs closer than this touch (D: the smaller "
                                 "model's bounding-box diagonal)")
                      ->check(cf::cli::finite_range(1e-15, 1e-5))
                      ->capture_default_str());
  added.push_back(
      app.add_option("--min-clearance", gen.rel.min_clearance,
                     "x D: at a witness, every pair not part of a PC is at least this far apart")
          ->check(cf::cli::finite_range(1e-9, 0.1))
          ->capture_default_str());
  added.push_back(app.add_option("--good-clearance", gen.rel.good_clearance,
                                 "x D: stop searching a CF's witness once it is this clear")
                      ->check(cf::cli::finite_range(1e-9, 1.0))
                      ->capture_default_str());
  added.push_back(app.add_option("--min-margin", gen.rel.min_margin,
                                 "x D: contact point at least this far inside its elements")
                      ->check(cf::cli::finite_range(1e-9, 0.1))
                      ->capture_default_str());
  added.push_back(app.add_option("--angle-margin", sp.angle_margin,
                                 "rad: local non-penetration slack at each PC")
                      ->check(cf::cli::finite_range(1e-9, 0.5))
                      ->capture_default_str());
  added.push_back(app.add_option("--theta-samples", sp.theta_samples,
                                 "samples of a one-parameter rotation family")
                      ->check(CLI::Range(1, 1000))
                      ->capture_default_str());
  added.push_back(app.add_option("--max-rotations", sp.max_rotations,
                                 "rotations tried per candidate set before it is declared invalid")
                      ->check(CLI::Range(1, 10000))
                      ->capture_default_str());
}

// How the run's work is kept and shared (--shard, --checkpoint, --shard-patience,
// --no-checkpoint) and --estimate, added to `added`.
void add_run_options(CLI::App& app, cf::tools::GenerateArgs& gen, std::string& shard_text,
                     CLI::Option* out, std::vector<CLI::Option*>& added) {
  auto* shard =
      app.add_option("--shard", shard_text,
                     "compute shard i of K of every stage, taking the other shards' work from "
                     "the --checkpoint DIR they share; shard 0 writes the graph")
          ->type_name("i/K");
  auto* checkpoint =
      app.add_option("--checkpoint", gen.checkpoint_dir,
                     "keep finished work in DIR; a rerun with the same models and options "
                     "resumes from it")
          ->type_name("DIR");
  shard->needs(checkpoint);
  auto* no_checkpoint =
      app.add_flag("--no-checkpoint", gen.no_checkpoint,
                   "keep no checkpoint (by default a run predicted to take over 2 minutes "
                   "keeps one in GRAPH.json.ckpt/ until the graph is written)")
          ->excludes(checkpoint);
  auto* estimate =
      app.add_flag("--estimate", gen.estimate,
                   "print the candidate sets per level, the CFs, time and peak memory predicted "
                   "for a run (from a few sets decided), and stop")
          ->excludes(out)
          ->excludes(checkpoint)
          ->excludes(no_checkpoint)
          ->excludes(shard);
  auto* patience =
      app.add_option("--shard-patience", gen.shard_patience,
                     "seconds a shard waits at least for another shard's chunk before "
                     "computing it itself (raise it where new files take long to be seen, "
                     "e.g. NFS)")
          ->check(cf::cli::finite_range(0, 1e6))
          ->capture_default_str()
          ->needs(shard);
  auto* certificates =
      app.add_option("--certificates", gen.certificates_path,
                     "also write every failed candidate set with its outcome and the evidence "
                     "for it (docs/certificates.md)")
          ->type_name("FILE")
          ->needs(out)
          ->excludes(estimate);
  for (CLI::Option* o : {shard, checkpoint, patience, no_checkpoint, estimate, certificates})
    added.push_back(o);
}

// The decision's options (docs/generator.md, "What the search could not decide"), added to
// `added`.
void add_decision_options(CLI::App& app, cf::tools::GenerateArgs& gen,
                          std::vector<CLI::Option*>& added) {
  added.push_back(
      app.add_option("--cube-cells", gen.cube_cells,
                     "cells of rotation space each orbit of failed candidates without an f-f PC "
                     "may take to be refuted (docs/generator.md, \"Refuting a set over cells of "
                     "poses\"; 0: not searched)")
          ->check(CLI::Range(std::size_t{0}, std::size_t{10000000}))
          ->capture_default_str());
  added.push_back(
      app.add_option("--resolution", gen.resolution,
                     "rad, and in units of D in translation: the decision's cells of poses are not "
                     "split below it, and a set left with such a cell open is undecided "
                     "(docs/generator.md, \"What the search could not decide\")")
          ->check(cf::cli::finite_range(1e-9, 0.1))
          ->capture_default_str());
}

}  // namespace

int main(int argc, char** argv) {
  const cf::cli::TerminalSafeStderr safe_stderr;  // paths as typed cannot drive the terminal
  CLI::App app{
      "cfgen: contact-formation graph generator.\n"
      "  cfgen A_MODEL B_MODEL -o GRAPH.json   write the CF graph of A (moving) against B (fixed)\n"
      "  cfgen --features MODEL                print the model's features as JSON\n"
      "  cfgen A_MODEL B_MODEL --estimate      predict the graph's size, the time and the memory\n"
      "  cfgen A_MODEL B_MODEL -o GRAPH.json --checkpoint DIR --shard i/K\n"
      "                                        one of K processes that share every stage through\n"
      "                                        DIR; shard 0 writes the graph\n"
      "Models: closed, outward-oriented polyhedra in OFF, OBJ, STL or PLY (mm).",
      "cfgen"};
  app.set_version_flag("--version", cf::cli::version_text("cfgen"));
  std::string features_path;
  std::vector<std::string> models;
  cf::tools::GenerateArgs gen;
  double coplanar_tol = cf::tools::LoadOptions{}.coplanar_rel_tol;
  double crease_angle = cf::tools::LoadOptions{}.crease_angle_deg;
  std::string units = "mm", units_a, units_b;

  auto* features = app.add_option("--features", features_path,
                                  "print the features (vertices, edges, faces) of MODEL as JSON")
                       ->type_name("MODEL");
  auto* pos = app.add_option("models", models, "A_MODEL B_MODEL: the moving and the fixed object")
                  ->expected(2)
                  ->type_name("MODEL");
  auto* out =
      app.add_option("-o,--output", gen.out_path, "graph file to write")->type_name("GRAPH.json");
  auto* threads = app.add_option("-j,--threads", gen.threads, "worker threads (0: all cores)")
                      ->check(CLI::Range(0, 1024));
  auto* quiet = app.add_flag("-q,--quiet", gen.quiet, "no progress messages");
  std::string shard_text;
  std::vector<CLI::Option*> gen_opts{threads, quiet};
  add_run_options(app, gen, shard_text, out, gen_opts);
  gen_opts.push_back(app.add_option("--max-pcs", gen.max_pcs, "largest CFs to enumerate")
                         ->check(CLI::Range(1, 3))
                         ->capture_default_str());
  bool no_symmetry = false, thorough = false;
  CLI::Option* no_sym_opt =
      app.add_flag("--no-symmetry", no_symmetry,
                   "search every candidate set, not one per orbit of the models' symmetries");
  gen_opts.push_back(no_sym_opt);
  gen_opts.push_back(
      app.add_flag(
             "--thorough", thorough,
             "search every candidate set as --no-symmetry does, then add every image of each CF "
             "found under the models' symmetries: the most complete graph, at --no-symmetry's cost")
          ->excludes(no_sym_opt));
  add_search_options(app, gen, gen_opts);
  add_decision_options(app, gen, gen_opts);
  app.add_option("--coplanar-tol", coplanar_tol,
                 "coplanarity tolerance relative to the model's bounding-box diagonal")
      ->check(cf::cli::finite_range(cf::tools::kMinCoplanarTol, cf::tools::kMaxCoplanarTol));
  app.add_option("--crease-angle", crease_angle,
                 "degrees: a facet joins a face only when its normal is within this angle of the "
                 "face's (docs/features.md, \"Creases\")")
      ->type_name("DEG")
      ->check(cf::cli::finite_range(cf::tools::kMinCreaseAngle, cf::tools::kMaxCreaseAngle))
      ->capture_default_str();
  // Model units (docs/spec.md, section 2): files carry none; mm unless said otherwise.
  const auto unit_names = CLI::IsMember({"mm", "cm", "m", "in"});
  app.add_option("--units", units,
                 "length unit of every model file: mm, cm, m or in (the graph stores mm)")
      ->check(unit_names)
      ->capture_default_str();
  gen_opts.push_back(
      app.add_option("--units-a", units_a, "length unit of A_MODEL (overrides --units)")
          ->check(unit_names));
  gen_opts.push_back(
      app.add_option("--units-b", units_b, "length unit of B_MODEL (overrides --units)")
          ->check(unit_names));
  features->excludes(pos)->excludes(out);
  for (CLI::Option* o : gen_opts) features->excludes(o);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::cerr << "cfgen: " << e.what() << " (see cfgen --help)\n";
    return 2;
  }
  gen.symmetry = !no_symmetry;
  gen.thorough = thorough;
  if (const std::string why = cf::tools::conflicting_lengths(gen.rel); !why.empty()) {
    std::cerr << "cfgen: " << why << " (see cfgen --help)\n";
    return 2;
  }

  try {
    cf::tools::LoadOptions load;
    load.coplanar_rel_tol = coplanar_tol;
    load.crease_angle_deg = crease_angle;
    load.units = units;
    if (!features_path.empty()) return print_features(features_path, load);
    if (models.size() != 2) {
      std::cerr << "cfgen: expected A_MODEL B_MODEL -o GRAPH.json or --features MODEL (see cfgen "
                   "--help)\n";
      return 2;
    }
    if (gen.out_path.empty() && !gen.estimate) {
      std::cerr << "cfgen: missing -o GRAPH.json\n";
      return 2;
    }
    if (!shard_text.empty()) {
      try {
        gen.shard = cf::tools::parse_shard(shard_text);
      } catch (const cf::Error& e) {
        std::cerr << "cfgen: " << e.what() << " (see cfgen --help)\n";
        return 2;
      }
    }
    gen.a_path = models[0];
    gen.b_path = models[1];
    gen.load_a = gen.load_b = load;
    if (!units_a.empty()) gen.load_a.units = units_a;
    if (!units_b.empty()) gen.load_b.units = units_b;
#ifdef CF_HAVE_MPI
    if (cf::tools::launched_by_mpi()) {
      if (gen.shard.count > 0) {
        std::cerr
            << "cfgen: --shard is for runs outside mpirun (mpirun shares every stage itself)\n";
        return 2;
      }
      return cf::tools::run_generate_mpi(gen);
    }
#endif
    // Ctrl-C or a batch system's SIGTERM stops the run between tasks (finished chunks kept
    // with --checkpoint); a second Ctrl-C ends it at once.
    cf::gen::stop_on_signals();
    gen.stop = &cf::gen::signal_stop_flag();
    return cf::tools::run_generate(gen);
  } catch (const cf::Error& e) {
    std::cerr << "cfgen: " << e.what() << '\n';
    return 1;
  } catch (const std::bad_alloc&) {
    // Named, not "internal error: std::bad_alloc": which input asked for the memory.
    std::string what = features_path;
    for (const std::string& m : models) what += (what.empty() ? "" : "' and '") + m;
    std::cerr << "cfgen: out of memory while processing '" << what << "'\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cfgen: internal error: " << e.what() << '\n';
    return 3;
  }
}
int x;

// cfgen: builds CF graphs (SPEC section 5b) and prints the features of a model.
//   cfgen --features MODEL                 the model object (SPEC section 5) as JSON on stdout
//   cfgen A_MODEL B_MODEL -o GRAPH.json    the CF graph of A against B

#include "cfgen/generate.hpp"
#include "mesh/model_loader.hpp"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <string>

namespace {

int print_features(const std::string& path, double coplanar_tol) {
  cf::tools::LoadOptions opt;
  opt.coplanar_rel_tol = coplanar_tol;
  const cf::Polyhedron model = cf::tools::load_model(path, opt);
  std::cout << cf::to_json(model) << '\n';
  std::cout.flush();
  if (!std::cout) throw cf::Error("writing the features to stdout failed");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "cfgen: contact-formation graph generator.\n"
      "  cfgen A_MODEL B_MODEL -o GRAPH.json   write the CF graph of A (moving) against B (fixed)\n"
      "  cfgen --features MODEL                print the model's features as JSON\n"
      "Models: closed, outward-oriented polyhedra in OFF, OBJ, STL or PLY (mm).",
      "cfgen"};
  std::string features_path;
  std::vector<std::string> models;
  cf::tools::GenerateArgs gen;
  double coplanar_tol = cf::tools::LoadOptions{}.coplanar_rel_tol;

  auto* features = app.add_option("--features", features_path,
                                  "print the features (vertices, edges, faces) of MODEL as JSON")
                       ->type_name("MODEL");
  auto* pos = app.add_option("models", models, "A_MODEL B_MODEL: the moving and the fixed object")
                  ->expected(2)
                  ->type_name("MODEL");
  auto* out = app.add_option("-o,--output", gen.out_path, "graph file to write")->type_name("GRAPH.json");
  auto* threads = app.add_option("-j,--threads", gen.threads, "worker threads (0: all cores)")
                      ->check(CLI::NonNegativeNumber);
  auto* quiet = app.add_flag("-q,--quiet", gen.quiet, "no progress messages");
  app.add_option("--coplanar-tol", coplanar_tol,
                 "coplanarity tolerance relative to the model's bounding-box diagonal")
      ->check(CLI::Range(1e-12, 0.1));
  features->excludes(pos)->excludes(out)->excludes(threads)->excludes(quiet);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help
  } catch (const CLI::ParseError& e) {
    std::cerr << "cfgen: " << e.what() << " (see cfgen --help)\n";
    return 2;
  }

  try {
    if (!features_path.empty()) return print_features(features_path, coplanar_tol);
    if (models.size() != 2) {
      std::cerr << "cfgen: expected A_MODEL B_MODEL -o GRAPH.json or --features MODEL (see cfgen --help)\n";
      return 2;
    }
    if (gen.out_path.empty()) {
      std::cerr << "cfgen: missing -o GRAPH.json\n";
      return 2;
    }
    gen.a_path = models[0];
    gen.b_path = models[1];
#ifdef CF_HAVE_GENERATOR
    return cf::tools::run_generate(gen);
#else
    std::cerr << "cfgen: graph generation is not built yet\n";
    return 2;
#endif
  } catch (const cf::Error& e) {
    std::cerr << "cfgen: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cfgen: internal error: " << e.what() << '\n';
    return 3;
  }
}

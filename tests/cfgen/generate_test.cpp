// Tests of cfgen's graph generation mode (tools/cfgen/generate.cpp): the search's lengths are
// relative to the models' size, so a pair read in another unit gives the same graph up to
// that scale.

#include "cfgen/generate.hpp"
#include "scratch.hpp"

#include <cf/graph.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Witnesses agree to rounding: translations of tens of mm, computed the same way at both scales.
constexpr double kWitnessTol = 1e-9;

cf::CfGraph generate(const std::string& units, const std::string& out) {
  cf::tools::GenerateArgs args;
  args.a_path = std::string(CF_SOURCE_DIR) + "/data/models/cube.off";
  args.b_path = cf::test::write_file(
      "slab.off",
      "OFF\n8 6 0\n0 0 0\n100 0 0\n0 20 0\n100 20 0\n0 0 100\n100 0 100\n0 20 100\n100 20 100\n"
      "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n");
  args.out_path = (cf::test::scratch() / out).string();
  args.quiet = true;
  args.threads = 2;
  args.max_pcs = 2;
  args.load_a.units = args.load_b.units = units;
  REQUIRE(cf::tools::run_generate(args) == 0);
  return cf::CfGraph::load(args.out_path);
}

}  // namespace

TEST_CASE("a pair read in metres gives the graph read in mm, scaled by 1000", "[generate]") {
  const cf::CfGraph mm = generate("mm", "mm.json");
  const cf::CfGraph m = generate("m", "m.json");
  REQUIRE(mm.num_cfs() > 0);
  REQUIRE(m.num_cfs() == mm.num_cfs());
  CHECK(m.num_transitions() == mm.num_transitions());
  // Both are written in canonical order, so CF i of one is CF i of the other.
  for (std::size_t i = 0; i < m.num_cfs(); ++i) {
    const cf::CfRecord& a = mm.cf(cf::CfId(static_cast<int>(i)));
    const cf::CfRecord& b = m.cf(cf::CfId(static_cast<int>(i)));
    INFO("CF " << i << ": " << cf::to_string(a.pcs));
    REQUIRE(a.pcs == b.pcs);
    CHECK((b.witness.t_BA / 1000 - a.witness.t_BA).cwiseAbs().maxCoeff() < kWitnessTol);
    CHECK((b.witness.R_BA - a.witness.R_BA).cwiseAbs().maxCoeff() < kWitnessTol);
  }
}

TEST_CASE("a model far from its origin gives the graph it gives at its origin", "[generate]") {
  // The bundled cube moved 1e8 mm along x: a double holds its coordinates to 1.5e-8 mm, 25
  // times the default touch tolerance against the L-block (5.2e-10 mm). Its planarity
  // (4 units of rounding of 1e8 mm) raises the tolerance, so every CF is found: without it,
  // 561 of the 574 single-PC CFs and 524 of the 816 two-PC ones were.
  std::ifstream cube(std::string(CF_SOURCE_DIR) + "/data/models/cube.off");
  std::vector<std::string> lines;
  for (std::string line; std::getline(cube, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  REQUIRE(lines.size() == 16);  // OFF, the counts, 8 vertices, 6 facets
  std::string far = lines[0] + "\n" + lines[1] + "\n";
  for (std::size_t i = 2; i < 10; ++i) {
    std::istringstream in(lines[i]);
    double x = 0, y = 0, z = 0;
    in >> x >> y >> z;
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", x + 1e8, y, z);
    far += buf;
  }
  for (std::size_t i = 10; i < lines.size(); ++i) far += lines[i] + "\n";
  auto run = [](const std::string& a, const std::string& out) {
    cf::tools::GenerateArgs args;
    args.a_path = a;
    args.b_path = std::string(CF_SOURCE_DIR) + "/data/models/l_block.off";
    args.out_path = (cf::test::scratch() / out).string();
    args.quiet = true;
    args.threads = 2;
    REQUIRE(cf::tools::run_generate(args) == 0);
    return cf::CfGraph::load(args.out_path);
  };
  const cf::CfGraph at_origin = run(std::string(CF_SOURCE_DIR) + "/data/models/cube.off", "o.json");
  const cf::CfGraph moved = run(cf::test::write_file("far_cube.off", far), "far.json");
  REQUIRE(moved.num_cfs() == at_origin.num_cfs());
  for (std::size_t i = 0; i < moved.num_cfs(); ++i)
    REQUIRE(moved.cf(cf::CfId(static_cast<int>(i))).pcs ==
            at_origin.cf(cf::CfId(static_cast<int>(i))).pcs);
}

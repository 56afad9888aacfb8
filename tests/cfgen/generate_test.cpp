// Tests of cfgen's graph generation mode (tools/cfgen/generate.cpp): the search's lengths are
// relative to the models' size, so a pair read in another unit gives the same graph up to
// that scale.

#include "cfgen/generate.hpp"
#include "scratch.hpp"

#include <cf/graph.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <string>

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

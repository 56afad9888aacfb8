// Identification at unambiguous poses found by the independent oracle (issue: exact
// identification). The recall test (tests/oracle/recall_test.cpp) keeps, for each fixed seed,
// the generated pair, cfgen's graph and samples.csv: every CF the oracle realised by exact
// first contacts that the graph holds, with its pose and how far the nearest contact that is
// not another reading of its PCs is (free_clearance_mm, measured by the oracle). Where that
// is at least epsilon, exactly the CF's PCs touch and nothing else is within the detection
// band: from a cold start the run time must identify that CF. This file links libcf, not the
// oracle; the oracle's poses and PC lists are its only inputs.

#include <cf/graph.hpp>
#include <cf/servo.hpp>

#include "oracle_kept.hpp"
#include "pc_lists.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct PairResult {
  std::string dir;
  int unambiguous = 0, correct = 0;
  std::vector<std::string> wrong;  // one line each: wanted, read, pose
};

PairResult check_pair(const fs::path& dir) {
  PairResult r;
  r.dir = dir.filename().string();
  const cf::CfGraph g = cf::CfGraph::load((dir / "G.json").string());
  const cf::CfModel model(g);
  std::ifstream in(dir / "samples.csv");
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::string cell;
    std::istringstream ls(line);
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    REQUIRE(f.size() == 14);
    if (std::stod(f[1]) < model.params().epsilon_mm) continue;  // another contact within the band
    ++r.unambiguous;
    cf::Pose X;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        X.R_BA(i, j) = std::stod(f[static_cast<std::size_t>(2 + 3 * i + j)]);
      X.t_BA(i) = std::stod(f[static_cast<std::size_t>(11 + i)]);
    }
    cf::CfState state(model);  // a cold start: no previous CF
    const cf::Identification& id = cf::identify(model, state, cf::detect(model, state, X));
    const std::set<std::string> want = cf::testdata::pc_strings(f[0], ' ');
    const std::set<std::string> got = id.has_cf()
                                          ? cf::testdata::pc_strings(cf::to_string(id.pcs), ';')
                                          : std::set<std::string>{};
    if (got == want) {
      ++r.correct;
    } else {
      std::ostringstream w;
      w << "  wanted " << f[0] << ", read "
        << (id.has_cf() ? cf::to_string(id.pcs) : std::string("none")) << " ("
        << cf::to_string(id.status) << ", " << id.contacts.size() << " contacts) at R,t =";
      for (std::size_t k = 2; k < 14; ++k) w << (k == 2 ? " " : ",") << f[k];
      r.wrong.push_back(w.str());
    }
  }
  return r;
}

}  // namespace

TEST_CASE("identification from a cold start at the oracle's unambiguous poses",
          "[identify][oracle]") {
  const fs::path kept = cf::test::kept_oracle_dir(CF_ORACLE_KEEP_DIR);
  const std::vector<fs::path> dirs = cf::test::kept_oracle_pairs(kept);
  INFO("no samples in " << kept.string()
                        << ": run the recall test first (ctest runs it as a fixture)");
  REQUIRE(!dirs.empty());
  int all = 0, all_correct = 0;
  for (const fs::path& d : dirs) {
    const PairResult r = check_pair(d);
    std::cout << r.dir << ": " << r.correct << " of " << r.unambiguous
              << " unambiguous poses identified\n";
    for (const std::string& w : r.wrong) std::cout << w << "\n";
    all += r.unambiguous;
    all_correct += r.correct;
    CAPTURE(r.dir, r.correct, r.unambiguous);
    CHECK(r.unambiguous > 0);
    // Every one: the seeds are fixed and the detection reads an unambiguous pose exactly
    // (3,733 of 3,733 here, 37,381 of 37,381 in identify_unambiguous_oracle_test), so a
    // single miss is a regression, not noise. The pose is printed above.
    CHECK(r.correct == r.unambiguous);
  }
  std::cout << "all pairs: " << all_correct << " of " << all << "\n";
  CHECK(all_correct == all);
}

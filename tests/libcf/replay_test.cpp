// The replay engine (cf/replay.hpp, libcf/src/replay): POSES.csv read a buffer at a time with
// file and line in every error, the engine against the renderer stepped by hand, and its CSV.

#include <cf/graph.hpp>
#include <cf/renderer.hpp>
#include <cf/replay.hpp>

#include "scratch.hpp"
#include "trajectories.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

const std::string kHeader = "t,tx,ty,tz,qw,qx,qy,qz\n";

std::vector<cf::TrajectorySample> read_text(const std::string& text, const std::string& source) {
  cf::TrajectoryCsvReader reader(text, source);
  std::vector<cf::TrajectorySample> out;
  cf::TrajectorySample s;
  while (reader.next(s)) out.push_back(s);
  return out;
}

const cf::CfGraph& cube_l_block() {
  static const cf::CfGraph g =
      cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json");
  return g;
}

}  // namespace

TEST_CASE("trajectory CSV: rows that are not poses are refused with file and line", "[replay]") {
  const std::string& h = kHeader;
  const auto rows = read_text(h + "0,1,2,3,1,0,0,0\n# comment\n\n0.001,1,2,3,0,0,0,1\n", "p.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[1].line == 5);
  CHECK(rows[1].X_WD.R_BA(0, 0) == Approx(-1));  // 180 degrees about z

  CHECK_THROWS_WITH(read_text("t,x,y,z,qw,qx,qy,qz\n", "p.csv"),
                    Catch::Contains("p.csv:1: expected the header 't,tx,ty,tz,qw,qx,qy,qz'"));
  CHECK_THROWS_WITH(read_text(h + "0,1,2,3,1,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: expected 8 columns") && Catch::Contains("found 7"));
  CHECK_THROWS_WITH(read_text(h + "0,1,2,3,1,0,0,0\n0.1,1,abc,3,1,0,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:3: column 'ty' is not a finite number: 'abc'"));
  CHECK_THROWS_WITH(read_text(h + "0,1,2,nan,1,0,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: column 'tz' is not a finite number"));
  CHECK_THROWS_WITH(read_text(h + "0,0x10,2,3,1,0,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: column 'tx' is not a decimal number: '0x10'"));
  CHECK_THROWS_WITH(read_text(h + "0,1,2,3,1,0.1,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: the quaternion (qw,qx,qy,qz) has norm 1.00498756"));
  CHECK_THROWS_WITH(
      read_text(h + "0.5,1,2,3,1,0,0,0\n0.5,1,2,3,1,0,0,0\n", "p.csv"),
      Catch::Contains("p.csv:3: time 0.5 s does not increase (previous row, line 2: 0.5 s)"));
  CHECK_THROWS_WITH(read_text("", "p.csv"), Catch::Contains("p.csv:1: empty file"));
  CHECK_THROWS_WITH(read_text(h, "p.csv"),
                    Catch::Contains("p.csv:1: no pose rows after the header"));
  CHECK_THROWS_WITH(
      cf::TrajectoryCsvReader::open("/nonexistent/poses.csv"),
      Catch::Contains("/nonexistent/poses.csv: cannot open the trajectory: no such file"));
  CHECK_THROWS_WITH(cf::TrajectoryCsvReader::open(cf::test::scratch().string()),
                    Catch::Contains("is a directory, not a regular file"));
  // A quaternion within the tolerance is accepted and normalised; the last line may lack its
  // line break; spaces and carriage returns around fields are taken.
  const auto near_unit = read_text(h + "0,1,2,3,1.0000005,0,0,0\n1, 4 ,5,6,1,0,0,0\r", "p.csv");
  REQUIRE(near_unit.size() == 2);
  CHECK(near_unit[0].q[0] == 1.0000005);
  CHECK(near_unit[0].X_WD.R_BA.determinant() == Approx(1).margin(1e-15));
  CHECK(near_unit[1].X_WD.t_BA.x() == 4);
}

TEST_CASE("trajectory CSV from a file: the same samples as from memory, a buffer at a time",
          "[replay]") {
  // 20,000 rows (about 1.3 MB) cross the reader's 64 KiB buffer many times, lines split at
  // every offset.
  std::string text = "# written by a test\n" + kHeader;
  for (int i = 0; i < 20000; ++i) {
    char row[160];
    std::snprintf(row, sizeof row, "%.6f,%.9g,%.9g,%.9g,%.12f,0,%.12f,0\n", 0.001 * i, 0.5 * i,
                  -3.25 + 1e-4 * i, 1e3, std::cos(1e-4 * i), std::sin(1e-4 * i));
    text += row;
  }
  const std::string path = cf::test::write_file("long.csv", text);
  const auto from_memory = read_text(text, path);
  cf::TrajectoryCsvReader reader = cf::TrajectoryCsvReader::open(path);
  cf::TrajectorySample s;
  std::size_t n = 0, differ = 0;
  while (reader.next(s)) {
    REQUIRE(n < from_memory.size());
    const cf::TrajectorySample& m = from_memory[n++];
    differ += s.t_s != m.t_s || s.X_WD.t_BA != m.X_WD.t_BA || s.X_WD.R_BA != m.X_WD.R_BA ||
              s.line != m.line;
  }
  CHECK(n == 20000);
  CHECK(differ == 0);
  CHECK(from_memory.back().line == 20002);

  // A line of 100 kB is no pose row: refused with its line, before it is all held.
  const std::string wide = cf::test::write_file("wide.csv", kHeader + std::string(100000, '1'));
  cf::TrajectoryCsvReader w = cf::TrajectoryCsvReader::open(wide);
  CHECK_THROWS_WITH(w.next(s), Catch::Contains(wide + ":2: a line longer than 65536 bytes"));
}

TEST_CASE("the replay engine gives the renderer's result at every tick", "[replay]") {
  const cf::CfGraph& g = cube_l_block();
  const auto samples = cf::testdata::read_samples(std::string(CF_SOURCE_DIR) +
                                                  "/data/trajectories/cube_lblock_corner.csv");
  cf::HapticRenderer by_hand(g);
  cf::TrajectorySamples source(samples);
  cf::Replay replay(g, cf::Params(), source);
  cf::ReplayRow row;
  long ticks = 0, in_contact = 0;
  while (replay.next(row)) {
    const cf::TrajectorySample& s = samples[static_cast<std::size_t>(ticks++)];
    const cf::HapticResult& r = by_hand.step(s.X_WD, s.t_s);
    // Bit for bit: the engine is the renderer, stepped at the same poses and times.
    CHECK(row.t_s == s.t_s);
    CHECK(row.F_W == r.F_W);
    CHECK(row.M_W == r.M_W);
    CHECK(row.cf == (r.cf.valid() ? r.cf.value() : -1));
    CHECK(row.X_WD.t_BA == s.X_WD.t_BA);
    CHECK(replay.result().F_W == r.F_W);
    in_contact += row.status != "no_contact";
  }
  CHECK(ticks == static_cast<long>(samples.size()));
  CHECK(replay.ticks() == ticks);
  CHECK(in_contact > 100);
  CHECK_FALSE(replay.next(row));  // stays at the end
}

TEST_CASE("the replay engine refuses a source whose time does not increase", "[replay]") {
  std::vector<cf::TrajectorySample> samples(3);
  for (int i = 0; i < 3; ++i) samples[static_cast<std::size_t>(i)].X_WD.t_BA = {70, 80, 40};
  samples[0].t_s = 0;
  samples[1].t_s = 0.001;
  samples[2].t_s = 0.001;
  cf::TrajectorySamples source(samples);
  cf::Replay replay(cube_l_block(), cf::Params(), source);
  cf::ReplayRow row;
  CHECK(replay.next(row));
  CHECK(replay.next(row));
  CHECK_THROWS_WITH(replay.next(row),
                    Catch::Contains("sample 3 (t = 0.001 s): time does not increase (previous "
                                    "sample: 0.001 s)"));
  cf::Params bad;
  bad.mu_static = -1;
  CHECK_THROWS_AS(cf::Replay(cube_l_block(), bad, source), cf::Error);
}

TEST_CASE("replay CSV rows: times round-trip, wrenches to 9 digits, one line each", "[replay]") {
  cf::ReplayRow row;
  row.t_s = 1e-7 * 3;
  row.cf = 4;
  row.pcs = "f-f:2:4";
  row.motion = "MT2.a";
  row.F_W = cf::Vec3(1.0 / 3, -2, 0);
  row.status = "ok";
  std::string line;
  cf::append_csv(row, line);
  CHECK(line.rfind("3e-07,4,f-f:2:4,MT2.a,0.333333333,-2,0,", 0) == 0);
  CHECK(line.find('\n') == std::string::npos);
  // As many fields as the header names.
  const std::string header = cf::replay_csv_header();
  CHECK(std::count(line.begin(), line.end(), ',') == std::count(header.begin(), header.end(), ','));
  CHECK(line.find(",ok,,0,0,0,1.000000000000,0.000000000000,") != std::string::npos);
}

// cfreplay: trajectory CSV errors, servo-rate independence, friction bounds and the moment
// recomputed independently over whole trajectories, and the program end to end.

#include "replay_io.hpp"
#include "replay_run.hpp"

#include <cf/renderer.hpp>

#include "fixtures.hpp"
#include "runtime_models.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

namespace {

using cf::test::from_loops;

const std::vector<cf::Vec3> kCubeVertices = {{-15, -15, -15}, {15, -15, -15}, {15, 15, -15},
                                             {-15, 15, -15},  {-15, -15, 15}, {15, -15, 15},
                                             {15, 15, 15},    {-15, 15, 15}};

// The cube and the L-block of data/models, with the floor, wall and corner CFs.
cf::CfGraph corner_graph() {
  const cf::Polyhedron cube = from_loops(
      "cube", kCubeVertices,
      {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}});
  const cf::Polyhedron l = cf::testmodels::l_block();
  const cf::Pc floor{cf::PcType::kFF, 2, 4}, wall{cf::PcType::kFF, 5, 5};
  std::vector<cf::CfRecord> cfs(3);
  cfs[0].pcs = cf::PcSet({floor});
  cfs[0].witness.t_BA = {70, 35, 40};
  cfs[1].pcs = cf::PcSet({wall});
  cfs[1].witness.t_BA = {35, 60, 40};
  cfs[2].pcs = cf::PcSet({floor, wall});
  cfs[2].witness.t_BA = {35, 35, 40};
  std::vector<cf::Transition> tr = {{cf::CfId(0), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(0), cf::TransitionKind::kLose},
                                    {cf::CfId(1), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(1), cf::TransitionKind::kLose}};
  return cf::CfGraph::from_parts(cube, l, std::move(cfs), std::move(tr));
}

// A scripted trajectory (positions of the cube's centre, identity rotation) sampled at
// `rate`: land on the floor at 20 mm/s, rest, slide 20 mm in -x at 20 mm/s with a little z,
// stop, slide into the inner corner, rest.
std::vector<cf::replay::Sample> scripted(double rate) {
  struct Key {
    double t;
    cf::Vec3 p;
  };
  const std::vector<Key> keys = {
      {0.0, {70, 40, 40}},   {0.225, {70, 35.5, 40}}, {0.3, {70, 35.5, 40}},  {1.3, {50, 35.5, 42}},
      {1.5, {50, 35.5, 42}}, {2.2, {35.5, 35.5, 42}}, {2.4, {35.5, 35.5, 42}}};
  std::vector<cf::replay::Sample> out;
  const long n = std::lround(keys.back().t * rate);
  std::size_t k = 0;
  for (long i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / rate;
    while (k + 2 < keys.size() && t > keys[k + 1].t) ++k;
    const double s = std::min(1.0, std::max(0.0, (t - keys[k].t) / (keys[k + 1].t - keys[k].t)));
    cf::replay::Sample smp;
    smp.t = t;
    smp.pose.t_BA = keys[k].p + s * (keys[k + 1].p - keys[k].p);
    out.push_back(smp);
  }
  return out;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("trajectory CSV: rows that are not poses are rejected with file and line", "[cfreplay]") {
  using cf::replay::parse_trajectory;
  const std::string h = "t,tx,ty,tz,qw,qx,qy,qz\n";
  const auto rows =
      parse_trajectory(h + "0,1,2,3,1,0,0,0\n# comment\n\n0.001,1,2,3,0,0,0,1\n", "p.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[1].line == 5);
  CHECK(rows[1].pose.R_BA(0, 0) == Approx(-1));  // 180 degrees about z

  CHECK_THROWS_WITH(parse_trajectory("t,x,y,z,qw,qx,qy,qz\n", "p.csv"),
                    Catch::Contains("p.csv:1: expected the header 't,tx,ty,tz,qw,qx,qy,qz'"));
  CHECK_THROWS_WITH(parse_trajectory(h + "0,1,2,3,1,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: expected 8 columns") && Catch::Contains("found 7"));
  CHECK_THROWS_WITH(parse_trajectory(h + "0,1,2,3,1,0,0,0\n0.1,1,abc,3,1,0,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:3: column 'ty' is not a finite number: 'abc'"));
  CHECK_THROWS_WITH(parse_trajectory(h + "0,1,2,nan,1,0,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: column 'tz' is not a finite number"));
  CHECK_THROWS_WITH(parse_trajectory(h + "0,1,2,3,1,0.1,0,0\n", "p.csv"),
                    Catch::Contains("p.csv:2: the quaternion (qw,qx,qy,qz) has norm 1.00498756"));
  CHECK_THROWS_WITH(
      parse_trajectory(h + "0.5,1,2,3,1,0,0,0\n0.5,1,2,3,1,0,0,0\n", "p.csv"),
      Catch::Contains("p.csv:3: time 0.5 s does not increase (previous row, line 2: 0.5 s)"));
  CHECK_THROWS_WITH(parse_trajectory("", "p.csv"), Catch::Contains("p.csv:1: empty file"));
  CHECK_THROWS_WITH(parse_trajectory(h, "p.csv"),
                    Catch::Contains("p.csv:1: no pose rows after the header"));
  CHECK_THROWS_WITH(cf::replay::read_trajectory("/nonexistent/poses.csv"),
                    Catch::Contains("/nonexistent/poses.csv: cannot open the trajectory"));
  // A quaternion within the tolerance is accepted and normalised.
  CHECK_NOTHROW(parse_trajectory(h + "0,1,2,3,1.0000005,0,0,0\n", "p.csv"));
}

TEST_CASE("forces do not depend on the servo rate (stick anchors)", "[cfreplay]") {
  const cf::CfGraph g = corner_graph();
  const cf::Params P;
  const auto slow = cf::replay::run(g, scripted(1000), P);
  const auto fast = cf::replay::run(g, scripted(10000), P);
  REQUIRE(fast.size() == 10 * (slow.size() - 1) + 1);
  // Same pose, same state => same force, up to the round-off of accumulating ten times as
  // many ticks: 1e-9 N and 1e-7 N mm (moment arms ~50 mm).
  int compared = 0, mismatched = 0;
  std::set<std::string> motions;
  for (std::size_t i = 0; i < slow.size(); ++i) {
    const cf::replay::Row& a = slow[i];
    const cf::replay::Row& b = fast[10 * i];
    REQUIRE(a.t == Approx(b.t).margin(1e-12));
    ++compared;
    motions.insert(a.motion);
    const bool same =
        a.cf == b.cf && (a.F_W - b.F_W).norm() < 1e-9 && (a.M_W - b.M_W).norm() < 1e-7;
    if (!same) {
      ++mismatched;
      // The only allowed differences: the tick at which the faster loop sees the contact
      // (it touches earlier, so one 1 kHz tick is MT1 where 10 kHz is already MT2).
      INFO("t = " << a.t << " 1kHz " << a.motion << " F " << a.F_W.transpose() << " | 10kHz "
                  << b.motion << " F " << b.F_W.transpose());
      CHECK((a.motion == "MT1" || a.motion == "MT4"));
    }
  }
  CHECK(compared == 2401);
  CHECK(mismatched <= 2);
  CHECK(motions.count("MT2.c"));  // the slide was kinetic at some point
  CHECK(motions.count("MT4"));
}

TEST_CASE("over whole trajectories: friction <= mu F_cy, and F and M recomputed independently",
          "[cfreplay]") {
  const cf::CfGraph g = corner_graph();
  const cf::Params P;
  // The vertex mean of the cube, computed here from its vertex list.
  cf::Vec3 pg_A = cf::Vec3::Zero();
  for (const cf::Vec3& v : kCubeVertices) pg_A += v / 8.0;
  std::vector<std::vector<cf::replay::Sample>> trajectories = {scripted(1000)};
  for (const char* name :
       {"cube_lblock_guarded.csv", "cube_lblock_slide.csv", "cube_lblock_corner.csv",
        "cube_lblock_rotate.csv", "cube_lblock_break.csv"}) {
    trajectories.push_back(
        cf::replay::read_trajectory(std::string(CF_SOURCE_DIR) + "/data/trajectories/" + name));
  }
  long pcs_checked = 0, ticks = 0;
  for (const auto& traj : trajectories) {
    cf::replay::run(g, traj, P, [&](const cf::replay::Sample& s, const cf::HapticResult& r) {
      ++ticks;
      const cf::Vec3 Fg(0, -0.5 * 9.8, 0);
      cf::Vec3 F = Fg;
      const cf::Vec3 o = s.pose.t_BA;  // moments about A's origin
      cf::Vec3 M = (s.pose.apply(pg_A) - o).cross(Fg);
      // The PCs and the approaching contacts: each pushes by eq. (1) and adds to the totals.
      for (int k = 0; k < r.force->num_pcs + r.force->num_approaching; ++k) {
        const cf::PcForce& f = r.force->pcs[k];
        const cf::Vec3 normal = f.R_WT.col(1);
        const double fn = f.F_W.dot(normal);
        const double ft = (f.F_W - fn * normal).norm();
        CHECK(fn == Approx(2.3 * (1.0 - f.distance)).margin(1e-9));
        CHECK(ft <= 0.7 * fn * (1 + 1e-12) + 1e-12);
        F += f.F_W;
        M += (f.centre_W - o).cross(f.F_W);  // where its plane's force acts
        ++pcs_checked;
      }
      CHECK((r.F_W - F).norm() < 1e-9);
      CHECK((r.M_W - M).norm() < 1e-7);
      CHECK((r.M_A - s.pose.R_BA.transpose() * M).norm() < 1e-7);
    });
  }
  CHECK(ticks > 9000);
  CHECK(pcs_checked > 5000);
}

#ifdef CF_CFREPLAY
TEST_CASE("cfreplay end to end: output, plot, and a bad row leaves no output", "[cfreplay]") {
  const std::string dir = std::string(CF_TEST_TMP_DIR);
  const std::string graph = dir + "/replay_graph.json";
  corner_graph().save(graph);
  const std::string out = dir + "/replay_out.csv", svg = dir + "/replay_out.svg";
  std::remove(out.c_str());
  std::remove(svg.c_str());
  const std::string traj = std::string(CF_SOURCE_DIR) + "/data/trajectories/cube_lblock_corner.csv";
  const std::string cmd = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " + traj +
                          " -o " + out + " --plot " + svg + " 2>" + dir + "/replay_err.txt";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string text = slurp(out);
  CHECK(text.rfind("t,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz,", 0) == 0);
  CHECK(text.find(",2,f-f:2:4;f-f:5:5,MT2.b,") != std::string::npos);  // sliding along the corner
  CHECK(slurp(svg).find("<svg") == 0);

  const std::string bad = dir + "/replay_bad.csv", out2 = dir + "/replay_out2.csv";
  std::ofstream(bad) << "t,tx,ty,tz,qw,qx,qy,qz\n0,70,40,40,1,0,0,0\n0.001,70,40,40,2,0,0,0\n";
  std::remove(out2.c_str());
  const std::string cmd2 = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " + bad +
                           " -o " + out2 + " 2>" + dir + "/replay_err2.txt";
  CHECK(std::system(cmd2.c_str()) != 0);
  CHECK(slurp(dir + "/replay_err2.txt").find("cfreplay: " + bad + ":3: the quaternion") == 0);
  CHECK_FALSE(std::ifstream(out2).good());

  // The moment about a point of A the user names; a point reference without the point is
  // refused before anything runs.
  const std::string out3 = dir + "/replay_out3.csv";
  const std::string cmd3 = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " +
                           traj + " -o " + out3 + " --moment-point 0 -15 0 2>" + dir +
                           "/replay_err3.txt";
  REQUIRE(std::system(cmd3.c_str()) == 0);
  CHECK(slurp(out3) != text);  // other moments, same forces
  const std::string cmd4 = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " +
                           traj + " -o " + dir + "/replay_out4.csv --moment-ref point 2>" + dir +
                           "/replay_err4.txt";
  CHECK(std::system(cmd4.c_str()) != 0);
  CHECK(slurp(dir + "/replay_err4.txt")
            .find("cfreplay: --moment-ref point needs --moment-point X Y Z") == 0);
  CHECK_FALSE(std::ifstream(dir + "/replay_out4.csv").good());
}

TEST_CASE("cfreplay --proxy: a device pressing 10 mm into the floor keeps its CF and its push",
          "[cfreplay]") {
  const std::string dir = std::string(CF_TEST_TMP_DIR);
  const std::string graph = std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json";
  const std::string traj = std::string(CF_SOURCE_DIR) + "/data/trajectories/cube_lblock_press.csv";
  const std::vector<cf::replay::Sample> device = cf::replay::read_trajectory(traj);
  // Columns by name, rows as fields.
  auto table = [](const std::string& text) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::string cell;
      std::istringstream ls(line);
      while (std::getline(ls, cell, ',')) f.push_back(cell);
      rows.push_back(f);
    }
    return rows;
  };
  auto column = [](const std::vector<std::string>& header, const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    return static_cast<std::size_t>(it - header.begin());
  };
  for (const char* mode : {"on", "off"}) {
    const std::string out = dir + "/replay_press_" + mode + ".csv";
    const std::string cmd = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " +
                            traj + " -o " + out + " --proxy " + mode + " 2>" + dir +
                            "/replay_press_err.txt";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const auto rows = table(slurp(out));
    REQUIRE(rows.size() == device.size() + 1);
    const auto& h = rows[0];
    const std::size_t cf = column(h, "cf"), fy = column(h, "Fy"), py = column(h, "proxy_ty"),
                      fcy = column(h, "Fcy");
    int inside = 0, without_cf = 0, deeper_and_weaker = 0;
    double last_depth = -1, last_fy = -1e9;
    for (std::size_t i = 0; i < device.size(); ++i) {
      const auto& r = rows[i + 1];
      const double depth =
          35 - device[i].pose.t_BA.y();  // mm the device is below the touching pose
      if (depth <= 0) continue;
      ++inside;
      without_cf += r[cf] == "-1" ? 1 : 0;
      if (std::string(mode) == "on") {
        CHECK(std::stod(r[py]) >= 35 - 0.01);  // the proxy stays on the floor (delta)
        // Going down, the push grows with depth.
        if (depth > last_depth + 1e-9 && last_depth > 0 && std::stod(r[fy]) < last_fy)
          ++deeper_and_weaker;
        CHECK(std::stod(r[fcy]) > 0);
      }
      last_depth = depth;
      last_fy = std::stod(r[fy]);
    }
    CHECK(inside > 1500);
    if (std::string(mode) == "on") {
      CHECK(without_cf == 0);
      CHECK(deeper_and_weaker == 0);
    } else {
      CHECK(without_cf > inside * 9 / 10);  // deeper than 1 mm the literal model sees nothing
    }
  }
}
#endif

// cfreplay: servo-rate independence, friction bounds and the moment
// recomputed independently over whole trajectories, and the program end to end.

#include "plot.hpp"

#include <cf/renderer.hpp>
#include <cf/replay.hpp>

#include "fixtures.hpp"
#include "runtime_models.hpp"
#include "trajectories.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
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
std::vector<cf::TrajectorySample> scripted(double rate) {
  struct Key {
    double t;
    cf::Vec3 p;
  };
  const std::vector<Key> keys = {
      {0.0, {70, 40, 40}},   {0.225, {70, 35.5, 40}}, {0.3, {70, 35.5, 40}},  {1.3, {50, 35.5, 42}},
      {1.5, {50, 35.5, 42}}, {2.2, {35.5, 35.5, 42}}, {2.4, {35.5, 35.5, 42}}};
  std::vector<cf::TrajectorySample> out;
  const long n = std::lround(keys.back().t * rate);
  std::size_t k = 0;
  for (long i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / rate;
    while (k + 2 < keys.size() && t > keys[k + 1].t) ++k;
    const double s = std::min(1.0, std::max(0.0, (t - keys[k].t) / (keys[k + 1].t - keys[k].t)));
    cf::TrajectorySample smp;
    smp.t_s = t;
    smp.X_WD.t_BA = keys[k].p + s * (keys[k + 1].p - keys[k].p);
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

TEST_CASE("forces do not depend on the servo rate (stick anchors)", "[cfreplay]") {
  const cf::CfGraph g = corner_graph();
  const cf::Params P;
  const auto slow = cf::testdata::replay_rows(g, scripted(1000), P);
  const auto fast = cf::testdata::replay_rows(g, scripted(10000), P);
  REQUIRE(fast.size() == 10 * (slow.size() - 1) + 1);
  // Same pose, same state => same force, up to the round-off of accumulating ten times as
  // many ticks: 1e-9 N and 1e-7 N mm (moment arms ~50 mm).
  int compared = 0, mismatched = 0;
  std::set<std::string> motions;
  for (std::size_t i = 0; i < slow.size(); ++i) {
    const cf::ReplayRow& a = slow[i];
    const cf::ReplayRow& b = fast[10 * i];
    REQUIRE(a.t_s == Approx(b.t_s).margin(1e-12));
    ++compared;
    motions.insert(a.motion);
    const bool same =
        a.cf == b.cf && (a.F_W - b.F_W).norm() < 1e-9 && (a.M_W - b.M_W).norm() < 1e-7;
    if (!same) {
      ++mismatched;
      // The only allowed differences: the tick at which the faster loop sees the contact
      // (it touches earlier, so one 1 kHz tick is MT1 where 10 kHz is already MT2).
      INFO("t = " << a.t_s << " 1kHz " << a.motion << " F " << a.F_W.transpose() << " | 10kHz "
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
  std::vector<std::vector<cf::TrajectorySample>> trajectories = {scripted(1000)};
  for (const char* name :
       {"cube_lblock_guarded.csv", "cube_lblock_slide.csv", "cube_lblock_corner.csv",
        "cube_lblock_rotate.csv", "cube_lblock_break.csv"}) {
    trajectories.push_back(
        cf::testdata::read_samples(std::string(CF_SOURCE_DIR) + "/data/trajectories/" + name));
  }
  long pcs_checked = 0, ticks = 0;
  for (const auto& traj : trajectories) {
    cf::testdata::replay_rows(
        g, traj, P, [&](const cf::TrajectorySample& s, const cf::HapticResult& r) {
          ++ticks;
          const cf::Vec3 Fg(0, -0.5 * 9.8, 0);
          cf::Vec3 F = Fg;
          const cf::Vec3 o = s.X_WD.t_BA;  // moments about A's origin
          cf::Vec3 M = (s.X_WD.apply(pg_A) - o).cross(Fg);
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
          CHECK((r.M_A - s.X_WD.R_BA.transpose() * M).norm() < 1e-7);
        });
  }
  CHECK(ticks > 9000);
  CHECK(pcs_checked > 5000);
}

namespace {

// A row of a made-up replay: CF `cf` with `pcs`, motion `motion`, a force of `fy` N.
cf::ReplayRow made_row(double t, int cf, const std::string& pcs, const std::string& motion,
                       double fy) {
  cf::ReplayRow r;
  r.t_s = t;
  r.cf = cf;
  r.pcs = pcs;
  r.motion = motion;
  r.F_W = cf::Vec3(0, fy, 0);
  r.Fc_W = cf::Vec3(0, 3 * fy, 0);     // the contact force runs past the rendered one's range
  r.X_WD.t_BA = cf::Vec3(0, -2.5, 0);  // the device 2.5 mm beyond the proxy
  return r;
}

}  // namespace

TEST_CASE("the plot: every event marked, bands named by their PCs, lines clipped, legend inside",
          "[cfreplay]") {
  cf::replay::PlotRecorder plot;
  const std::string corner = "f-f:2:4;f-f:5:5";
  for (int i = 0; i < 10000; ++i) {
    const double t = 0.001 * i;
    const double fy = i == 7000 ? 50 : 5 * std::sin(0.01 * i);
    if (i == 100)
      plot.add(made_row(t, 0, "f-f:2:4", "MT1", fy));  // one tick of each event
    else if (i == 5000)
      plot.add(made_row(t, 0, "f-f:2:4", "MT3", fy));
    else
      plot.add(made_row(t, 2, corner, "MT2.b", fy));
  }
  const std::string svg = plot.svg("made up");
  // Each one-tick event has its mark, named with its motion type and the span of the bin
  // holding it (10,000 ticks in at most 2,048 bins).
  const auto marked_at = [&svg](const std::string& type, double t) {
    const std::regex mark("<title>" + type + " between ([0-9.]+) and ([0-9.]+) s</title>");
    int n = 0;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), mark); it != std::sregex_iterator();
         ++it)
      n += std::stod((*it)[1].str()) <= t && t <= std::stod((*it)[2].str());
    return n;
  };
  CHECK(marked_at("MT1", 0.1) == 1);
  CHECK(marked_at("MT3", 5.0) == 1);
  // Bands say which contacts they are.
  CHECK(svg.find(">CF 2 MT2.b f-f:2:4;f-f:5:5</text>") != std::string::npos);
  // Every line is clipped to its panel, and there are three panels.
  const auto count = [&svg](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = svg.find(what); at != std::string::npos; at = svg.find(what, at + 1)) ++n;
    return n;
  };
  CHECK(count("<polyline") == 13);
  CHECK(count("<polyline clip-path=\"url(#panel") == 13);
  CHECK(count("<clipPath id=\"panel") == 3);
  CHECK(svg.find("beyond the proxy (mm)") != std::string::npos);
  // The one-tick spike of 50 N survives the binning: the force axis reaches it.
  CHECK(svg.find(">150</text>") != std::string::npos);  // 3 x 50 N, the contact force
  // Legend entries end inside the figure (1100 px wide, 20 px right margin), at the width the
  // layout assumes per glyph.
  const std::regex legend_text("<text x=\"([0-9.]+)\" y=\"[0-9.]+\">([^<]+)</text>");
  int legend = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), legend_text);
       it != std::sregex_iterator(); ++it) {
    const double x = std::stod((*it)[1].str());
    CHECK(x + 6.5 * static_cast<double>((*it)[2].length()) <= 1080 + 1e-9);
    ++legend;
  }
  CHECK(legend >= 10);
}

TEST_CASE("the plot's memory is bounded: a CF change at every tick of a million", "[cfreplay]") {
  cf::replay::PlotRecorder plot;
  for (int i = 0; i < 1000000; ++i)
    plot.add(made_row(1e-3 * i, i % 2, i % 2 ? "f-f:2:4" : "e-f:1:3", i % 3 ? "MT2.a" : "MT4", 1));
  const std::string svg = plot.svg("a million ticks");
  // At most kMaxBands bands in each of 3 panels, kBins points per line: a few MB, whatever
  // the length.
  CHECK(svg.size() < 8'000'000);
  CHECK(svg.find("several CFs") != std::string::npos);
  CHECK(svg.find(" and 999.999 s</title>") != std::string::npos);  // events to the last tick
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
                           traj + " -o " + out3 + " --moment-point-A 0 -15 0 2>" + dir +
                           "/replay_err3.txt";
  REQUIRE(std::system(cmd3.c_str()) == 0);
  CHECK(slurp(out3) != text);  // other moments, same forces
  const std::string cmd4 = std::string(CF_CFREPLAY) + " --graph " + graph + " --trajectory " +
                           traj + " -o " + dir + "/replay_out4.csv --moment-reference a_point 2>" +
                           dir + "/replay_err4.txt";
  CHECK(std::system(cmd4.c_str()) != 0);
  CHECK(slurp(dir + "/replay_err4.txt")
            .find("cfreplay: --moment-reference a_point needs --moment-point-A X Y Z") == 0);
  CHECK_FALSE(std::ifstream(dir + "/replay_out4.csv").good());
}

TEST_CASE("cfreplay --proxy: a device pressing 10 mm into the floor keeps its CF and its push",
          "[cfreplay]") {
  const std::string dir = std::string(CF_TEST_TMP_DIR);
  const std::string graph = std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json";
  const std::string traj = std::string(CF_SOURCE_DIR) + "/data/trajectories/cube_lblock_press.csv";
  const std::vector<cf::TrajectorySample> device = cf::testdata::read_samples(traj);
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
          35 - device[i].X_WD.t_BA.y();  // mm the device is below the touching pose
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

TEST_CASE("the plot takes rows whose times do not increase (no replay gives them)", "[cfreplay]") {
  // Repeated and earlier times land in the first bin instead of dividing by a zero bin width.
  cf::replay::PlotRecorder plot;
  for (double t : {1.0, 1.0, 0.5, 2.0, 2.0, 3.0}) plot.add(made_row(t, 1, "f-f:2:4", "MT2.a", t));
  const std::string svg = plot.svg("odd times");
  CHECK(svg.rfind("<svg", 0) == 0);
  CHECK(svg.find("CF 1 MT2.a f-f:2:4") != std::string::npos);
}

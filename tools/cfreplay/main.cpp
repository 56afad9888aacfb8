// cfreplay: runs the run-time loop (detect, identify, classify, force) over a trajectory of A
// and writes one row per servo tick (docs/spec.md, section 5b).
//   cfreplay --graph GRAPH.json --trajectory POSES.csv -o OUT.csv [--plot OUT.svg]

#include "plot.hpp"

#include <cf/file_io.hpp>
#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/replay.hpp>

#include "cli_checks.hpp"
#include "safe_stderr.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace {

// The options given as words, and which of the related ones were given.
struct Choices {
  std::string friction, moment_ref, centroid, proxy;
  std::vector<double> moment_point;
  bool moment_ref_given, mu_given, mu_d_given;
};

std::string with_default(double v, bool given) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g%s", v, given ? "" : " (the default)");
  return buf;
}

// The choices in P, and the options that contradict each other refused before the work
// (docs/bad-input.md, "Options checked together"): empty, or why.
std::string apply_choices(const Choices& c, cf::Params& P) {
  P.proxy.enabled = c.proxy == "on";
  P.friction_displacement = c.friction == "per-tick" ? cf::FrictionDisplacement::kPerTick
                                                     : cf::FrictionDisplacement::kStickAnchor;
  P.centroid =
      c.centroid == "volume" ? cf::CentroidChoice::kVolume : cf::CentroidChoice::kVertexMean;
  P.moment_reference =
      c.moment_ref == "centroid" ? cf::MomentReference::kACentroid : cf::MomentReference::kAOrigin;
  if (!c.moment_point.empty()) {
    if (c.moment_ref_given && c.moment_ref != "point")
      return "--moment-ref " + c.moment_ref +
             " contradicts --moment-point, which sets the moment's reference point; give one";
    P.moment_reference = cf::MomentReference::kAPoint;
    P.moment_point_A = cf::Vec3(c.moment_point[0], c.moment_point[1], c.moment_point[2]);
  } else if (c.moment_ref == "point") {
    return "--moment-ref point needs --moment-point X Y Z";
  }
  if (P.mu_kinetic > P.mu_static)
    return "--mu-d " + with_default(P.mu_kinetic, c.mu_d_given) + " is above --mu " +
           with_default(P.mu_static, c.mu_given) +
           ": kinetic friction cannot exceed static friction; give --mu-d at most --mu";
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  const cf::cli::TerminalSafeStderr safe_stderr;  // paths as typed cannot drive the terminal
  using cf::cli::finite_range;
  CLI::App app{
      "cfreplay: replays a trajectory of A against the CF graph and writes the haptic force and\n"
      "moment of every servo tick.\n"
      "  POSES.csv: header t,tx,ty,tz,qw,qx,qy,qz (s, mm, unit quaternion of R; x_B = R x_A + t)\n"
      "  POSES.csv is the device: where the hand holds A. With the proxy (default) A is rendered\n"
      "  at a proxy pose that never goes into B (docs/spec.md, section 6b).\n"
      "  OUT.csv:   t,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz (the rendered wrench: coupling + contact at\n"
      "             the proxy + gravity; world; N, N mm), then the same in A's frame (FAx..MAz),\n"
      "             the status, the per-PC friction regimes (then approaching:PC for each contact\n"
      "             pushing by eq. (1) alone), the proxy pose proxy_tx..proxy_qz and the contact\n"
      "             wrench Fcx..Mcz (what B exerts on A), and the force model's\n"
      "             discontinuities by design at the tick (slip_onset, impact_end,\n"
      "             regime_switch, hold_release, pc_lost; docs/force-model.md).\n"
      "Defaults are the paper's: m 0.5 kg, g 9.8 N/kg along -y, K 2.3 N/mm, K_p 1.6 N/mm,\n"
      "mu 0.7, mu_D 0.08, epsilon 1 mm (docs/force-model.md).",
      "cfreplay"};
  app.set_version_flag("--version", cf::cli::version_text("cfreplay"));
  std::string graph_path, traj_path, out_path, plot_path;
  cf::Params P;
  std::string friction = "anchor", moment_ref = "origin", centroid = "vertex", proxy = "on";
  app.add_option("--graph", graph_path, "CF graph file (cfgen's output)")
      ->required()
      ->type_name("GRAPH.json");
  app.add_option("--trajectory", traj_path, "poses of A, one row per servo tick")
      ->required()
      ->type_name("POSES.csv");
  app.add_option("-o,--output", out_path, "force and moment per tick")
      ->required()
      ->type_name("OUT.csv");
  app.add_option("--plot", plot_path, "also write an SVG plot of force and moment against time")
      ->type_name("OUT.svg");
  app.add_option(
         "--friction", friction,
         "s_pj reading: 'anchor' (displacement since sticking, rate independent) or 'per-tick' "
         "(the paper's literal one-tick displacement)")
      ->check(CLI::IsMember({"anchor", "per-tick"}));
  app.add_option(
         "--proxy", proxy,
         "'on': the trajectory is the device and A is rendered at a proxy that stays out of B, "
         "felt through a spring (docs/spec.md, section 6b); 'off': A's pose is the trajectory "
         "(the paper's literal model)")
      ->check(CLI::IsMember({"on", "off"}));
  CLI::Option* moment_ref_opt =
      app.add_option(
             "--moment-ref", moment_ref,
             "moment about A's 'origin' (paper eq. (9)), its 'centroid', or the 'point' given "
             "by --moment-point")
          ->check(CLI::IsMember({"origin", "centroid", "point"}));
  std::vector<double> moment_point;
  app.add_option(
         "--moment-point", moment_point,
         "X Y Z: the moment's reference point, mm in A's frame (implies --moment-ref point)")
      ->expected(3)
      ->check(finite_range(-1e9, 1e9));
  app.add_option("--centroid", centroid, "mass centre: 'vertex' mean (paper) or 'volume' centroid")
      ->check(CLI::IsMember({"vertex", "volume"}));
  // The real-valued parameters that have an option: names, ranges and help from libcf's
  // parameter table (cf::param_specs), so they are checked as the library checks them.
  std::map<std::string, CLI::Option*> given;
  for (const cf::ParamSpec& spec : cf::param_specs()) {
    if (!spec.option) continue;
    const std::string unit = *spec.unit ? std::string(", ") + spec.unit : "";
    given[spec.path] = app.add_option(spec.option, spec.field(P), spec.doc + unit)
                           ->check(cf::cli::param_range(spec));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cfreplay: " << e.what() << " (see cfreplay --help)\n";
    return 2;
  }
  const std::string why = apply_choices(
      {friction, moment_ref, centroid, proxy, moment_point, moment_ref_opt->count() > 0,
       given.at("mu_static")->count() > 0, given.at("mu_kinetic")->count() > 0},
      P);
  if (!why.empty()) {
    std::cerr << "cfreplay: " << why << " (see cfreplay --help)\n";
    return 2;
  }

  try {
    // Output paths first, so that a bad one fails before the work (docs/spec.md, section 5b).
    const std::vector<std::string> inputs{graph_path, traj_path};
    cf::check_output_path(out_path, inputs, "writing");
    if (!plot_path.empty()) cf::check_output_path(plot_path, inputs, "writing", {out_path});
    const cf::CfGraph graph = cf::CfGraph::load(graph_path);
    for (const auto& [m, which] :
         {std::pair{&graph.model_a(), "A"}, std::pair{&graph.model_b(), "B"}})
      if (const std::string w = cf::size_warning(*m, which, P.epsilon_mm); !w.empty())
        std::cerr << "cfreplay: warning: " << w << "\n";
    auto poses = cf::TrajectoryCsvReader::open(traj_path);
    cf::Replay replay(graph, P, poses);
    cf::replay::PlotRecorder plot;
    std::map<std::string, long> statuses;
    // The CSV is written as the ticks are rendered, the plot after them; both land or neither
    // does, and memory does not grow with the ticks (docs/performance.md, "Replay").
    auto write_rows = [&](const cf::ByteSink& sink) {
      std::string text = std::string(cf::replay_csv_header()) + '\n';
      cf::ReplayRow row;
      while (replay.next(row)) {
        cf::append_csv(row, text);
        text += '\n';
        if (text.size() > (1u << 16)) {
          sink(text.data(), text.size());
          text.clear();
        }
        ++statuses[row.status];
        if (!plot_path.empty()) plot.add(row);
      }
      sink(text.data(), text.size());
    };
    std::vector<cf::StreamedOutput> files{{out_path, write_rows}};
    if (!plot_path.empty())
      files.push_back({plot_path, [&](const cf::ByteSink& sink) {
                         const std::string svg = plot.svg(traj_path + " against " + graph_path);
                         sink(svg.data(), svg.size());
                       }});
    cf::write_streamed_outputs(files, inputs, "writing");
    const long ticks = replay.ticks();
    std::cerr << "cfreplay: " << ticks << (ticks == 1 ? " tick" : " ticks") << " -> " << out_path
              << " (";
    bool first = true;
    for (const auto& [s, n] : statuses) {
      std::cerr << (first ? "" : ", ") << s << " " << n;
      first = false;
    }
    std::cerr << ")\n";
  } catch (const std::exception& e) {
    std::cerr << "cfreplay: " << e.what() << '\n';
    return 1;
  }
  return 0;
}

// cfreplay: runs the run-time loop (detect, identify, classify, force) over a trajectory of A
// and writes one row per servo tick (docs/spec.md, section 5b).
//   cfreplay --graph GRAPH.json --trajectory POSES.csv -o OUT.csv [--plot OUT.svg]
// Options are named as the Python package's keywords (cf/params.hpp, the parameter table);
// the names before that still work, with a warning, for one release.

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
#include <set>
#include <string>
#include <vector>

namespace {

const char* const kAbout =
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
    "mu 0.7, mu_D 0.08, epsilon 1 mm (docs/force-model.md).";

// What the command line gives.
struct Options {
  std::string graph_path, traj_path, out_path, plot_path;
  cf::Params P;
  std::string friction = cf::to_string(cf::FrictionDisplacement::kStickAnchor);
  std::string centroid = cf::to_string(cf::CentroidChoice::kVertexMean);
  std::string moment_ref = cf::to_string(cf::MomentReference::kAOrigin);
  std::string proxy = "on";
  std::vector<double> moment_point;
  std::map<std::string, std::vector<CLI::Option*>> given;  // by name: the option and its alias
  std::set<std::string> renamed;  // "--mu is now --mu-static", for each old name used
  bool was_given(const std::string& name) const {
    for (const CLI::Option* o : given.at(name))
      if (o->count() > 0) return true;
    return false;
  }
};

// The old spelling of a choice (before the options took the Python keywords' names) and
// today's.
const std::map<std::string, std::string> kOldChoices = {
    {"anchor", "stick_anchor"}, {"per-tick", "per_tick"},   {"vertex", "vertex_mean"},
    {"origin", "a_origin"},     {"centroid", "a_centroid"}, {"point", "a_point"}};

template <class E, std::size_t N>
std::vector<std::string> choice_names(const E (&all)[N], std::vector<std::string> old = {}) {
  std::vector<std::string> names;
  for (E e : all) names.emplace_back(cf::to_string(e));
  names.insert(names.end(), old.begin(), old.end());
  return names;
}

// An option under its name before the rename (cf::cli::old_option_name).
template <class T>
CLI::Option* old_name(CLI::App& app, Options& o, const std::string& name, const std::string& now,
                      T& value) {
  return cf::cli::old_option_name(app, name, now, value, o.renamed);
}

// The choices and the moment's point, each under its name and its old one.
void add_choice_options(CLI::App& app, Options& o) {
  const auto friction = choice_names(cf::kFrictionDisplacements);
  const auto moment = choice_names(cf::kMomentReferences);
  const auto old_friction = choice_names(cf::kFrictionDisplacements, {"anchor", "per-tick"});
  const auto old_moment = choice_names(cf::kMomentReferences, {"origin", "centroid", "point"});
  app.add_option("--friction-displacement", o.friction,
                 "s_pj reading: 'stick_anchor' (displacement since sticking, rate independent) "
                 "or 'per_tick' (the paper's literal one-tick displacement)")
      ->check(CLI::IsMember(friction));
  old_name(app, o, "--friction", "--friction-displacement", o.friction)
      ->check(CLI::IsMember(old_friction));
  app.add_option("--proxy", o.proxy,
                 "'on': the trajectory is the device and A is rendered at a proxy that stays out "
                 "of B, felt through a spring (docs/spec.md, section 6b); 'off': A's pose is the "
                 "trajectory (the paper's literal model)")
      ->check(CLI::IsMember({"on", "off"}));
  o.given["moment_reference"] = {
      app.add_option("--moment-reference", o.moment_ref,
                     "moment about A's origin 'a_origin' (paper eq. (9)), its mass centre "
                     "'a_centroid', or the point 'a_point' given by --moment-point-A")
          ->check(CLI::IsMember(moment)),
      old_name(app, o, "--moment-ref", "--moment-reference", o.moment_ref)
          ->check(CLI::IsMember(old_moment))};
  app.add_option("--moment-point-A", o.moment_point,
                 "X Y Z: the moment's reference point, mm in A's frame (implies --moment-reference "
                 "a_point)")
      ->expected(3)
      ->check(cf::cli::finite_range(-1e9, 1e9));
  old_name(app, o, "--moment-point", "--moment-point-A", o.moment_point)
      ->expected(3)
      ->check(cf::cli::finite_range(-1e9, 1e9));
  app.add_option("--centroid", o.centroid,
                 "mass centre: 'vertex_mean' (paper) or 'volume' centroid")
      ->check(CLI::IsMember(choice_names(cf::kCentroidChoices, {"vertex"})));
}

// The real-valued parameters that have an option: names, ranges and help from libcf's
// parameter table (cf::param_specs), so they are checked as the library checks them.
void add_param_options(CLI::App& app, Options& o) {
  for (const cf::ParamSpec& spec : cf::param_specs()) {
    if (!spec.option) continue;
    const std::string unit = *spec.unit ? std::string(", ") + spec.unit : "";
    std::vector<CLI::Option*>& names = o.given[spec.path];
    names.push_back(app.add_option(spec.option, spec.field(o.P), spec.doc + unit)
                        ->check(cf::cli::param_range(spec)));
    if (spec.deprecated_option)
      names.push_back(old_name(app, o, spec.deprecated_option, spec.option, spec.field(o.P))
                          ->check(cf::cli::param_range(spec)));
  }
}

std::string with_default(double v, bool given) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g%s", v, given ? "" : " (the default)");
  return buf;
}

// The choices in P, and the options that contradict each other refused before the work
// (docs/bad-input.md, "Options checked together"): empty, or why.
std::string apply_choices(Options& o) {
  for (std::string* choice : {&o.friction, &o.centroid, &o.moment_ref})
    if (const auto it = kOldChoices.find(*choice); it != kOldChoices.end()) {
      o.renamed.insert("'" + it->first + "' is now '" + it->second + "'");
      *choice = it->second;
    }
  cf::Params& P = o.P;
  P.proxy.enabled = o.proxy == "on";
  for (auto e : cf::kFrictionDisplacements)
    if (o.friction == cf::to_string(e)) P.friction_displacement = e;
  for (auto e : cf::kCentroidChoices)
    if (o.centroid == cf::to_string(e)) P.centroid = e;
  for (auto e : cf::kMomentReferences)
    if (o.moment_ref == cf::to_string(e)) P.moment_reference = e;
  const std::string point = cf::to_string(cf::MomentReference::kAPoint);
  if (!o.moment_point.empty()) {
    if (o.was_given("moment_reference") && o.moment_ref != point)
      return "--moment-reference " + o.moment_ref +
             " contradicts --moment-point-A, which sets the moment's reference point; give one";
    P.moment_reference = cf::MomentReference::kAPoint;
    P.moment_point_A = cf::Vec3(o.moment_point[0], o.moment_point[1], o.moment_point[2]);
  } else if (o.moment_ref == point) {
    return "--moment-reference a_point needs --moment-point-A X Y Z";
  }
  if (P.mu_kinetic > P.mu_static)
    return "--mu-kinetic " + with_default(P.mu_kinetic, o.was_given("mu_kinetic")) +
           " is above --mu-static " + with_default(P.mu_static, o.was_given("mu_static")) +
           ": kinetic friction cannot exceed static friction; give --mu-kinetic at most "
           "--mu-static";
  return "";
}

// The replay: its CSV streamed as the ticks are rendered, the plot after them; both land or
// neither does, and memory does not grow with the ticks (docs/performance.md, "Replay").
void run(const Options& o) {
  // Output paths first, so that a bad one fails before the work (docs/spec.md, section 5b).
  const std::vector<std::string> inputs{o.graph_path, o.traj_path};
  cf::check_output_path(o.out_path, inputs, "writing");
  const bool plotting = !o.plot_path.empty();
  if (plotting) cf::check_output_path(o.plot_path, inputs, "writing", {o.out_path});
  const cf::CfGraph graph = cf::CfGraph::load(o.graph_path);
  for (const auto& [m, which] :
       {std::pair{&graph.model_a(), "A"}, std::pair{&graph.model_b(), "B"}})
    if (const std::string w = cf::size_warning(*m, which, o.P.epsilon_mm); !w.empty())
      std::cerr << "cfreplay: warning: " << w << "\n";
  auto poses = cf::TrajectoryCsvReader::open(o.traj_path);
  cf::Replay replay(graph, o.P, poses);
  cf::replay::PlotRecorder plot;
  std::map<std::string, long> statuses;
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
      if (plotting) plot.add(row);
    }
    sink(text.data(), text.size());
  };
  std::vector<cf::StreamedOutput> files{{o.out_path, write_rows}};
  if (plotting)
    files.push_back({o.plot_path, [&](const cf::ByteSink& sink) {
                       const std::string svg = plot.svg(o.traj_path + " against " + o.graph_path);
                       sink(svg.data(), svg.size());
                     }});
  cf::write_streamed_outputs(files, inputs, "writing");
  const long ticks = replay.ticks();
  std::cerr << "cfreplay: " << ticks << (ticks == 1 ? " tick" : " ticks") << " -> " << o.out_path
            << " (";
  bool first = true;
  for (const auto& [s, n] : statuses) {
    std::cerr << (first ? "" : ", ") << s << " " << n;
    first = false;
  }
  std::cerr << ")\n";
}

}  // namespace

int main(int argc, char** argv) {
  const cf::cli::TerminalSafeStderr safe_stderr;  // paths as typed cannot drive the terminal
  CLI::App app{kAbout, "cfreplay"};
  app.set_version_flag("--version", cf::cli::version_text("cfreplay"));
  Options o;
  app.add_option("--graph", o.graph_path, "CF graph file (cfgen's output)")
      ->required()
      ->type_name("GRAPH.json");
  app.add_option("--trajectory", o.traj_path, "poses of A, one row per servo tick")
      ->required()
      ->type_name("POSES.csv");
  app.add_option("-o,--output", o.out_path, "force and moment per tick")
      ->required()
      ->type_name("OUT.csv");
  app.add_option("--plot", o.plot_path, "also write an SVG plot of force and moment against time")
      ->type_name("OUT.svg");
  add_choice_options(app, o);
  add_param_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cfreplay: " << e.what() << " (see cfreplay --help)\n";
    return 2;
  }
  const std::string why = apply_choices(o);
  for (const std::string& note : o.renamed)
    std::cerr << "cfreplay: warning: " << note << "; the old name goes in the next release\n";
  if (!why.empty()) {
    std::cerr << "cfreplay: " << why << " (see cfreplay --help)\n";
    return 2;
  }
  try {
    run(o);
  } catch (const std::exception& e) {
    std::cerr << "cfreplay: " << e.what() << '\n';
    return 1;
  }
  return 0;
}

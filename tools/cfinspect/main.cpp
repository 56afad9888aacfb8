// cfinspect: validates a CF graph file against the schema, re-checks its witnesses with
// cfgen's verify (witness_check.cpp, the only part that needs CGAL) and summarises it,
// answers queries (CFs holding a PC, a CF's transitions, one CF, the CF at a pose) and
// exports Graphviz DOT and the browser viewer (docs/spec.md, section 5b).

#include <cf/file_io.hpp>
#include <cf/graph.hpp>
#include <cf/identifier.hpp>

#include "cli_checks.hpp"  // finite_range, param_range, version_text
#include "html.hpp"        // --html: the browser viewer
#include "safe_stderr.hpp"
#include "witness_check.hpp"  // --verify

#include <CLI/CLI.hpp>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/graphviz.hpp>
#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using ojson = nlohmann::ordered_json;

/// A user-facing failure: printed as one line, exit status 1.
struct Failure {
  std::string message;
};

struct Summary {
  std::array<std::size_t, 4> cfs_by_size{};    // index = number of PCs
  std::array<std::size_t, 6> pcs_by_type{};    // PCs over all CFs
  std::array<std::size_t, 6> cfs_with_type{};  // CFs holding at least one PC of a type
  std::array<std::size_t, 3> transitions_by_kind{};
  std::size_t unpaired = 0;  // transitions whose reverse is not in the graph
  std::size_t min_out = 0, max_out = 0;
  double mean_out = 0;
  std::size_t components = 0, largest_component = 0, isolated = 0;
};

std::size_t reflex_edges(const cf::Polyhedron& m) {
  return static_cast<std::size_t>(std::count_if(m.edges().begin(), m.edges().end(),
                                                [](const cf::Edge& e) { return !e.convex; }));
}

Summary summarise(const cf::CfGraph& g) {
  Summary s;
  const std::size_t n = g.num_cfs();
  for (std::size_t i = 0; i < n; ++i) {
    const cf::PcSet& pcs = g.cf(cf::CfId(static_cast<int>(i))).pcs;
    ++s.cfs_by_size[static_cast<std::size_t>(pcs.size())];
    std::array<bool, 6> seen{};
    for (const cf::Pc& pc : pcs) {
      const auto t = static_cast<std::size_t>(pc.type);
      ++s.pcs_by_type[t];
      seen[t] = true;
    }
    for (std::size_t t = 0; t < 6; ++t) s.cfs_with_type[t] += seen[t] ? 1 : 0;
  }
  for (std::size_t i = 0; i < g.num_transitions(); ++i) {
    const cf::Transition& t = g.transition(i);
    ++s.transitions_by_kind[static_cast<std::size_t>(t.kind)];
    if (!g.adjacent(t.to, t.from)) ++s.unpaired;
  }
  if (n > 0) {
    s.min_out = static_cast<std::size_t>(-1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t d = g.out_transitions(cf::CfId(static_cast<int>(i))).size();
      s.min_out = std::min(s.min_out, d);
      s.max_out = std::max(s.max_out, d);
    }
    s.mean_out = static_cast<double>(g.num_transitions()) / static_cast<double>(n);
    // Components of the undirected view: CFs reachable from each other by any transitions,
    // by union-find over the transitions with path halving (a vector of n: an adjacency list
    // of 2.85 million transitions took a second and 200 MB).
    std::vector<std::size_t> parent(n);
    std::iota(parent.begin(), parent.end(), std::size_t{0});
    const auto root = [&parent](std::size_t i) {
      for (; parent[i] != i; i = parent[i]) parent[i] = parent[parent[i]];
      return i;
    };
    for (std::size_t i = 0; i < g.num_transitions(); ++i)
      parent[root(static_cast<std::size_t>(g.transition(i).from.index()))] =
          root(static_cast<std::size_t>(g.transition(i).to.index()));
    std::vector<std::size_t> sizes(n, 0);
    for (std::size_t i = 0; i < n; ++i) ++sizes[root(i)];
    s.components =
        n - static_cast<std::size_t>(std::count(sizes.begin(), sizes.end(), std::size_t{0}));
    s.largest_component = *std::max_element(sizes.begin(), sizes.end());
    s.isolated = static_cast<std::size_t>(std::count(sizes.begin(), sizes.end(), std::size_t{1}));
  }
  return s;
}

const char* kTypeNames[] = {"f-f", "e-f", "f-e", "v-f", "f-v", "e-e"};
const char* kKindNames[] = {"gain", "lose", "change"};

ojson model_json(const cf::Polyhedron& m) {
  ojson j = ojson::object();
  j["name"] = m.name();
  j["vertices"] = m.num_vertices();
  j["edges"] = m.num_edges();
  j["reflex_edges"] = reflex_edges(m);
  j["faces"] = m.num_faces();
  return j;
}

// What the witness check did, for the summary's first line.
std::string witness_words(const cf::inspect::WitnessCheck& w, bool asked) {
  if (w.available) return "; " + std::to_string(w.checked) + " witnesses verified";
  return asked ? "; witnesses not checked: built without CGAL" : "";
}

// How the file was checked against the schema: valijson on everything (--full-schema), or on
// the skeleton with the items of cfs and transitions by the reader's rules, which refuse
// whatever the schema refuses (tests/libcf/graph_reader_test.cpp).
const char* schema_words(bool full_schema) {
  return full_schema ? "full schema check" : "schema check, items by the reader's rules";
}

ojson summary_json(const std::string& path, const cf::CfGraph& g, const Summary& s,
                   bool full_schema, const cf::inspect::WitnessCheck& w) {
  ojson j = ojson::object();
  j["file"] = path;
  j["valid"] = true;
  j["schema_check"] = full_schema ? "full" : "reader";
  j["witnesses_verified"] = w.available ? ojson(w.checked) : ojson(nullptr);
  j["models"] = {{"A", model_json(g.model_a())}, {"B", model_json(g.model_b())}};
  ojson by_size = ojson::object();
  for (std::size_t k = 1; k <= 3; ++k) by_size[std::to_string(k)] = s.cfs_by_size[k];
  ojson by_type = ojson::object(), with_type = ojson::object();
  for (std::size_t t = 0; t < 6; ++t) {
    by_type[kTypeNames[t]] = s.pcs_by_type[t];
    with_type[kTypeNames[t]] = s.cfs_with_type[t];
  }
  j["cfs"] = {{"count", g.num_cfs()},
              {"by_num_pcs", by_size},
              {"pcs_by_type", by_type},
              {"cfs_with_type", with_type}};
  ojson by_kind = ojson::object();
  for (std::size_t k = 0; k < 3; ++k) by_kind[kKindNames[k]] = s.transitions_by_kind[k];
  j["transitions"] = {
      {"count", g.num_transitions()}, {"by_kind", by_kind}, {"without_reverse", s.unpaired}};
  j["out_degree"] = {{"min", s.min_out}, {"mean", s.mean_out}, {"max", s.max_out}};
  j["components"] = {
      {"count", s.components}, {"largest", s.largest_component}, {"isolated_cfs", s.isolated}};
  j["metadata"] = ojson::parse(g.metadata_json());
  return j;
}

void print_summary(std::ostream& out, const std::string& path, const cf::CfGraph& g,
                   const Summary& s, bool full_schema, bool witnesses_asked,
                   const cf::inspect::WitnessCheck& w) {
  auto model_line = [&](const char* which, const cf::Polyhedron& m) {
    out << "model " << which << " '" << cf::printable(m.name()) << "': " << m.num_vertices()
        << " vertices, " << m.num_edges() << " edges (" << reflex_edges(m) << " reflex), "
        << m.num_faces() << " faces\n";
  };
  out << path << ": valid cf-graph v1 (" << schema_words(full_schema)
      << witness_words(w, witnesses_asked) << ")\n";
  model_line("A", g.model_a());
  model_line("B", g.model_b());
  out << "CFs: " << g.num_cfs() << "\n";
  out << "  by number of PCs:";
  for (std::size_t k = 1; k <= 3; ++k)
    out << " " << k << ": " << s.cfs_by_size[k] << (k < 3 ? "," : "\n");
  out << "  PCs by type (CFs holding one):";
  for (std::size_t t = 0; t < 6; ++t)
    out << " " << kTypeNames[t] << " " << s.pcs_by_type[t] << " (" << s.cfs_with_type[t] << ")"
        << (t < 5 ? "," : "\n");
  out << "transitions: " << g.num_transitions() << " (gain " << s.transitions_by_kind[0]
      << ", lose " << s.transitions_by_kind[1] << ", change " << s.transitions_by_kind[2] << "), "
      << s.unpaired << " without their reverse\n";
  out << "out-degree: min " << s.min_out << ", mean " << std::fixed << std::setprecision(2)
      << s.mean_out << ", max " << s.max_out << "\n";
  out.unsetf(std::ios::floatfield);
  out << "connected components: " << s.components << " (largest " << s.largest_component << " CFs, "
      << s.isolated << " isolated CFs)\n";
  const auto meta = nlohmann::json::parse(g.metadata_json());
  out << "metadata:";
  if (meta.empty()) out << " none";
  for (auto it = meta.begin(); it != meta.end(); ++it) out << " " << cf::printable(it.key());
  out << "\n";
}

cf::CfId parse_cf_id(const cf::CfGraph& g, const std::string& path, long long id) {
  if (id < 0 || static_cast<std::size_t>(id) >= g.num_cfs())
    throw Failure{"'" + path + "': CF " + std::to_string(id) + " does not exist (the graph has " +
                  std::to_string(g.num_cfs()) + " CFs)"};
  return cf::CfId(static_cast<int>(id));
}

ojson pcs_json(const cf::PcSet& pcs) {
  ojson a = ojson::array();
  for (const cf::Pc& pc : pcs) a.push_back(cf::to_string(pc));
  return a;
}

ojson pose_json(const cf::Pose& p) {
  ojson R = ojson::array();
  for (int i = 0; i < 3; ++i) R.push_back({p.R_BA(i, 0), p.R_BA(i, 1), p.R_BA(i, 2)});
  return {{"R", R}, {"t", {p.t_BA.x(), p.t_BA.y(), p.t_BA.z()}}};
}

ojson cf_json(const cf::CfGraph& g, cf::CfId id) {
  const cf::CfRecord& r = g.cf(id);
  ojson j = ojson::object();
  j["id"] = id.value();
  j["pcs"] = pcs_json(r.pcs);
  j["witness"] = pose_json(r.witness);
  if (r.dof >= 0) j["dof"] = r.dof;
  if (r.translation_dof >= 0) j["translation_dof"] = r.translation_dof;
  if (r.dof >= 0 || r.translation_dof >= 0) j["pure_rotation"] = r.pure_rotation;
  ojson out = ojson::array();
  for (const cf::Transition& t : g.out_transitions(id))
    out.push_back(
        {{"to", t.to.value()}, {"kind", cf::to_string(t.kind)}, {"pcs", pcs_json(g.cf(t.to).pcs)}});
  j["transitions"] = out;
  return j;
}

void print_cf(std::ostream& out, const cf::CfGraph& g, cf::CfId id) {
  const cf::CfRecord& r = g.cf(id);
  out << "CF " << id.value() << ": " << cf::to_string(r.pcs) << "\n";
  const Eigen::IOFormat fmt(Eigen::FullPrecision, 0, ", ", "\n", "    [", "]");
  out << "  witness R (rows):\n" << r.witness.R_BA.format(fmt) << "\n";
  out << "  witness t (mm): "
      << r.witness.t_BA.transpose().format(
             Eigen::IOFormat(Eigen::FullPrecision, 0, ", ", "", "", "", "[", "]"))
      << "\n";
  if (r.dof >= 0 || r.translation_dof >= 0)
    out << "  freedoms: dof " << r.dof << ", translation dof " << r.translation_dof
        << ", pure rotation " << (r.pure_rotation ? "yes" : "no") << "\n";
  out << "  transitions out: " << g.out_transitions(id).size() << "\n";
}

void print_neighbours(std::ostream& out, const cf::CfGraph& g, cf::CfId id) {
  const auto& list = g.out_transitions(id);
  out << "CF " << id.value() << " {" << cf::to_string(g.cf(id).pcs) << "}: " << list.size()
      << " transitions\n";
  for (const cf::Transition& t : list)
    out << "  -> CF " << t.to.value() << " " << cf::to_string(t.kind) << " {"
        << cf::to_string(g.cf(t.to).pcs) << "}\n";
}

std::vector<cf::CfId> holding(const cf::CfGraph& g, const cf::Pc& pc) {
  std::vector<cf::CfId> ids;
  for (std::size_t i = 0; i < g.num_cfs(); ++i)
    if (g.cf(cf::CfId(static_cast<int>(i))).pcs.contains(pc))
      ids.push_back(cf::CfId(static_cast<int>(i)));
  return ids;
}

// Vertex i is CF i; one directed edge per transition, in file order (write_graphviz lists
// them per source CF in that order).
using DotGraph = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS,
                                       boost::no_property, cf::TransitionKind>;

std::string dot_text(const cf::CfGraph& g) {
  DotGraph bg(g.num_cfs());
  for (std::size_t i = 0; i < g.num_transitions(); ++i) {
    const cf::Transition& t = g.transition(i);
    boost::add_edge(t.from.index(), t.to.index(), t.kind, bg);
  }
  std::ostringstream dot;
  auto vertex_label = [&g](std::ostream& os, std::size_t v) {
    os << "[label=\"" << v << ": " << cf::to_string(g.cf(cf::CfId(static_cast<int>(v))).pcs)
       << "\"]";
  };
  auto edge_label = [&bg](std::ostream& os, const DotGraph::edge_descriptor& e) {
    const cf::TransitionKind k = bg[e];
    const char* style = k == cf::TransitionKind::kGain   ? "solid"
                        : k == cf::TransitionKind::kLose ? "dashed"
                                                         : "dotted";
    os << "[label=\"" << cf::to_string(k) << "\", style=" << style << "]";
  };
  auto graph_attrs = [](std::ostream& os) { os << "node [shape=box, fontname=\"monospace\"];\n"; };
  boost::write_graphviz(dot, bg, vertex_label, edge_label, graph_attrs);
  return dot.str();
}

/// "tx,ty,tz,qw,qx,qy,qz" (mm, unit quaternion of R), as a row of cfreplay's POSES.csv.
cf::Pose parse_pose(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    while (used < item.size() && item[used] == ' ') ++used;
    if (item.empty() || used != item.size())
      throw Failure{"--pose '" + cf::printable(text) + "': '" + cf::printable(item) +
                    "' is not a number"};
    v.push_back(x);
  }
  if (v.size() != 7)
    throw Failure{"--pose '" + cf::printable(text) +
                  "': expected 7 numbers tx,ty,tz,qw,qx,qy,qz, got " + std::to_string(v.size())};
  Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  // The one tolerance of every tool (cfreplay's POSES.csv too): 4 significant digits.
  if (std::string why = cf::quaternion_problem(v[3], v[4], v[5], v[6]); !why.empty())
    throw Failure{"--pose '" + text + "': " + why};
  cf::Pose p;
  p.R_BA = q.normalized().toRotationMatrix();
  p.t_BA = cf::Vec3(v[0], v[1], v[2]);
  return p;
}

// The command line.
struct Options {
  std::string path, holding_text, dot_path, pose_text, html_path, replay_path, trajectory_path;
  long long neighbours_id = -1, cf_id = -1;
  bool neighbours = false, cf = false;  // --neighbours, --cf given
  bool as_json = false, fast = false, full_schema = false, print_schema = false, verify = false;
  double epsilon = 1.0;           // mm
  std::set<std::string> renamed;  // "--epsilon is now --epsilon-mm", for each old name used
  int threads = 0;                // 0: the hardware's count
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("graph", o.path, "CF graph file (.json, or .cbor)");
  app.add_option("--holding", o.holding_text,
                 "list the CFs that hold this PC, TYPE:A:B (e.g. v-f:3:5)");
  app.add_option("--neighbours,--neighbors", o.neighbours_id, "list the transitions leaving CF ID");
  app.add_option("--cf", o.cf_id, "print CF ID with its witness pose and freedoms");
  app.add_option("--dot", o.dot_path,
                 "write the graph as Graphviz DOT (labels: PC lists; edges: kinds)");
  app.add_option("--pose", o.pose_text,
                 "identify the CF at the pose tx,ty,tz,qw,qx,qy,qz of A (mm, unit quaternion; as "
                 "in POSES.csv)");
  // The contact threshold as libcf's parameter table has it (name, range), as cfreplay's.
  const cf::ParamSpec& epsilon = cf::cli::param_spec("epsilon_mm");
  app.add_option(epsilon.option, o.epsilon,
                 "contact threshold for --pose, mm (default 1.0, the paper's)")
      ->check(cf::cli::param_range(epsilon));
  cf::cli::old_option_name(app, "--epsilon", epsilon.option, o.epsilon, o.renamed)
      ->check(cf::cli::param_range(epsilon));
  app.add_option("--html", o.html_path,
                 "write the browser viewer of the graph: one self-contained HTML file");
  app.add_option("--replay", o.replay_path,
                 "with --html: a cfreplay output CSV for the page to animate");
  app.add_option("--trajectory", o.trajectory_path,
                 "with --replay: the POSES.csv it was replayed from (moves A)");
  app.add_flag("--json", o.as_json, "machine-readable output (the summary or the query's answer)");
  app.add_flag("--fast", o.fast, "skip the witness check");
  app.add_flag("--full-schema", o.full_schema,
               "check the items of cfs/transitions with valijson as well (the reader's rules, "
               "always applied, refuse whatever the schema does; this takes 7x as long)");
  app.add_flag("--verify", o.verify,
               "re-check every CF's witness and freedoms with cfgen's verify (part of the "
               "default check; with --fast, only this)");
  app.add_option("-j,--threads", o.threads, "threads of the witness check (0: all cores)")
      ->check(CLI::Range(0, 1024));
  app.add_flag("--print-schema", o.print_schema,
               "print the JSON Schema of graph files (schemas/cf-graph.schema.json) and exit");
}

// The files --html reads, never written over.
std::vector<std::string> html_inputs(const Options& o) {
  std::vector<std::string> in{o.path};
  for (const std::string* p : {&o.replay_path, &o.trajectory_path})
    if (!p->empty()) in.push_back(*p);
  return in;
}

// The inputs that go together, and the output paths, checked before the (possibly long)
// load so that mistakes fail fast. Returns 0, or the exit status of a usage error.
int check_arguments(const Options& o) {
  if (o.path.empty()) {
    std::cerr << "cfinspect: no graph file given (see --help)\n";
    return 2;
  }
  if (o.html_path.empty() && !(o.replay_path.empty() && o.trajectory_path.empty())) {
    std::cerr << "cfinspect: --replay and --trajectory go with --html (see --help)\n";
    return 2;
  }
  if (!o.trajectory_path.empty() && o.replay_path.empty()) {
    std::cerr << "cfinspect: --trajectory goes with --replay (see --help)\n";
    return 2;
  }
  // Never the graph itself, a device, a FIFO or a directory (docs/spec.md, section 5b).
  if (!o.dot_path.empty()) cf::check_output_path(o.dot_path, {o.path}, "writing DOT");
  if (!o.html_path.empty())
    cf::check_output_path(o.html_path, html_inputs(o), "writing HTML", {o.dot_path});
  return 0;
}

// Warnings (stderr, exit status 0): nothing to identify, or models whose size suggests a
// unit mistake.
void warn_about(const cf::CfGraph& g, double epsilon) {
  if (g.num_cfs() == 0)
    std::cerr << "cfinspect: warning: the graph has no CF (A " << g.model_a().size()
              << " mm across, B " << g.model_b().size()
              << " mm across): nothing can be identified; were the models' units right?\n";
  for (const auto& [m, which] : {std::pair{&g.model_a(), "A"}, std::pair{&g.model_b(), "B"}})
    if (const std::string w = cf::size_warning(*m, which, epsilon); !w.empty())
      std::cerr << "cfinspect: warning: " << w << "\n";
}

// The witness check, when asked for or part of the full check: a graph whose witness or
// freedoms do not hold is refused, naming the first such CF.
cf::inspect::WitnessCheck check_witnesses(const Options& o, const cf::CfGraph& g) {
  if (o.fast && !o.verify) return {};
  cf::inspect::WitnessCheck w = cf::inspect::check_witnesses(g, o.threads);
  if (!w.available && o.verify)
    throw Failure{
        "--verify: this cfinspect was built without CGAL (CF_WITH_CGAL=OFF), so "
        "without the generator's verify"};
  if (w.failed > 0) {
    const cf::CfId id(static_cast<int>(w.first_bad));
    throw Failure{"'" + o.path + "' at /cfs/" + std::to_string(w.first_bad) + ": CF " +
                  std::to_string(w.first_bad) + " {" + cf::to_string(g.cf(id).pcs) +
                  "}: " + cf::printable(w.why) + " (" + std::to_string(w.failed) + " of " +
                  std::to_string(w.checked) + " CFs fail the witness check)"};
  }
  return w;
}

void answer_holding(const Options& o, const cf::CfGraph& g, ojson& answer) {
  const std::optional<cf::Pc> pc = cf::pc_from_string(o.holding_text);
  const char* field = "";
  if (std::string why = cf::check_pc(*pc, g.model_a(), g.model_b(), &field); !why.empty())
    throw Failure{"--holding '" + o.holding_text + "': " + why};
  const auto ids = holding(g, *pc);
  if (o.as_json) {
    ojson list = ojson::array();
    for (cf::CfId id : ids) list.push_back({{"id", id.value()}, {"pcs", pcs_json(g.cf(id).pcs)}});
    answer["holding"] = {{"pc", cf::to_string(*pc)}, {"cfs", list}};
    return;
  }
  std::cout << ids.size() << " CFs hold " << cf::to_string(*pc) << "\n";
  for (cf::CfId id : ids)
    std::cout << "  CF " << id.value() << ": " << cf::to_string(g.cf(id).pcs) << "\n";
}

void answer_pose(const Options& o, const cf::CfGraph& g, const cf::Pose& pose, ojson& answer) {
  cf::Params params;
  params.epsilon_mm = o.epsilon;
  cf::CfIdentifier identifier(g, params);
  const cf::Identification& r = identifier.step(pose);
  if (o.as_json) {
    ojson candidates = ojson::array();
    for (int i = 0; i < r.contacts.size(); ++i) {
      const cf::ContactPc& c = r.contacts[i];
      candidates.push_back({{"pc", cf::to_string(c.pc)}, {"distance", c.distance}});
    }
    answer["pose"] = {{"status", cf::to_string(r.status)},
                      {"cf", r.has_cf() ? r.cf.value() : -1},
                      {"pcs", pcs_json(r.pcs)},
                      {"candidates", candidates}};
    return;
  }
  std::cout << "pose: " << cf::to_string(r.status) << ", CF " << (r.has_cf() ? r.cf.value() : -1);
  if (r.has_cf()) std::cout << " {" << cf::to_string(r.pcs) << "}";
  std::cout << ", " << r.contacts.size() << " candidate PCs within " << o.epsilon << " mm\n";
  for (int i = 0; i < r.contacts.size(); ++i)
    std::cout << "  " << cf::to_string(r.contacts[i].pc) << " at " << r.contacts[i].distance
              << " mm\n";
}

// --holding, --neighbours, --cf, --pose. Returns whether one was asked.
bool answer_queries(const Options& o, const cf::CfGraph& g, const std::optional<cf::Pose>& pose,
                    ojson& answer) {
  if (!o.holding_text.empty()) answer_holding(o, g, answer);
  if (o.neighbours) {
    const cf::CfId id = parse_cf_id(g, o.path, o.neighbours_id);
    if (o.as_json)
      answer["neighbours"] = cf_json(g, id)["transitions"];
    else
      print_neighbours(std::cout, g, id);
  }
  if (o.cf) {
    const cf::CfId id = parse_cf_id(g, o.path, o.cf_id);
    if (o.as_json)
      answer["cf"] = cf_json(g, id);
    else
      print_cf(std::cout, g, id);
  }
  if (pose) answer_pose(o, g, *pose, answer);
  return !o.holding_text.empty() || o.neighbours || o.cf || pose;
}

// --dot and --html.
void write_exports(const Options& o, const cf::CfGraph& g, ojson& answer) {
  if (!o.dot_path.empty()) {
    cf::write_outputs({{o.dot_path, dot_text(g)}}, {o.path}, "writing DOT");
    if (!o.as_json)
      std::cout << "wrote " << o.dot_path << " (" << g.num_cfs() << " nodes, "
                << g.num_transitions() << " edges)\n";
    else
      answer["dot"] = o.dot_path;
  }
  if (o.html_path.empty()) return;
  // The graph file's own text when it is JSON (with cfgen's contact planes, which the
  // loaded graph does not keep); the re-serialised graph for CBOR.
  const std::string& path = o.path;
  const bool cbor = path.size() >= 5 && path.compare(path.size() - 5, 5, ".cbor") == 0;
  cf::inspect::ViewerInputs in{path,
                               cbor ? g.to_json(-1) : cf::inspect::read_text_file(path, "reading"),
                               g.num_cfs(),
                               o.replay_path,
                               o.trajectory_path,
                               o.cf_id};
  cf::write_outputs({{o.html_path, cf::inspect::viewer_html(in)}}, html_inputs(o), "writing HTML");
  if (!o.as_json)
    std::cout << "wrote " << o.html_path << " (viewer of " << g.num_cfs() << " CFs"
              << (o.replay_path.empty() ? "" : ", with the replay") << ")\n";
  else
    answer["html"] = o.html_path;
}

int run(int argc, char** argv) {
  CLI::App app{
      "cfinspect: validate a CF graph file against the schema and re-check its witnesses, "
      "summarise it, answer queries, export DOT and the browser viewer"};
  app.set_version_flag("--version", cf::cli::version_text("cfinspect"));
  Options o;
  add_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "cfinspect: " << e.what() << " (see --help)\n";
    return 2;
  }
  for (const std::string& note : o.renamed)
    std::cerr << "cfinspect: warning: " << note << "; the old name goes in the next release\n";
  if (o.print_schema) {
    std::cout << cf::graph_schema_text();
    return 0;
  }
  o.neighbours = o.neighbours_id != -1 || app.count("--neighbours") > 0;
  o.cf = o.cf_id != -1 || app.count("--cf") > 0;
  if (const int status = check_arguments(o)) return status;
  // The query arguments before the load, so typos fail fast.
  if (!o.holding_text.empty() && !cf::pc_from_string(o.holding_text))
    throw Failure{"--holding '" + o.holding_text + "': expected TYPE:A:B such as v-f:3:5"};
  std::optional<cf::Pose> pose;
  if (!o.pose_text.empty()) pose = parse_pose(o.pose_text);
  cf::GraphLoadOptions options;
  options.full_schema_check = o.full_schema;
  const cf::CfGraph g = cf::CfGraph::load(o.path, options);
  warn_about(g, o.epsilon);
  const cf::inspect::WitnessCheck witnesses = check_witnesses(o, g);
  ojson answer = ojson::object();
  const bool queried = answer_queries(o, g, pose, answer);
  write_exports(o, g, answer);
  if (!queried) {  // no query: the summary (also after --dot, --html)
    const Summary s = summarise(g);
    if (o.as_json) {
      ojson summary = summary_json(o.path, g, s, o.full_schema, witnesses);
      for (auto it = answer.begin(); it != answer.end(); ++it) summary[it.key()] = it.value();
      answer = std::move(summary);
    } else {
      print_summary(std::cout, o.path, g, s, o.full_schema, !o.fast || o.verify, witnesses);
    }
  }
  if (o.as_json) std::cout << answer.dump(2, ' ', false, ojson::error_handler_t::replace) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const cf::cli::TerminalSafeStderr safe_stderr;  // paths as typed cannot drive the terminal
  try {
    return run(argc, argv);
  } catch (const Failure& f) {
    std::cerr << "cfinspect: " << f.message << "\n";
  } catch (const cf::Error& e) {
    std::cerr << "cfinspect: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "cfinspect: unexpected error: " << e.what() << "\n";
  }
  return 1;
}

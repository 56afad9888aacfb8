// The CF graph file (SPEC section 5): writing (deterministic, whole-or-nothing) and reading
// (JSON or CBOR, schema-validated, every fault named by file and JSON pointer).

#include "graph_impl.hpp"
#include "graph_schema.hpp"
#include "json_util.hpp"
#include "polyhedron_json.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cf {

namespace {

using detail::json;
using detail::JsonWhere;
using ojson = nlohmann::ordered_json;

/// Members of the file that are the graph itself; every other top-level member is metadata.
bool is_reserved(const std::string& key) {
  return key == "format" || key == "version" || key == "units" || key == "models" || key == "cfs" ||
         key == "transitions";
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool is_cbor_path(const std::string& path) { return ends_with(path, ".cbor") || ends_with(path, ".CBOR"); }

// --- writing ----------------------------------------------------------------------------

ojson pose_json(const Pose& pose) {
  ojson R = ojson::array();
  for (int i = 0; i < 3; ++i) R.push_back({pose.R_BA(i, 0), pose.R_BA(i, 1), pose.R_BA(i, 2)});
  ojson w = ojson::object();
  w["R"] = std::move(R);
  w["t"] = {pose.t_BA.x(), pose.t_BA.y(), pose.t_BA.z()};
  return w;
}

ojson cf_json(std::size_t id, const CfRecord& r) {
  ojson c = ojson::object();
  c["id"] = id;
  ojson pcs = ojson::array();
  for (const Pc& pc : r.pcs) {
    ojson p = ojson::object();
    p["type"] = to_string(pc.type);
    p["a"] = pc.a;
    p["b"] = pc.b;
    pcs.push_back(std::move(p));
  }
  c["pcs"] = std::move(pcs);
  c["witness"] = pose_json(r.witness);
  if (r.dof >= 0) c["dof"] = r.dof;
  if (r.translation_dof >= 0) c["translation_dof"] = r.translation_dof;
  if (r.dof >= 0 || r.translation_dof >= 0 || r.pure_rotation) c["pure_rotation"] = r.pure_rotation;
  return c;
}

ojson transition_json(const Transition& t) {
  ojson o = ojson::object();
  o["from"] = t.from.value();
  o["to"] = t.to.value();
  o["kind"] = to_string(t.kind);
  return o;
}

/// The whole file as one ordered value: format, version, units, metadata (sorted by key),
/// models, cfs, transitions.
ojson graph_json(const CfGraph::Impl& g) {
  ojson root = ojson::object();
  root["format"] = "cf-graph";
  root["version"] = 1;
  root["units"] = "mm";
  const json meta = json::parse(g.metadata);
  for (auto it = meta.begin(); it != meta.end(); ++it) root[it.key()] = ojson(it.value());
  ojson models = ojson::object();
  models["A"] = ojson(detail::polyhedron_to_json(g.a));
  models["B"] = ojson(detail::polyhedron_to_json(g.b));
  root["models"] = std::move(models);
  ojson cfs = ojson::array();
  for (std::size_t i = 0; i < g.cfs.size(); ++i) cfs.push_back(cf_json(i, g.cfs[i]));
  root["cfs"] = std::move(cfs);
  ojson tr = ojson::array();
  for (const Transition& t : g.transitions) tr.push_back(transition_json(t));
  root["transitions"] = std::move(tr);
  return root;
}

/// Pretty printing that stays readable for large graphs: containers whose one-line form is
/// short stay on one line, and every CF and transition is one line.
constexpr std::size_t kInlineWidth = 100;

void print(const ojson& v, int indent, int level, bool items_inline, std::string& out) {
  const bool container = v.is_object() || v.is_array();
  if (!container || v.empty()) {
    out += v.dump();
    return;
  }
  if (!items_inline) {
    // Cheap upper bound first so that huge arrays are never dumped just to be measured.
    if (v.size() * 2 < kInlineWidth) {
      std::string one = v.dump();
      if (one.size() <= kInlineWidth) {
        out += one;
        return;
      }
    }
  }
  const std::string pad(static_cast<std::size_t>(indent * (level + 1)), ' ');
  out += v.is_object() ? "{\n" : "[\n";
  bool first = true;
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (!first) out += ",\n";
    first = false;
    out += pad;
    if (v.is_object()) {
      out += ojson(it.key()).dump();
      out += ": ";
      const bool lines = level == 0 && (it.key() == "cfs" || it.key() == "transitions");
      if (lines && it.value().is_array() && !it.value().empty()) {
        out += "[\n";
        const std::string pad2(static_cast<std::size_t>(indent * (level + 2)), ' ');
        bool first_item = true;
        for (const ojson& item : it.value()) {
          if (!first_item) out += ",\n";
          first_item = false;
          out += pad2;
          out += item.dump();
        }
        out += "\n" + pad + "]";
      } else {
        print(it.value(), indent, level + 1, false, out);
      }
    } else {
      print(*it, indent, level + 1, false, out);
    }
  }
  out += "\n" + std::string(static_cast<std::size_t>(indent * level), ' ') + (v.is_object() ? "}" : "]");
}

// --- reading ----------------------------------------------------------------------------

class JsonLocator final : public detail::FaultLocator {
 public:
  explicit JsonLocator(const JsonWhere& root) : root_(root) {}
  [[noreturn]] void cf_fault(std::size_t cf, const std::string& what) const override {
    detail::json_fail(root_ / "cfs" / cf, what);
  }
  [[noreturn]] void pc_fault(std::size_t cf, std::size_t pc, const char* field,
                             const std::string& what) const override {
    detail::json_fail(root_ / "cfs" / cf / "pcs" / pc / field, what);
  }
  [[noreturn]] void transition_fault(std::size_t t, const char* field,
                                     const std::string& what) const override {
    detail::json_fail(root_ / "transitions" / t / field, what);
  }
  [[noreturn]] void metadata_fault(const std::string& what) const override {
    detail::json_fail(root_, what);
  }

 private:
  const JsonWhere& root_;
};

int json_small_int(const json& j, const JsonWhere& w, int lo, int hi) {
  if (!j.is_number_integer() || j.get<long long>() < lo || j.get<long long>() > hi)
    detail::json_fail(w, "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                             ", got " + detail::json_short(j));
  return static_cast<int>(j.get<long long>());
}

Pose read_witness(const json& j, const JsonWhere& w) {
  const json& jR = detail::json_array(detail::json_member(j, "R", w), w / "R");
  if (jR.size() != 3) detail::json_fail(w / "R", "expected 3 rows, got " + std::to_string(jR.size()));
  Pose pose;
  for (std::size_t i = 0; i < 3; ++i) pose.R_BA.row(static_cast<Eigen::Index>(i)) = detail::json_vec3(jR[i], w / "R" / i).transpose();
  pose.t_BA = detail::json_vec3(detail::json_member(j, "t", w), w / "t");
  // Witnesses are written with full double precision; 1e-6 leaves room for hand-written
  // files with 7 significant digits while still catching a scaled or sheared matrix.
  constexpr double kRotationTol = 1e-6;
  const double ortho = (pose.R_BA.transpose() * pose.R_BA - Mat3::Identity()).cwiseAbs().maxCoeff();
  const double det = pose.R_BA.determinant();
  if (!(ortho <= kRotationTol) || !(det > 0)) {
    std::ostringstream s;
    s << "not a rotation matrix (max |R^T R - I| = " << ortho << ", det R = " << det << ")";
    detail::json_fail(w / "R", s.str());
  }
  return pose;
}

std::unique_ptr<CfGraph::Impl> graph_from_json(const json& j, const std::string& source,
                                               bool validate_schema) {
  const JsonWhere root{source, ""};
  if (!j.is_object()) detail::json_fail(root, "expected a cf-graph object, got " + detail::json_short(j));
  {
    const auto it = j.find("format");
    if (it == j.end()) detail::json_fail(root, "missing member \"format\": not a cf-graph file");
    if (!it->is_string() || it->get<std::string>() != "cf-graph")
      detail::json_fail(root / "format", "format is " + detail::json_short(*it) + ", expected \"cf-graph\"");
    const json& v = detail::json_member(j, "version", root);
    if (!v.is_number_integer() || v.get<long long>() != 1)
      detail::json_fail(root / "version", "version " + detail::json_short(v) +
                                              " is not supported (this library reads version 1)");
    const json& u = detail::json_member(j, "units", root);
    if (!u.is_string() || u.get<std::string>() != "mm")
      detail::json_fail(root / "units", "units " + detail::json_short(u) + " are not supported, expected \"mm\"");
  }
  const JsonWhere wm = root / "models";
  const json& jm = detail::json_member(j, "models", root);
  Polyhedron a = detail::polyhedron_from_json(detail::json_member(jm, "A", wm), wm / "A");
  Polyhedron b = detail::polyhedron_from_json(detail::json_member(jm, "B", wm), wm / "B");

  const JsonWhere wc = root / "cfs";
  const json& jc = detail::json_array(detail::json_member(j, "cfs", root), wc);
  std::vector<CfRecord> cfs;
  cfs.reserve(jc.size());
  for (std::size_t i = 0; i < jc.size(); ++i) {
    const JsonWhere w = wc / i;
    const json& c = jc[i];
    const json& jid = detail::json_member(c, "id", w);
    if (!jid.is_number_integer() || jid.get<long long>() != static_cast<long long>(i))
      detail::json_fail(w / "id", "id " + detail::json_short(jid) + " should be " + std::to_string(i) +
                                      " (CF ids are the array positions)");
    const json& jp = detail::json_array(detail::json_member(c, "pcs", w), w / "pcs");
    if (jp.empty() || jp.size() > static_cast<std::size_t>(PcSet::kMaxPcs))
      detail::json_fail(w / "pcs", "a CF has 1 to 3 PCs, got " + std::to_string(jp.size()));
    CfRecord r;
    for (std::size_t k = 0; k < jp.size(); ++k) {
      const JsonWhere wp = w / "pcs" / k;
      const std::string tname = detail::json_string(detail::json_member(jp[k], "type", wp), wp / "type");
      const auto type = pc_type_from_string(tname);
      if (!type)
        detail::json_fail(wp / "type", "unknown PC type \"" + tname +
                                           "\" (expected one of f-f, e-f, f-e, v-f, f-v, e-e)");
      Pc pc;
      pc.type = *type;
      pc.a = detail::json_index(detail::json_member(jp[k], "a", wp), wp / "a");
      pc.b = detail::json_index(detail::json_member(jp[k], "b", wp), wp / "b");
      const char* field = "";
      if (std::string why = detail::check_pc(pc, a, b, &field); !why.empty())
        detail::json_fail(wp / field, why);
      if (!r.pcs.insert(pc)) detail::json_fail(wp, "PC " + to_string(pc) + " is repeated in this CF");
    }
    r.witness = read_witness(detail::json_member(c, "witness", w), w / "witness");
    if (auto it = c.find("dof"); it != c.end()) r.dof = json_small_int(*it, w / "dof", 0, 6);
    if (auto it = c.find("translation_dof"); it != c.end())
      r.translation_dof = json_small_int(*it, w / "translation_dof", 0, 3);
    if (auto it = c.find("pure_rotation"); it != c.end()) {
      if (!it->is_boolean()) detail::json_fail(w / "pure_rotation", "expected true or false, got " + detail::json_short(*it));
      r.pure_rotation = it->get<bool>();
    }
    cfs.push_back(r);
  }

  const JsonWhere wt = root / "transitions";
  const json& jt = detail::json_array(detail::json_member(j, "transitions", root), wt);
  std::vector<Transition> transitions;
  transitions.reserve(jt.size());
  for (std::size_t i = 0; i < jt.size(); ++i) {
    const JsonWhere w = wt / i;
    Transition t;
    t.from = CfId(detail::json_index(detail::json_member(jt[i], "from", w), w / "from"));
    t.to = CfId(detail::json_index(detail::json_member(jt[i], "to", w), w / "to"));
    const std::string kname = detail::json_string(detail::json_member(jt[i], "kind", w), w / "kind");
    const auto kind = transition_kind_from_string(kname);
    if (!kind)
      detail::json_fail(w / "kind", "unknown transition kind \"" + kname + "\" (expected gain, lose or change)");
    t.kind = *kind;
    transitions.push_back(t);
  }

  // Whatever the reader above accepted must also pass the schema, which says the same in
  // a form other programs can use (and catches what the reader does not look at).
  if (validate_schema) detail::validate_graph_schema(j, source);

  json meta = json::object();
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!is_reserved(it.key())) meta[it.key()] = it.value();

  auto impl = std::make_unique<CfGraph::Impl>();
  impl->a = std::move(a);
  impl->b = std::move(b);
  impl->cfs = std::move(cfs);
  impl->transitions = std::move(transitions);
  impl->metadata = meta.dump();
  impl->build(JsonLocator(root));
  return impl;
}

std::string errno_text() { return std::strerror(errno); }

}  // namespace

std::string CfGraph::to_json(int indent) const {
  const ojson j = graph_json(impl());
  if (indent < 0) return j.dump();
  std::string out;
  print(j, indent, 0, true, out);
  out += '\n';
  return out;
}

void CfGraph::save(const std::string& path) const {
  std::string bytes;
  if (is_cbor_path(path)) {
    const std::vector<std::uint8_t> cbor = ojson::to_cbor(graph_json(impl()));
    bytes.assign(cbor.begin(), cbor.end());
  } else {
    bytes = to_json(1);
  }
  detail::write_file_atomically(path, bytes, "writing graph");
}

CfGraph CfGraph::load(const std::string& path) { return load(path, GraphLoadOptions()); }

CfGraph CfGraph::load(const std::string& path, const GraphLoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("reading '" + path + "': cannot open: " + errno_text());
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("reading '" + path + "': read failed: " + errno_text());
  return from_bytes(bytes, path, is_cbor_path(path), options);
}

CfGraph CfGraph::from_bytes(const std::string& bytes, const std::string& source, bool cbor,
                            const GraphLoadOptions& options) {
  json j;
  if (cbor) {
    try {
      j = json::from_cbor(bytes.begin(), bytes.end());
    } catch (const json::exception& e) {
      throw Error("reading '" + source + "': not valid CBOR: " + e.what());
    }
  } else {
    try {
      j = json::parse(bytes);
    } catch (const json::parse_error& e) {
      throw Error("reading '" + source + "': not valid JSON: " + e.what());
    }
  }
  CfGraph g;
  g.impl_ = graph_from_json(j, source, options.validate_schema);
  return g;
}

namespace detail {

void write_file_atomically(const std::string& path, const std::string& bytes, const char* what) {
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash == 0 ? 1 : slash);
  std::string tmp = path + ".tmp-XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0)
    throw Error(std::string(what) + " '" + path + "': cannot create a temporary file in '" + dir +
                "': " + errno_text());
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = errno_text();
      ::close(fd);
      ::unlink(tmp.c_str());
      throw Error(std::string(what) + " '" + path + "': write failed: " + why);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string why = errno_text();
    ::unlink(tmp.c_str());
    throw Error(std::string(what) + " '" + path + "': write failed: " + why);
  }
  // mkstemp creates the file 0600; a graph is an ordinary document.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(tmp.c_str(), 0666 & ~mask);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = errno_text();
    ::unlink(tmp.c_str());
    throw Error(std::string(what) + " '" + path + "': cannot rename the temporary file into place: " + why);
  }
}

}  // namespace detail

}  // namespace cf

// The CF graph file (docs/spec.md, section 5): writing (deterministic, whole-or-nothing) and
// reading (JSON or CBOR, schema-validated, every fault named by file and JSON pointer).

#include "byte_input.hpp"
#include "graph_schema.hpp"
#include "input_file.hpp"
#include "json_util.hpp"
#include "model/graph_impl.hpp"
#include "polyhedron_json.hpp"

#include <cf/file_io.hpp>
#include <cf/version.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <sstream>

#include <sys/stat.h>

namespace cf {

namespace {

using internal::json;
using internal::JsonWhere;
using ojson = nlohmann::ordered_json;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

bool is_cbor_path(const std::string& path) {
  return ends_with(path, ".cbor") || ends_with(path, ".CBOR");
}

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
  if (r.num_planes > 0) {
    ojson planes = ojson::array();
    for (int i = 0; i < r.num_planes; ++i) {
      const auto& q = r.planes[static_cast<std::size_t>(i)];
      planes.push_back({q[0], q[1], q[2], q[3]});
    }
    c["planes"] = std::move(planes);
  }
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
/// models, cfs, transitions. Without items, cfs and transitions are empty arrays (the JSON
/// writer appends them itself: a DOM of 100,000 CFs costs seconds of malloc).
ojson graph_json(const CfGraph::Impl& g, bool with_items = true) {
  ojson root = ojson::object();
  root["format"] = "cf-graph";
  root["version"] = kGraphFormatVersion;
  root["units"] = "mm";
  const json meta = json::parse(g.metadata);
  for (auto it = meta.begin(); it != meta.end(); ++it) root[it.key()] = ojson(it.value());
  ojson models = ojson::object();
  models["A"] = ojson(internal::polyhedron_to_json(g.a));
  models["B"] = ojson(internal::polyhedron_to_json(g.b));
  root["models"] = std::move(models);
  ojson cfs = ojson::array();
  ojson tr = ojson::array();
  if (with_items) {
    for (std::size_t i = 0; i < g.cfs.size(); ++i) cfs.push_back(cf_json(i, g.cfs[i]));
    for (const Transition& t : g.transitions) tr.push_back(transition_json(t));
  }
  root["cfs"] = std::move(cfs);
  root["transitions"] = std::move(tr);
  return root;
}

// --- direct writing of the items, in the layout of nlohmann's dump() --------------------

void append_int(std::string& out, long long v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

/// Shortest round-trip digits (std::to_chars), laid out by nlohmann's rules
/// (dtoa_impl::format_buffer): plain decimals for exponents -4 < n <= 15, else d.ddde+XX.
/// nlohmann's own Grisu2 digits are not always the shortest (it writes -7.3743686707643326
/// for -7.374368670764333); both read back to the same double.
void append_double(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  if (v == 0) {
    out += std::signbit(v) ? "-0.0" : "0.0";
    return;
  }
  char buf[48];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
  const char* p = buf;
  if (*p == '-') {
    out += '-';
    ++p;
  }
  const char* e = std::find(p, static_cast<const char*>(r.ptr), 'e');
  char digits[24];
  int k = 0;
  for (const char* q = p; q < e && k < 24; ++q)
    if (*q != '.') digits[k++] = *q;
  int exp10 = 0;
  std::from_chars(e[1] == '+' ? e + 2 : e + 1, r.ptr, exp10);
  const int n = exp10 + 1;  // value = 0.d1d2...dk * 10^n
  constexpr int kMinExp = -4, kMaxExp = 15;
  if (k <= n && n <= kMaxExp) {
    out.append(digits, static_cast<std::size_t>(k));
    out.append(static_cast<std::size_t>(n - k), '0');
    out += ".0";
  } else if (0 < n && n <= kMaxExp) {
    out.append(digits, static_cast<std::size_t>(n));
    out += '.';
    out.append(digits + n, static_cast<std::size_t>(k - n));
  } else if (kMinExp < n && n <= 0) {
    out += "0.";
    out.append(static_cast<std::size_t>(-n), '0');
    out.append(digits, static_cast<std::size_t>(k));
  } else {
    out += digits[0];
    if (k > 1) {
      out += '.';
      out.append(digits + 1, static_cast<std::size_t>(k - 1));
    }
    out += 'e';
    int x = n - 1;
    out += x < 0 ? '-' : '+';
    x = x < 0 ? -x : x;
    if (x < 10) out += '0';
    append_int(out, x);
  }
}

void append_vec3(std::string& out, double x, double y, double z) {
  out += '[';
  append_double(out, x);
  out += ',';
  append_double(out, y);
  out += ',';
  append_double(out, z);
  out += ']';
}

/// One CF as one line, the same bytes as cf_json(id, r).dump().
void append_cf(std::string& out, std::size_t id, const CfRecord& r) {
  out += "{\"id\":";
  append_int(out, static_cast<long long>(id));
  out += ",\"pcs\":[";
  bool first = true;
  for (const Pc& pc : r.pcs) {
    if (!first) out += ',';
    first = false;
    out += "{\"type\":\"";
    out += to_string(pc.type);
    out += "\",\"a\":";
    append_int(out, pc.a);
    out += ",\"b\":";
    append_int(out, pc.b);
    out += '}';
  }
  out += "],\"witness\":{\"R\":[";
  const Mat3& R = r.witness.R_BA;
  for (int i = 0; i < 3; ++i) {
    if (i > 0) out += ',';
    append_vec3(out, R(i, 0), R(i, 1), R(i, 2));
  }
  out += "],\"t\":";
  append_vec3(out, r.witness.t_BA.x(), r.witness.t_BA.y(), r.witness.t_BA.z());
  out += '}';
  if (r.dof >= 0) {
    out += ",\"dof\":";
    append_int(out, r.dof);
  }
  if (r.translation_dof >= 0) {
    out += ",\"translation_dof\":";
    append_int(out, r.translation_dof);
  }
  if (r.dof >= 0 || r.translation_dof >= 0 || r.pure_rotation)
    out += r.pure_rotation ? ",\"pure_rotation\":true" : ",\"pure_rotation\":false";
  if (r.num_planes > 0) {
    out += ",\"planes\":[";
    for (int i = 0; i < r.num_planes; ++i) {
      const auto& q = r.planes[static_cast<std::size_t>(i)];
      if (i > 0) out += ',';
      out += '[';
      for (int k = 0; k < 4; ++k) {
        if (k > 0) out += ',';
        append_double(out, q[static_cast<std::size_t>(k)]);
      }
      out += ']';
    }
    out += ']';
  }
  out += '}';
}

void append_transition(std::string& out, const Transition& t) {
  out += "{\"from\":";
  append_int(out, t.from.value());
  out += ",\"to\":";
  append_int(out, t.to.value());
  out += ",\"kind\":\"";
  out += to_string(t.kind);
  out += "\"}";
}

/// Hands on what `out` holds and empties it (writing a file in pieces); null to keep all.
using Flush = std::function<void(std::string& out)>;
// A piece of a file written in pieces: large enough that writes are few, small against the
// graph (a 12-gon peg and hole writes 353 MB).
constexpr std::size_t kFlushBytes = std::size_t{4} << 20;

/// Appends the items, `sep` between them (",", or ",\n" plus padding).
void append_items(std::string& out, const CfGraph::Impl& g, bool cfs, const std::string& before,
                  const std::string& sep, const Flush* flush) {
  const std::size_t n = cfs ? g.cfs.size() : g.transitions.size();
  for (std::size_t i = 0; i < n; ++i) {
    out += i == 0 ? before : sep;
    if (cfs)
      append_cf(out, i, g.cfs[i]);
    else
      append_transition(out, g.transitions[i]);
    if (flush && out.size() >= kFlushBytes) (*flush)(out);
  }
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
  out += "\n" + std::string(static_cast<std::size_t>(indent * level), ' ') +
         (v.is_object() ? "}" : "]");
}

/// The graph's JSON text (CfGraph::to_json) appended to `out`, handed to `flush` in pieces
/// when it is set (the rest stays in `out`).
void emit_json(const CfGraph::Impl& g, int indent, std::string& out, const Flush* flush) {
  const ojson head = graph_json(g, false);
  if (indent < 0) {
    out = head.dump();
    const std::string tail = ",\"cfs\":[],\"transitions\":[]}";
    if (!ends_with(out, tail)) {  // cannot happen: keys are ours
      out = graph_json(g).dump();
      return;
    }
    out.resize(out.size() - tail.size());
    out += ",\"cfs\":[";
    append_items(out, g, true, "", ",", flush);
    out += "],\"transitions\":[";
    append_items(out, g, false, "", ",", flush);
    out += "]}";
    return;
  }
  print(head, indent, 0, true, out);
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  const std::string tail = ",\n" + pad + "\"cfs\": [],\n" + pad + "\"transitions\": []\n}";
  if (!ends_with(out, tail)) {  // cannot happen: keys are ours
    out.clear();
    print(graph_json(g), indent, 0, true, out);
    out += '\n';
    return;
  }
  out.resize(out.size() - tail.size());
  const std::string item_pad = "\n" + pad + pad;
  for (const bool cfs : {true, false}) {
    const bool empty = cfs ? g.cfs.empty() : g.transitions.empty();
    out += ",\n" + pad + (cfs ? "\"cfs\": [" : "\"transitions\": [");
    if (!empty) {
      append_items(out, g, cfs, item_pad, "," + item_pad, flush);
      out += "\n" + pad;
    }
    out += ']';
  }
  out += "\n}\n";
}

}  // namespace

std::string CfGraph::to_json(int indent) const {
  const Impl& g = impl();
  std::string out;
  out.reserve(4096 + g.cfs.size() * 400 + g.transitions.size() * 48);
  emit_json(g, indent, out, nullptr);
  return out;
}

void CfGraph::save(const std::string& path) const {
  if (is_cbor_path(path)) {
    const std::vector<std::uint8_t> cbor = ojson::to_cbor(graph_json(impl()));
    internal::write_file_atomically(path, std::string(cbor.begin(), cbor.end()), "writing graph");
    return;
  }
  // JSON goes to the file in pieces: a large graph's text is several times its records.
  const Impl& g = impl();
  write_streamed_outputs({{path,
                           [&g](const ByteSink& sink) {
                             std::string out;
                             out.reserve(kFlushBytes + 65536);
                             const Flush flush = [&sink](std::string& piece) {
                               sink(piece.data(), piece.size());
                               piece.clear();
                             };
                             emit_json(g, 1, out, &flush);
                             sink(out.data(), out.size());
                           }}},
                         {}, "writing graph");
}

CfGraph CfGraph::load(const std::string& path) { return load(path, GraphLoadOptions()); }

// The largest graph file read, as for any input (read_input_file).
constexpr std::size_t kMaxGraphFileBytes = std::size_t{1} << 31;

CfGraph CfGraph::load(const std::string& path, const GraphLoadOptions& options) {
  // Never blocks on a FIFO; a directory, a device or a FIFO is refused before reading.
  std::string why;
  const int fd = internal::open_input_file(path, why, kMaxGraphFileBytes);
  if (fd < 0) throw FileError("reading '" + path + "': cannot open: " + why);
  struct stat st {};
  if (::fstat(fd, &st) != 0) st.st_size = 0;
  const internal::ByteInput in(fd, static_cast<std::size_t>(st.st_size), path);
  CfGraph g;
  g.impl_ = internal::read_graph(in, is_cbor_path(path), options);
  return g;
}

CfGraph CfGraph::from_bytes(const std::string& bytes, const std::string& source, bool cbor,
                            const GraphLoadOptions& options) {
  const internal::ByteInput in(bytes.data(), bytes.size(), source);
  CfGraph g;
  g.impl_ = internal::read_graph(in, cbor, options);
  return g;
}

namespace internal {

void write_file_atomically(const std::string& path, const std::string& bytes, const char* what) {
  write_outputs({OutputFile{path, bytes}}, {}, what);
}

}  // namespace internal

}  // namespace cf

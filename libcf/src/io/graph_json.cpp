// The CF graph file (docs/spec.md, section 5): writing (deterministic, whole-or-nothing) and
// reading (JSON or CBOR, schema-validated, every fault named by file and JSON pointer).

#include "byte_input.hpp"
#include "graph_schema.hpp"
#include "graph_writer.hpp"
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

/// The file's head as one ordered value: format, version, units, metadata (sorted by key),
/// models, and cfs and transitions as empty arrays, which the writers fill item by item
/// (a DOM of 100,000 CFs costs seconds of malloc).
ojson graph_head(const CfGraph::Impl& g) {
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
  root["cfs"] = ojson::array();
  root["transitions"] = ojson::array();
  return root;
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
    internal::JsonSink sink(out);
    if (cfs)
      internal::write_cf(sink, i, g.cfs[i]);
    else
      internal::write_transition(sink, g.transitions[i]);
    if (flush && out.size() >= kFlushBytes) (*flush)(out);
  }
}

/// The graph as CBOR appended to `out`, handed to `flush` in pieces (the rest stays in
/// `out`): the head's members, then the items, through the same records as the JSON.
void emit_cbor(const CfGraph::Impl& g, std::string& out, const Flush& flush) {
  const ojson head = graph_head(g);
  internal::CborSink sink(out);
  sink.begin_object(head.size());
  for (auto it = head.begin(); it != head.end(); ++it) {
    sink.key(it.key());
    const bool cfs = it.key() == "cfs";
    if (!cfs && it.key() != "transitions") {
      internal::write_value(sink, it.value());
      continue;
    }
    sink.begin_array(cfs ? g.cfs.size() : g.transitions.size());
    for (std::size_t i = 0; i < (cfs ? g.cfs.size() : g.transitions.size()); ++i) {
      if (cfs)
        internal::write_cf(sink, i, g.cfs[i]);
      else
        internal::write_transition(sink, g.transitions[i]);
      if (out.size() >= kFlushBytes) flush(out);
    }
    sink.end_array();
  }
  sink.end_object();
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
  const ojson head = graph_head(g);
  if (indent < 0) {
    out = head.dump();
    // The head ends with the two empty arrays (graph_head puts them last).
    const std::string tail = ",\"cfs\":[],\"transitions\":[]}";
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
  // The file is written in pieces: a large graph's text is several times its records.
  const Impl& g = impl();
  const bool cbor = is_cbor_path(path);
  write_streamed_outputs({{path,
                           [&g, cbor](const ByteSink& sink) {
                             std::string out;
                             out.reserve(kFlushBytes + 65536);
                             const Flush flush = [&sink](std::string& piece) {
                               sink(piece.data(), piece.size());
                               piece.clear();
                             };
                             if (cbor)
                               emit_cbor(g, out, flush);
                             else
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

}  // namespace cf

#pragma once
// Private: writing a graph file. Each record (a CF, a transition) is described once, as
// values handed to a ValueSink; JsonSink writes them as JSON text (nlohmann's compact layout,
// shortest round-trip numbers) and CborSink as CBOR (RFC 8949), so that JSON and CBOR are one
// writer (docs/graph-format.md, "Writing").

#include <cf/graph.hpp>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace cf::internal {

/// Where a file's values go, in document order, is a sink: JsonSink or CborSink, with the
/// members begin_object(n), key, end_object, begin_array(n), end_array, integer,
/// unsigned_integer, number, boolean, string and null. Containers give their size first (CBOR
/// writes it before the items). The records are templates on the sink, so that a graph of
/// millions of transitions is written without a call per value.

/// Text of a number as nlohmann's dump() lays it out (shortest round-trip digits), of an
/// integer, and of a JSON string that needs escapes.
void append_double(std::string& out, double v);
void append_int(std::string& out, long long v);
void append_escaped(std::string& out, std::string_view v);

/// A JSON string: printable ASCII without '"' and '\\' (every name and kind of a record)
/// as it is, anything else escaped.
inline void append_string(std::string& out, std::string_view v) {
  for (const char c : v)
    if (c < 0x20 || c >= 0x7f || c == '"' || c == '\\') return append_escaped(out, v);
  out += '"';
  out.append(v.data(), v.size());
  out += '"';
}

/// JSON text appended to a string, without white space (as nlohmann's dump()).
class JsonSink {
 public:
  explicit JsonSink(std::string& out) : out_(out) {}
  void begin_object(std::size_t) { open('{'); }
  void key(std::string_view name) {
    separate();
    append_string(out_, name);
    out_ += ':';
    after_key_ = true;
  }
  void end_object() { close('}'); }
  void begin_array(std::size_t) { open('['); }
  void end_array() { close(']'); }
  void integer(std::int64_t v) {
    separate();
    append_int(out_, v);
  }
  void unsigned_integer(std::uint64_t v);
  void number(double v) {
    separate();
    append_double(out_, v);
  }
  void boolean(bool v) {
    separate();
    out_ += v ? "true" : "false";
  }
  void string(std::string_view v) {
    separate();
    append_string(out_, v);
  }
  void null() {
    separate();
    out_ += "null";
  }

 private:
  void open(char c) {
    separate();
    out_ += c;
    first_ = true;
  }
  void close(char c) {
    out_ += c;
    first_ = false;
  }
  // A ',' before every value but a container's first, and none after a key.
  void separate() {
    if (after_key_) {
      after_key_ = false;
    } else {
      if (!first_) out_ += ',';
      first_ = false;
    }
  }
  std::string& out_;
  bool first_ = true, after_key_ = false;
};

/// CBOR bytes appended to a string: definite lengths, the shortest integer heads, a double as
/// float32 when that is exact (as nlohmann's to_cbor).
class CborSink {
 public:
  explicit CborSink(std::string& out) : out_(out) {}
  void begin_object(std::size_t members) { head(5, members); }
  void key(std::string_view name) { string(name); }
  void end_object() {}
  void begin_array(std::size_t items) { head(4, items); }
  void end_array() {}
  void integer(std::int64_t v);
  void unsigned_integer(std::uint64_t v) { head(0, v); }
  void number(double v);
  void boolean(bool v) { out_ += static_cast<char>(v ? 0xf5 : 0xf4); }
  void string(std::string_view v);
  void null() { out_ += static_cast<char>(0xf6); }

 private:
  void head(unsigned major, std::uint64_t argument);
  std::string& out_;
};

// ---- the records ---------------------------------------------------------------------------

template <class Sink>
void write_vec3(Sink& sink, double x, double y, double z) {
  sink.begin_array(3);
  sink.number(x);
  sink.number(y);
  sink.number(z);
  sink.end_array();
}

/// One CF record, the `cfs` item at position `id` (docs/graph-format.md, "CFs").
template <class Sink>
void write_cf(Sink& sink, std::size_t id, const CfRecord& r) {
  const bool freedoms = r.dof >= 0 || r.translation_dof >= 0 || r.pure_rotation;
  sink.begin_object(3 + (r.dof >= 0) + (r.translation_dof >= 0) + freedoms + (r.num_planes > 0));
  sink.key("id");
  sink.unsigned_integer(id);
  sink.key("pcs");
  sink.begin_array(static_cast<std::size_t>(r.pcs.size()));
  for (const Pc& pc : r.pcs) {
    sink.begin_object(3);
    sink.key("type");
    sink.string(to_string(pc.type));
    sink.key("a");
    sink.integer(pc.a);
    sink.key("b");
    sink.integer(pc.b);
    sink.end_object();
  }
  sink.end_array();
  sink.key("witness");
  sink.begin_object(2);
  sink.key("R");
  sink.begin_array(3);
  const Mat3& R = r.witness.R_BA;
  for (int i = 0; i < 3; ++i) write_vec3(sink, R(i, 0), R(i, 1), R(i, 2));
  sink.end_array();
  sink.key("t");
  write_vec3(sink, r.witness.t_BA.x(), r.witness.t_BA.y(), r.witness.t_BA.z());
  sink.end_object();
  if (r.dof >= 0) {
    sink.key("dof");
    sink.integer(r.dof);
  }
  if (r.translation_dof >= 0) {
    sink.key("translation_dof");
    sink.integer(r.translation_dof);
  }
  if (freedoms) {
    sink.key("pure_rotation");
    sink.boolean(r.pure_rotation);
  }
  if (r.num_planes > 0) {
    sink.key("planes");
    sink.begin_array(static_cast<std::size_t>(r.num_planes));
    for (int i = 0; i < r.num_planes; ++i) {
      sink.begin_array(4);
      for (const double q : r.planes[static_cast<std::size_t>(i)]) sink.number(q);
      sink.end_array();
    }
    sink.end_array();
  }
  sink.end_object();
}

/// One transition (docs/graph-format.md, "Transitions").
template <class Sink>
void write_transition(Sink& sink, const Transition& t) {
  sink.begin_object(3);
  sink.key("from");
  sink.integer(t.from.value());
  sink.key("to");
  sink.integer(t.to.value());
  sink.key("kind");
  sink.string(to_string(t.kind));
  sink.end_object();
}

/// A JSON value (the models, the metadata).
template <class Sink>
void write_value(Sink& sink, const nlohmann::ordered_json& v) {
  using T = nlohmann::ordered_json::value_t;
  switch (v.type()) {
    case T::object:
      sink.begin_object(v.size());
      for (auto it = v.begin(); it != v.end(); ++it) {
        sink.key(it.key());
        write_value(sink, it.value());
      }
      sink.end_object();
      return;
    case T::array:
      sink.begin_array(v.size());
      for (const auto& item : v) write_value(sink, item);
      sink.end_array();
      return;
    case T::number_integer:
      sink.integer(v.get<std::int64_t>());
      return;
    case T::number_unsigned:
      sink.unsigned_integer(v.get<std::uint64_t>());
      return;
    case T::number_float:
      sink.number(v.get<double>());
      return;
    case T::boolean:
      sink.boolean(v.get<bool>());
      return;
    case T::string:
      sink.string(v.get_ref<const std::string&>());
      return;
    default:  // null (a graph's values are never binary)
      sink.null();
      return;
  }
}

}  // namespace cf::internal

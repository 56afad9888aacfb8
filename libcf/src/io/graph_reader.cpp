// Reading a graph file in one streaming pass (nlohmann's SAX interface, JSON or CBOR).
//
// Why not the DOM: a graph of 100,000 CFs is ~50 MB of JSON, and a std::map-based DOM of it
// costs seconds in malloc/free alone. Here the `cfs` and `transitions` arrays go straight into
// CfRecords and Transitions; only the small members (models, metadata) become a DOM, the
// "skeleton", which is validated against the schema with valijson. The item-level checks
// below mirror the schema's definitions of a CF, a PC, a pose and a transition (required
// members, types, ranges, no unknown members in PCs and witnesses); GraphLoadOptions::
// full_schema_check runs valijson over the whole document as well.

#include "graph_schema.hpp"
#include "json_util.hpp"
#include "model/graph_impl.hpp"
#include "polyhedron_json.hpp"

#include <cf/file_io.hpp>
#include <cf/version.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string_view>
#include <utility>

#include <simdjson.h>
#include <sstream>

namespace cf::internal {

namespace {

constexpr std::size_t kNoFault = static_cast<std::size_t>(-1);
/// Deepest nesting of arrays and objects accepted, in JSON and in CBOR.
constexpr std::size_t kMaxNesting = 256;

/// A CF's PCs as the file gives them (order kept for error pointers), checked against the
/// models once those are read.
struct RawPcs {
  std::array<Pc, PcSet::kMaxPcs> pcs{};
  int num_pcs = 0;  // as given; > 3 is reported at the end of the array
};

/// One scalar event, kept light (strings by pointer) so that the hot path allocates nothing.
struct Scalar {
  enum Type : std::uint8_t { kNull, kBool, kInt, kUint, kFloat, kString } type = kNull;
  bool b = false;
  std::int64_t i = 0;
  std::uint64_t u = 0;
  double d = 0;
  const std::string* s = nullptr;

  bool is_number() const { return type == kInt || type == kUint || type == kFloat; }
  bool is_integer() const { return type == kInt || type == kUint; }
  double number() const {
    return type == kInt ? static_cast<double>(i) : type == kUint ? static_cast<double>(u) : d;
  }
  json to_json() const {
    switch (type) {
      case kNull:
        return json(nullptr);
      case kBool:
        return json(b);
      case kInt:
        return json(i);
      case kUint:
        return json(u);
      case kFloat:
        return json(d);
      default:
        return json(*s);
    }
  }
  std::string shown() const { return json_short(to_json()); }
};

enum class Ctx : std::uint8_t {
  kDocument,     // expecting the root value
  kRoot,         // in the root object
  kCapture,      // inside a DOM-captured container (models, metadata)
  kSkip,         // inside a container whose content is ignored
  kCfs,          // in the cfs array
  kCf,           // in a CF object
  kPcs,          // in a CF's pcs array
  kPc,           // in a PC object
  kWitness,      // in a witness object
  kR,            // in witness.R
  kRRow,         // in a row of witness.R
  kT,            // in witness.t
  kTransitions,  // in the transitions array
  kTransition,   // in a transition object
};

/// What the next value is, set by the preceding key.
enum class Field : std::uint8_t {
  kNone,
  kRootOther,
  kRootCfs,
  kRootTransitions,
  kCfId,
  kCfPcs,
  kCfWitness,
  kCfDof,
  kCfTdof,
  kCfPure,
  kCfOther,
  kPcType,
  kPcA,
  kPcB,
  kPcOther,
  kWR,
  kWT,
  kWOther,
  kTrFrom,
  kTrTo,
  kTrKind,
  kTrOther,
};

/// The root's `format` and `version` (null: absent): a cf-graph of the version this library
/// reads, else the reason, naming the member.
void check_format(const json& format, const JsonWhere& root) {
  if (!format.is_string() || format.get<std::string>() != "cf-graph")
    json_fail(root / "format", "format is " + json_short(format) + ", expected \"cf-graph\"");
}
void check_version(const json& version, const JsonWhere& root) {
  if (!version.is_number_integer() || version.get<long long>() != kGraphFormatVersion)
    json_fail(root / "version", "version " + json_short(version) +
                                    " is not supported (this library reads version " +
                                    std::to_string(kGraphFormatVersion) + ")");
}
void check_format_and_version(const json* format, const json* version, const JsonWhere& root) {
  if (format == nullptr) json_fail(root, "missing member \"format\": not a cf-graph file");
  check_format(*format, root);
  if (version == nullptr) json_fail(root, "missing member \"version\"");
  check_version(*version, root);
}

/// The root's format and version, read before the graph when other members come first (a
/// file that is no cf-graph, or of another version, is refused before anything is
/// allocated for what it holds). The scan stops once both are read.
struct Header {
  json format, version;
  bool has_format = false, has_version = false;
  bool complete() const { return has_format && has_version; }
  void check(const std::string& source) const {
    check_format_and_version(has_format ? &format : nullptr, has_version ? &version : nullptr,
                             JsonWhere{source, ""});
  }
};

class GraphSax {
 public:
  GraphSax(const std::string& source, bool cbor) : source_(source), cbor_(cbor) {
    stack_.reserve(16);
    seen_.reserve(16);
    push(Ctx::kDocument);
  }

  // --- nlohmann SAX interface -----------------------------------------------------------
  bool null() {
    Scalar s;
    s.type = Scalar::kNull;
    return scalar(s);
  }
  bool boolean(bool v) {
    Scalar s;
    s.type = Scalar::kBool;
    s.b = v;
    return scalar(s);
  }
  bool number_integer(std::int64_t v) {
    Scalar s;
    s.type = Scalar::kInt;
    s.i = v;
    return scalar(s);
  }
  bool number_unsigned(std::uint64_t v) {
    Scalar s;
    s.type = Scalar::kUint;
    s.u = v;
    return scalar(s);
  }
  bool number_float(double v, const std::string&) {
    Scalar s;
    s.type = Scalar::kFloat;
    s.d = v;
    return scalar(s);
  }
  bool string(std::string& v) {
    Scalar s;
    s.type = Scalar::kString;
    s.s = &v;
    return scalar(s);
  }
  bool binary(json::binary_t&) {
    Scalar s;
    s.type = Scalar::kNull;
    return scalar(s);
  }
  bool start_object(std::size_t) { return start(true); }
  bool start_array(std::size_t) { return start(false); }
  bool end_object() { return end(); }
  bool end_array() { return end(); }
  bool key(std::string& k);
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) {
    throw Error("reading '" + source_ + "': not valid " + (cbor_ ? "CBOR" : "JSON") + ": " +
                e.what());
  }

  // --- results --------------------------------------------------------------------------
  json skeleton = json::object();  ///< every root member except the cfs and transitions items
  std::vector<CfRecord> cfs;       ///< PC sets still empty: filled from raw_pcs after the parse
  std::vector<RawPcs> raw_pcs;
  std::vector<Transition> transitions;
  bool have_cfs = false, have_transitions = false;
  /// Checks the header when a member other than format and version comes before both
  /// (cfgen writes them first): a scan of the file's root for them, which throws.
  std::function<void()> header_scan;
  std::string fault_pointer;  ///< first item-level fault, reported after the parse
  std::string fault_what;
  bool faulted() const { return !fault_what.empty(); }

 private:
  bool scalar(const Scalar& s);
  bool start(bool object);
  bool end();

  // scalar() inside an item (a CF, a PC, a witness, a transition), by context.
  void item_scalar(Ctx c, const Scalar& s);
  void cf_scalar(const Scalar& s);
  void pc_scalar(const Scalar& s);
  void transition_scalar(const Scalar& s);
  // An index into a table (0 .. 2^31 - 1), else a fault.
  bool read_index(const Scalar& s, std::int32_t& out);
  // An integer in lo..hi into out, else a fault.
  void read_small_int(const Scalar& s, int lo, int hi, int& out);
  // start() of a container: a root member; one inside a captured member; one inside an item
  // (returns its context).
  void start_at_root(bool object);
  void start_captured(bool object);
  Ctx start_in_item(Ctx c, bool object);
  Ctx start_in_cf(bool object);
  Ctx start_in_witness(bool object);

  /// Records the first fault; later item-level events are then only tracked structurally.
  void fault(std::string pointer, std::string what) {
    if (!faulted()) {
      fault_pointer = std::move(pointer);
      fault_what = std::move(what);
    }
  }
  std::string cf_ptr() const { return "/cfs/" + std::to_string(cfs.size() - 1); }
  std::string pc_ptr() const { return cf_ptr() + "/pcs/" + std::to_string(pc_count_ - 1); }
  std::string tr_ptr() const { return "/transitions/" + std::to_string(transitions.size() - 1); }
  std::string field_ptr() const;
  static const char* container_name(bool object) { return object ? "an object" : "an array"; }

  void capture_value(json value);
  bool item_context(Ctx c) const {
    return c != Ctx::kDocument && c != Ctx::kRoot && c != Ctx::kCapture;
  }

  /// A member named twice in one object: JSON leaves its meaning open and readers differ
  /// (the last wins, the first wins, or, here before, two `cfs` arrays joined), so it is
  /// refused. `seen_` holds, per open item object, a bit per known member read; the root's
  /// names are kept whole; a captured object (models, metadata) is asked itself.
  void duplicate(std::string pointer, const std::string& name) {
    fault(std::move(pointer),
          "member \"" + printable(name) + "\" appears twice in this object (each name once)");
  }
  void push(Ctx c) {
    stack_.push_back(c);
    seen_.push_back(0);
  }
  bool first_time(Field f) {
    const std::uint64_t bit = std::uint64_t{1} << static_cast<unsigned>(f);
    const bool first = (seen_.back() & bit) == 0;
    seen_.back() |= bit;
    return first;
  }

  const std::string& source_;
  bool cbor_;
  std::vector<Ctx> stack_;
  std::vector<std::uint64_t> seen_;  // parallel to stack_
  std::vector<std::string> root_keys_;
  bool format_ok_ = false, version_ok_ = false, header_scanned_ = false;
  /// A root format or version checked as it is read: a file that is no graph stops here.
  void check_header_member(const json& value) {
    if (faulted()) return;  // a second "format" is reported as such
    const JsonWhere root{source_, ""};
    if (root_key_ == "format") {
      check_format(value, root);
      format_ok_ = true;
    } else if (root_key_ == "version") {
      check_version(value, root);
      version_ok_ = true;
    }
  }
  Field field_ = Field::kNone;
  std::string root_key_;
  // Capture state: the DOM containers being filled and the key inside each object.
  std::vector<json*> capture_;
  std::string capture_key_;
  // Per-item state.
  int pc_count_ = 0, row_ = 0, col_ = 0, t_count_ = 0;
  bool has_id_ = false, has_pcs_ = false, has_witness_ = false;
  bool has_type_ = false, has_a_ = false, has_b_ = false, has_R_ = false, has_t_ = false;
  bool has_from_ = false, has_to_ = false, has_kind_ = false;
  Pc pc_;
};

std::string GraphSax::field_ptr() const {
  switch (field_) {
    case Field::kCfId:
      return cf_ptr() + "/id";
    case Field::kCfPcs:
      return cf_ptr() + "/pcs";
    case Field::kCfWitness:
      return cf_ptr() + "/witness";
    case Field::kCfDof:
      return cf_ptr() + "/dof";
    case Field::kCfTdof:
      return cf_ptr() + "/translation_dof";
    case Field::kCfPure:
      return cf_ptr() + "/pure_rotation";
    case Field::kPcType:
      return pc_ptr() + "/type";
    case Field::kPcA:
      return pc_ptr() + "/a";
    case Field::kPcB:
      return pc_ptr() + "/b";
    case Field::kWR:
      return cf_ptr() + "/witness/R";
    case Field::kWT:
      return cf_ptr() + "/witness/t";
    case Field::kTrFrom:
      return tr_ptr() + "/from";
    case Field::kTrTo:
      return tr_ptr() + "/to";
    case Field::kTrKind:
      return tr_ptr() + "/kind";
    case Field::kRootCfs:
      return "/cfs";
    case Field::kRootTransitions:
      return "/transitions";
    default:
      return "/";
  }
}

void GraphSax::capture_value(json value) {
  json* top = capture_.back();
  if (top->is_object()) {
    (*top)[capture_key_] = std::move(value);
  } else {
    top->push_back(std::move(value));
  }
}

bool GraphSax::key(std::string& k) {
  switch (stack_.back()) {
    case Ctx::kRoot:
      root_key_ = k;
      field_ = k == "cfs"           ? Field::kRootCfs
               : k == "transitions" ? Field::kRootTransitions
                                    : Field::kRootOther;
      if (std::find(root_keys_.begin(), root_keys_.end(), k) != root_keys_.end())
        duplicate("/" + k, k);
      else
        root_keys_.push_back(k);
      if (k != "format" && k != "version" && !(format_ok_ && version_ok_) && !header_scanned_) {
        header_scanned_ = true;
        if (header_scan) header_scan();
      }
      break;
    case Ctx::kCapture:
      capture_key_ = k;
      if (capture_.back()->is_object() && capture_.back()->contains(k))
        duplicate("/" + root_key_, k);
      break;
    case Ctx::kCf:
      field_ = k == "id"                ? Field::kCfId
               : k == "pcs"             ? Field::kCfPcs
               : k == "witness"         ? Field::kCfWitness
               : k == "dof"             ? Field::kCfDof
               : k == "translation_dof" ? Field::kCfTdof
               : k == "pure_rotation"   ? Field::kCfPure
                                        : Field::kCfOther;  // CFs may carry extra members
      if (field_ != Field::kCfOther && !first_time(field_)) duplicate(cf_ptr(), k);
      break;
    case Ctx::kPc:
      field_ = k == "type" ? Field::kPcType
               : k == "a"  ? Field::kPcA
               : k == "b"  ? Field::kPcB
                           : Field::kPcOther;
      if (field_ == Field::kPcOther)
        fault(pc_ptr(), "unexpected member \"" + printable(k) + "\" (a PC has type, a and b)");
      else if (!first_time(field_))
        duplicate(pc_ptr(), k);
      break;
    case Ctx::kWitness:
      field_ = k == "R" ? Field::kWR : k == "t" ? Field::kWT : Field::kWOther;
      if (field_ == Field::kWOther)
        fault(cf_ptr() + "/witness",
              "unexpected member \"" + printable(k) + "\" (a witness has R and t)");
      else if (!first_time(field_))
        duplicate(cf_ptr() + "/witness", k);
      break;
    case Ctx::kTransition:
      field_ = k == "from"   ? Field::kTrFrom
               : k == "to"   ? Field::kTrTo
               : k == "kind" ? Field::kTrKind
                             : Field::kTrOther;
      if (field_ != Field::kTrOther && !first_time(field_)) duplicate(tr_ptr(), k);
      break;
    default:
      break;  // kSkip
  }
  return true;
}

bool GraphSax::scalar(const Scalar& s) {
  const Ctx c = stack_.back();
  if (c == Ctx::kDocument) {
    skeleton = s.to_json();  // reported as "not an object" after the parse
    return true;
  }
  if (c == Ctx::kRoot) {
    if (field_ == Field::kRootOther) {
      check_header_member(s.to_json());
      skeleton[root_key_] = s.to_json();
    } else
      fault(field_ptr(), std::string("expected an array, got ") + s.shown());
    return true;
  }
  if (c == Ctx::kCapture) {
    capture_value(s.to_json());
    return true;
  }
  if (faulted() || c == Ctx::kSkip) return true;
  item_scalar(c, s);
  return true;
}

bool GraphSax::read_index(const Scalar& s, std::int32_t& out) {
  if (s.is_integer() &&
      (s.type == Scalar::kUint ? s.u <= 2147483647ULL : (s.i >= 0 && s.i <= 2147483647LL))) {
    out =
        static_cast<std::int32_t>(s.type == Scalar::kUint ? s.u : static_cast<std::uint64_t>(s.i));
    return true;
  }
  fault(field_ptr(), "expected a non-negative integer index, got " + s.shown());
  return false;
}

void GraphSax::read_small_int(const Scalar& s, int lo, int hi, int& out) {
  const bool ok = s.is_integer() && (s.type == Scalar::kUint ? s.u <= static_cast<std::uint64_t>(hi)
                                                             : (s.i >= lo && s.i <= hi));
  if (!ok) {
    fault(field_ptr(), "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                           ", got " + s.shown());
    return;
  }
  out = static_cast<int>(s.type == Scalar::kUint ? static_cast<std::int64_t>(s.u) : s.i);
}

void GraphSax::item_scalar(Ctx c, const Scalar& s) {
  switch (c) {
    case Ctx::kCfs:
      cfs.emplace_back();
      raw_pcs.emplace_back();
      fault(cf_ptr(), "expected a CF object, got " + s.shown());
      break;
    case Ctx::kCf:
      cf_scalar(s);
      break;
    case Ctx::kPcs:
      ++pc_count_;
      fault(pc_ptr(), "expected a PC object, got " + s.shown());
      break;
    case Ctx::kPc:
      pc_scalar(s);
      break;
    case Ctx::kWitness:
      if (field_ == Field::kWR) has_R_ = true;
      if (field_ == Field::kWT) has_t_ = true;
      fault(field_ptr(), "expected an array, got " + s.shown());
      break;
    case Ctx::kR:
      fault(cf_ptr() + "/witness/R/" + std::to_string(row_),
            "expected a row of 3 numbers, got " + s.shown());
      ++row_;
      break;
    case Ctx::kRRow: {
      if (!s.is_number())
        fault(cf_ptr() + "/witness/R/" + std::to_string(row_ - 1) + "/" + std::to_string(col_),
              "expected a number, got " + s.shown());
      else if (col_ < 3)
        cfs.back().witness.R_BA(row_ - 1, col_) = s.number();
      ++col_;
      break;
    }
    case Ctx::kT:
      if (!s.is_number())
        fault(cf_ptr() + "/witness/t/" + std::to_string(t_count_),
              "expected a number, got " + s.shown());
      else if (t_count_ < 3)
        cfs.back().witness.t_BA(t_count_) = s.number();
      ++t_count_;
      break;
    case Ctx::kTransitions:
      transitions.emplace_back();
      fault(tr_ptr(), "expected a transition object, got " + s.shown());
      break;
    case Ctx::kTransition:
      transition_scalar(s);
      break;
    default:
      break;
  }
}

void GraphSax::cf_scalar(const Scalar& s) {
  CfRecord& r = cfs.back();
  switch (field_) {
    case Field::kCfId: {
      has_id_ = true;
      const auto expected = static_cast<std::int64_t>(cfs.size() - 1);
      if (!s.is_integer() ||
          (s.type == Scalar::kInt ? s.i : static_cast<std::int64_t>(s.u)) != expected)
        fault(field_ptr(), "id " + s.shown() + " should be " + std::to_string(expected) +
                               " (CF ids are the array positions)");
      break;
    }
    case Field::kCfPcs:
      has_pcs_ = true;
      fault(field_ptr(), "expected an array, got " + s.shown());
      break;
    case Field::kCfWitness:
      has_witness_ = true;
      fault(field_ptr(), "expected an object, got " + s.shown());
      break;
    case Field::kCfDof:
      read_small_int(s, 0, 6, r.dof);
      break;
    case Field::kCfTdof:
      read_small_int(s, 0, 3, r.translation_dof);
      break;
    case Field::kCfPure:
      if (s.type != Scalar::kBool)
        fault(field_ptr(), "expected true or false, got " + s.shown());
      else
        r.pure_rotation = s.b;
      break;
    default:
      break;
  }
}

void GraphSax::pc_scalar(const Scalar& s) {
  switch (field_) {
    case Field::kPcType: {
      has_type_ = true;
      if (s.type != Scalar::kString) {
        fault(field_ptr(), "expected a string, got " + s.shown());
        break;
      }
      const auto type = pc_type_from_string(*s.s);
      if (!type)
        fault(field_ptr(),
              "unknown PC type \"" + *s.s + "\" (expected one of f-f, e-f, f-e, v-f, f-v, e-e)");
      else
        pc_.type = *type;
      break;
    }
    case Field::kPcA:
      has_a_ = true;
      read_index(s, pc_.a);
      break;
    case Field::kPcB:
      has_b_ = true;
      read_index(s, pc_.b);
      break;
    default:
      break;
  }
}

void GraphSax::transition_scalar(const Scalar& s) {
  Transition& t = transitions.back();
  std::int32_t v = -1;
  switch (field_) {
    case Field::kTrFrom:
      has_from_ = true;
      if (read_index(s, v)) t.from = CfId(v);
      break;
    case Field::kTrTo:
      has_to_ = true;
      if (read_index(s, v)) t.to = CfId(v);
      break;
    case Field::kTrKind: {
      has_kind_ = true;
      if (s.type != Scalar::kString) {
        fault(field_ptr(), "expected a string, got " + s.shown());
        break;
      }
      const auto kind = transition_kind_from_string(*s.s);
      if (!kind)
        fault(field_ptr(),
              "unknown transition kind \"" + *s.s + "\" (expected gain, lose or change)");
      else
        t.kind = *kind;
      break;
    }
    default:
      break;
  }
}

bool GraphSax::start(bool object) {
  // nlohmann's CBOR reader recurses once per level: without a cap, a few hundred thousand
  // nested arrays overflow the stack. JSON is capped by JsonWalker at the same depth.
  if (cbor_ && stack_.size() > kMaxNesting)
    throw Error("reading '" + source_ + "': not valid CBOR: nesting deeper than " +
                std::to_string(kMaxNesting) + " levels");
  const Ctx c = stack_.back();
  if (c == Ctx::kDocument) {
    if (!object) {
      skeleton = json::array();  // reported after the parse; the rest is ignored
      push(Ctx::kSkip);
      return true;
    }
    push(Ctx::kRoot);
    return true;
  }
  if (c == Ctx::kRoot) {
    start_at_root(object);
    return true;
  }
  if (c == Ctx::kCapture) {
    start_captured(object);
    return true;
  }
  if (faulted() || c == Ctx::kSkip) {
    push(Ctx::kSkip);
    return true;
  }
  push(start_in_item(c, object));
  return true;
}

void GraphSax::start_at_root(bool object) {
  if (field_ == Field::kRootOther) {
    check_header_member(object ? json::object() : json::array());
    json& slot = skeleton[root_key_];
    slot = object ? json::object() : json::array();
    capture_.push_back(&slot);
    push(Ctx::kCapture);
  } else if (!object && field_ == Field::kRootCfs) {
    have_cfs = true;
    push(Ctx::kCfs);
  } else if (!object && field_ == Field::kRootTransitions) {
    have_transitions = true;
    push(Ctx::kTransitions);
  } else {
    if (field_ == Field::kRootCfs)
      have_cfs = true;
    else
      have_transitions = true;
    fault(field_ptr(), std::string("expected an array, got ") + container_name(object));
    push(Ctx::kSkip);
  }
}

void GraphSax::start_captured(bool object) {
  json* top = capture_.back();
  json* child;
  if (top->is_object()) {
    json& slot = (*top)[capture_key_];
    slot = object ? json::object() : json::array();
    child = &slot;
  } else {
    top->push_back(object ? json::object() : json::array());
    child = &top->back();
  }
  capture_.push_back(child);
  push(Ctx::kCapture);
}

Ctx GraphSax::start_in_item(Ctx c, bool object) {
  Ctx next = Ctx::kSkip;
  switch (c) {
    case Ctx::kCfs:
      cfs.emplace_back();
      raw_pcs.emplace_back();
      if (object) {
        next = Ctx::kCf;
        has_id_ = has_pcs_ = has_witness_ = false;
      } else {
        fault(cf_ptr(), "expected a CF object, got an array");
      }
      break;
    case Ctx::kCf:
      next = start_in_cf(object);
      break;
    case Ctx::kPcs:
      ++pc_count_;
      if (object) {
        next = Ctx::kPc;
        has_type_ = has_a_ = has_b_ = false;
        pc_ = Pc{};
      } else {
        fault(pc_ptr(), "expected a PC object, got an array");
      }
      break;
    case Ctx::kPc:
      fault(field_ptr(), std::string("expected a scalar, got ") + container_name(object));
      break;
    case Ctx::kWitness:
      next = start_in_witness(object);
      break;
    case Ctx::kR:
      ++row_;
      if (!object && row_ <= 3) {
        col_ = 0;
        next = Ctx::kRRow;
      } else if (object) {
        fault(cf_ptr() + "/witness/R/" + std::to_string(row_ - 1),
              "expected a row of 3 numbers, got an object");
      }
      break;
    case Ctx::kRRow:
      fault(cf_ptr() + "/witness/R/" + std::to_string(row_ - 1) + "/" + std::to_string(col_),
            std::string("expected a number, got ") + container_name(object));
      break;
    case Ctx::kT:
      fault(cf_ptr() + "/witness/t/" + std::to_string(t_count_),
            std::string("expected a number, got ") + container_name(object));
      break;
    case Ctx::kTransitions:
      transitions.emplace_back();
      if (object) {
        next = Ctx::kTransition;
        has_from_ = has_to_ = has_kind_ = false;
      } else {
        fault(tr_ptr(), "expected a transition object, got an array");
      }
      break;
    case Ctx::kTransition:
      if (field_ == Field::kTrOther) break;  // extra members allowed, skipped
      fault(field_ptr(), std::string("expected a scalar, got ") + container_name(object));
      break;
    default:
      break;
  }
  return next;
}

Ctx GraphSax::start_in_cf(bool object) {
  if (field_ == Field::kCfPcs && !object) {
    has_pcs_ = true;
    pc_count_ = 0;
    return Ctx::kPcs;
  }
  if (field_ == Field::kCfWitness && object) {
    has_witness_ = true;
    has_R_ = has_t_ = false;
    return Ctx::kWitness;
  }
  if (field_ == Field::kCfOther) return Ctx::kSkip;  // extra members of a CF are allowed, ignored
  if (field_ == Field::kCfPcs) has_pcs_ = true;
  if (field_ == Field::kCfWitness) has_witness_ = true;
  const char* want = field_ == Field::kCfPcs       ? "an array"
                     : field_ == Field::kCfWitness ? "an object"
                                                   : "a scalar";
  fault(field_ptr(), std::string("expected ") + want + ", got " + container_name(object));
  return Ctx::kSkip;
}

Ctx GraphSax::start_in_witness(bool object) {
  if (field_ == Field::kWR) has_R_ = true;
  if (field_ == Field::kWT) has_t_ = true;
  if (!object && field_ == Field::kWR) {
    row_ = 0;
    return Ctx::kR;
  }
  if (!object && field_ == Field::kWT) {
    t_count_ = 0;
    return Ctx::kT;
  }
  fault(field_ptr(), std::string("expected an array, got ") + container_name(object));
  return Ctx::kSkip;
}

bool GraphSax::end() {
  const Ctx c = stack_.back();
  stack_.pop_back();
  seen_.pop_back();
  if (c == Ctx::kCapture) {
    capture_.pop_back();
    return true;
  }
  if (faulted() || c == Ctx::kSkip) return true;
  // The pointer is built only for a fault: this runs once per CF, PC and transition.
  auto missing = [&](auto where, bool has, const char* name) {
    if (!has) fault(where(), std::string("missing member \"") + name + "\"");
  };
  const auto at_cf = [&] { return cf_ptr(); };
  const auto at_pc = [&] { return pc_ptr(); };
  const auto at_witness = [&] { return cf_ptr() + "/witness"; };
  const auto at_tr = [&] { return tr_ptr(); };
  switch (c) {
    case Ctx::kCf:
      missing(at_cf, has_id_, "id");
      missing(at_cf, has_pcs_, "pcs");
      missing(at_cf, has_witness_, "witness");
      break;
    case Ctx::kPcs:
      if (pc_count_ < 1 || pc_count_ > PcSet::kMaxPcs)
        fault(cf_ptr() + "/pcs", "a CF has 1 to 3 PCs, got " + std::to_string(pc_count_));
      break;
    case Ctx::kPc: {
      missing(at_pc, has_type_, "type");
      missing(at_pc, has_a_, "a");
      missing(at_pc, has_b_, "b");
      RawPcs& r = raw_pcs.back();
      if (pc_count_ <= PcSet::kMaxPcs) r.pcs[static_cast<std::size_t>(pc_count_ - 1)] = pc_;
      r.num_pcs = pc_count_;
      break;
    }
    case Ctx::kWitness: {
      missing(at_witness, has_R_, "R");
      missing(at_witness, has_t_, "t");
      if (faulted()) break;
      const char* field = "";
      if (std::string why = check_witness(cfs.back().witness, &field); !why.empty())
        fault(cf_ptr() + "/witness/" + field, why);
      break;
    }
    case Ctx::kR:
      if (row_ != 3) fault(cf_ptr() + "/witness/R", "expected 3 rows, got " + std::to_string(row_));
      break;
    case Ctx::kRRow:
      if (col_ != 3)
        fault(cf_ptr() + "/witness/R/" + std::to_string(row_ - 1),
              "expected 3 numbers, got " + std::to_string(col_));
      break;
    case Ctx::kT:
      if (t_count_ != 3)
        fault(cf_ptr() + "/witness/t", "expected 3 numbers, got " + std::to_string(t_count_));
      break;
    case Ctx::kTransition:
      missing(at_tr, has_from_, "from");
      missing(at_tr, has_to_, "to");
      missing(at_tr, has_kind_, "kind");
      break;
    default:
      break;
  }
  return true;
}

/// nlohmann SAX handler that reads a CBOR root's format and version and stops; anything
/// else it skips. A syntax error ends the scan quietly: the reading pass reports it.
class HeaderSax {
 public:
  explicit HeaderSax(Header& h) : h_(h) {}
  bool null() { return value(json(nullptr)); }
  bool boolean(bool v) { return value(json(v)); }
  bool number_integer(std::int64_t v) { return value(json(v)); }
  bool number_unsigned(std::uint64_t v) { return value(json(v)); }
  bool number_float(double v, const std::string&) { return value(json(v)); }
  bool string(std::string& v) { return value(json(v)); }
  bool binary(json::binary_t&) { return value(json(nullptr)); }
  bool start_object(std::size_t) { return start(json::object()); }
  bool start_array(std::size_t) { return start(json::array()); }
  bool end_object() { return end(); }
  bool end_array() { return end(); }
  bool key(std::string& k) {
    if (depth_ == 1) target_ = k == "format" ? &h_.format : k == "version" ? &h_.version : nullptr;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) {
    return false;
  }

 private:
  bool value(json v) {
    if (depth_ == 1 && target_ != nullptr) take(std::move(v));
    return !h_.complete();
  }
  bool start(json empty) {
    if (depth_ == 0 && !empty.is_object()) return false;  // the reading pass says so
    if (depth_ == 1 && target_ != nullptr) take(std::move(empty));
    if (++depth_ > kMaxNesting) return false;
    return !h_.complete();
  }
  bool end() {
    finished_ = --depth_ == 0;
    return !finished_ && !h_.complete();
  }
  void take(json v) {
    *target_ = std::move(v);
    (target_ == &h_.format ? h_.has_format : h_.has_version) = true;
    target_ = nullptr;
  }
  Header& h_;
  std::size_t depth_ = 0;
  json* target_ = nullptr;

 public:
  bool finished_ = false;  ///< the root object was read to its end
};

/// Drives a SAX handler from simdjson's On-Demand parser: strict RFC 8259 with UTF-8
/// checked, and every value visited, so the whole document is validated (On Demand checks
/// what it is asked for). Errors give the line and column of where the parser stopped.
/// CBOR goes through nlohmann's SAX parser.
class JsonWalker {
 public:
  JsonWalker(const std::string& bytes, const std::string& source) : source_(source) {
    static_assert(kReadSlack >= simdjson::SIMDJSON_PADDING,
                  "read_input_file's slack must cover simdjson's padding");
    if (bytes.capacity() - bytes.size() >= simdjson::SIMDJSON_PADDING) {
      text_ = simdjson::padded_string_view(bytes);  // reads into the string's spare capacity
    } else {
      copy_ = simdjson::padded_string(bytes.data(), bytes.size());
      text_ = copy_;
    }
  }

  template <class Sax>
  void parse(Sax& sax) {
    // An empty or blank document is refused before simdjson sees it, to say so plainly.
    const char* first = text_.data();
    const char* const end = first + text_.size();
    while (first < end && (*first == ' ' || *first == '\n' || *first == '\r' || *first == '\t'))
      ++first;
    if (first == end) fail_at(end, "empty input, expected a JSON value");
    // Errors of simdjson's first pass (invalid UTF-8, an unclosed string, a raw control
    // character) come before there is a document to ask for a position.
    if (const auto e = parser_.iterate(text_).get(doc_); e != simdjson::SUCCESS)
      throw Error("reading '" + source_ + "': not valid JSON: " + simdjson::error_message(e));
    iterating_ = true;
    simdjson::ondemand::json_type type{};
    check(doc_.type().get(type), first);
    if (type == simdjson::ondemand::json_type::object ||
        type == simdjson::ondemand::json_type::array) {
      simdjson::ondemand::value root;
      check(doc_.get_value().get(root), first);
      value(root, sax, 0);
    } else {
      scalar(doc_, type, sax, first);
    }
    // current_location() is OUT_OF_BOUNDS once every token has been read.
    if (const char* rest = nullptr; doc_.current_location().get(rest) == simdjson::SUCCESS)
      fail_at(rest, "unexpected content after the JSON value");
  }

 private:
  /// Line and column (1-based) of a position in the text, and what is there.
  [[noreturn]] void fail_at(const char* at, const std::string& what) const {
    const char* const begin = text_.data();
    const char* const end = begin + text_.size();
    if (at == nullptr || at < begin || at > end) at = end;
    std::size_t line = 1, col = 1;
    for (const char* q = begin; q < at; ++q) {
      if (*q == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    std::string near;
    if (at < end) {
      const unsigned char c = static_cast<unsigned char>(*at);
      near = c >= 0x20 && c < 0x7f ? std::string(" near '") + *at + "'"
                                   : " near byte " + std::to_string(c);
    } else {
      near = " at the end of the input";
    }
    throw Error("reading '" + source_ + "': not valid JSON: syntax error at line " +
                std::to_string(line) + ", column " + std::to_string(col) + near + ": " + what);
  }

 public:
  /// Reads the root object's format and version into `h` with a parser of its own, stopping
  /// once both are read; false when a syntax error stops the scan (the walk reports it).
  bool scan_header(Header& h) {
    simdjson::ondemand::parser parser;
    simdjson::ondemand::document doc;
    simdjson::ondemand::object root;
    if (parser.iterate(text_).get(doc) != simdjson::SUCCESS ||
        doc.get_object().get(root) != simdjson::SUCCESS)
      return false;
    for (auto item : root) {
      simdjson::ondemand::field field;
      std::string_view key;
      if (std::move(item).get(field) != simdjson::SUCCESS ||
          field.unescaped_key().get(key) != simdjson::SUCCESS)
        return false;
      if (key != "format" && key != "version") continue;  // its value is skipped
      json& out = key == "format" ? h.format : h.version;
      if (!scalar_json(field.value(), out)) return false;
      (key == "format" ? h.has_format : h.has_version) = true;
      if (h.complete()) return true;
    }
    return true;
  }

  /// A value as nlohmann JSON for the header's messages (containers as empty ones).
  static bool scalar_json(simdjson::ondemand::value v, json& out) {
    using simdjson::ondemand::json_type;
    json_type type{};
    if (v.type().get(type) != simdjson::SUCCESS) return false;
    std::string_view str;
    std::int64_t i = 0;
    double d = 0;
    bool b = false;
    switch (type) {
      case json_type::string:
        if (v.get_string().get(str) != simdjson::SUCCESS) return false;
        out = std::string(str);
        return true;
      case json_type::number:
        if (v.get_int64().get(i) == simdjson::SUCCESS)
          out = i;
        else if (v.get_double().get(d) == simdjson::SUCCESS)
          out = d;
        else
          return false;
        return true;
      case json_type::boolean:
        if (v.get_bool().get(b) != simdjson::SUCCESS) return false;
        out = b;
        return true;
      case json_type::object:
        out = json::object();
        return true;
      case json_type::array:
        out = json::array();
        return true;
      default: {  // null, or a literal the walk reports ("nul")
        bool is_null = false;
        if (v.is_null().get(is_null) != simdjson::SUCCESS || !is_null) return false;
        out = nullptr;
        return true;
      }
    }
  }

 private:
  /// Where the parser stopped; `fallback` when it cannot say.
  const char* here(const char* fallback) {
    const char* at = nullptr;
    if (!iterating_ || doc_.current_location().get(at) != simdjson::SUCCESS) return fallback;
    return at;
  }

  /// An error reading the value that starts at `at`, reported there.
  void check(simdjson::error_code e, const char* at) {
    if (e != simdjson::SUCCESS) fail_at(at, what(e));
  }
  /// An error moving through a container, reported where the parser stopped.
  void check_step(simdjson::error_code e, const char* fallback) {
    if (e != simdjson::SUCCESS) fail_at(here(fallback), what(e));
  }
  static std::string what(simdjson::error_code e) {
    switch (e) {
      case simdjson::T_ATOM_ERROR:
      case simdjson::F_ATOM_ERROR:
      case simdjson::N_ATOM_ERROR:
        return "invalid literal";
      case simdjson::STRING_ERROR:
        return "invalid string (an unknown escape or an unpaired UTF-16 surrogate)";
      case simdjson::NUMBER_ERROR:
        return "invalid number";
      default:
        return simdjson::error_message(e);
    }
  }

  template <class Sax>
  void value(simdjson::ondemand::value v, Sax& sax, std::size_t depth) {
    using simdjson::ondemand::json_type;
    const char* at = v.raw_json_token().data();  // the value's first byte
    json_type type{};
    check(v.type().get(type), at);
    switch (type) {
      case json_type::object: {
        if (depth >= kMaxNesting)
          fail_at(at, "nesting deeper than " + std::to_string(kMaxNesting) + " levels");
        simdjson::ondemand::object object;
        check(v.get_object().get(object), at);
        sax.start_object(static_cast<std::size_t>(-1));
        for (auto item : object) {
          simdjson::ondemand::field field;
          check_step(std::move(item).get(field), at);
          // The key's position first: unescaping consumes it.
          const char* key_at = field.key().raw();
          std::string_view key;
          check(field.unescaped_key().get(key), key_at);
          key_.assign(key.data(), key.size());
          sax.key(key_);
          value(field.value(), sax, depth + 1);
        }
        sax.end_object();
        return;
      }
      case json_type::array: {
        if (depth >= kMaxNesting)
          fail_at(at, "nesting deeper than " + std::to_string(kMaxNesting) + " levels");
        simdjson::ondemand::array array;
        check(v.get_array().get(array), at);
        sax.start_array(static_cast<std::size_t>(-1));
        for (auto item : array) {
          simdjson::ondemand::value element;
          check_step(std::move(item).get(element), at);
          value(element, sax, depth + 1);
        }
        sax.end_array();
        return;
      }
      default:
        scalar(v, type, sax, at);
        return;
    }
  }

  /// A scalar value or scalar document (simdjson's value and document share the getters).
  template <class Node, class Sax>
  void scalar(Node& node, simdjson::ondemand::json_type type, Sax& sax, const char* at) {
    using simdjson::ondemand::json_type;
    switch (type) {
      case json_type::number: {
        simdjson::ondemand::number n;
        if (node.get_number().get(n) != simdjson::SUCCESS)
          return number_fallback(node.raw_json_token(), sax, at);
        return emit_number(n, sax);
      }
      case json_type::string: {
        std::string_view str;
        check(node.get_string().get(str), at);
        string_.assign(str.data(), str.size());
        sax.string(string_);
        return;
      }
      case json_type::boolean: {
        bool b = false;
        if (node.get_bool().get(b) != simdjson::SUCCESS) fail_at(at, "invalid literal");
        sax.boolean(b);
        return;
      }
      case json_type::null: {
        bool is_null = false;
        if (node.is_null().get(is_null) != simdjson::SUCCESS || !is_null)
          fail_at(at, "invalid literal");
        sax.null();
        return;
      }
      default:
        fail_at(at, "expected a value");
    }
  }

  template <class Sax>
  void emit_number(simdjson::ondemand::number n, Sax& sax) {
    switch (n.get_number_type()) {
      case simdjson::ondemand::number_type::signed_integer:
        sax.number_integer(n.get_int64());
        return;
      case simdjson::ondemand::number_type::unsigned_integer:
        sax.number_unsigned(n.get_uint64());
        return;
      default:
        sax.number_float(n.get_double(), kEmpty);
        return;
    }
  }

  /// simdjson refuses integers past 64 bits, which JSON allows and nlohmann reads as doubles;
  /// any other number it refuses is reported with its position.
  template <class Sax>
  void number_fallback(simdjson::simdjson_result<std::string_view> token, Sax& sax,
                       const char* at) {
    std::string_view raw;
    if (std::move(token).get(raw) != simdjson::SUCCESS) fail_at(at, "invalid number");
    // The token runs to the next structural character: the number, then at most white space
    // (anything else, '1e400z' say, is not a number).
    std::size_t len = 0;
    while (len < raw.size() && std::strchr("+-.0123456789eE", raw[len]) != nullptr) ++len;
    if (raw.find_first_not_of(" \t\n\r", len) != std::string_view::npos)
      fail_at(at, kInvalidNumber);
    raw = raw.substr(0, len);
    const std::string_view digits = raw.substr(!raw.empty() && raw[0] == '-' ? 1 : 0);
    const bool long_integer = digits.size() >= 20 && digits[0] != '0' &&
                              digits.find_first_not_of("0123456789") == std::string_view::npos;
    double d = 0;
    const auto r = std::from_chars(raw.data(), raw.data() + raw.size(), d);
    if (long_integer && r.ec == std::errc()) {
      sax.number_float(d, kEmpty);
      return;
    }
    if (r.ec == std::errc::result_out_of_range) fail_at(at, "number out of the range of a double");
    fail_at(at, kInvalidNumber);
  }

  inline static const std::string kEmpty;
  static constexpr const char* kInvalidNumber =
      "invalid number (RFC 8259: an optional minus, digits without leading zeros, an optional "
      "fraction and "
      "exponent)";
  simdjson::padded_string copy_;       // when the caller's bytes have no padding
  simdjson::padded_string_view text_;  // simdjson reads up to SIMDJSON_PADDING bytes past the end
  const std::string& source_;
  simdjson::ondemand::parser parser_;
  simdjson::ondemand::document doc_;
  bool iterating_ = false;  // doc_ is valid
  std::string key_, string_;
};

class JsonLocator final : public FaultLocator {
 public:
  explicit JsonLocator(const JsonWhere& root) : root_(root) {}
  [[noreturn]] void cf_fault(std::size_t cf, const std::string& what) const override {
    json_fail(root_ / "cfs" / cf, what);
  }
  [[noreturn]] void pc_fault(std::size_t cf, std::size_t pc, const char* field,
                             const std::string& what) const override {
    json_fail(root_ / "cfs" / cf / "pcs" / pc / field, what);
  }
  [[noreturn]] void transition_fault(std::size_t t, const char* field,
                                     const std::string& what) const override {
    json_fail(root_ / "transitions" / t / field, what);
  }
  [[noreturn]] void metadata_fault(const std::string& what) const override {
    json_fail(root_, what);
  }

 private:
  const JsonWhere& root_;
};

bool is_reserved(const std::string& key) {
  return key == "format" || key == "version" || key == "units" || key == "models" || key == "cfs" ||
         key == "transitions";
}

}  // namespace

std::unique_ptr<CfGraph::Impl> read_graph(const std::string& bytes, const std::string& source,
                                          bool cbor, const GraphLoadOptions& options) {
  const char* const data = bytes.data();
  const std::size_t size = bytes.size();
  GraphSax sax(source, cbor);
  if (cbor) {
    sax.header_scan = [&] {
      Header header;
      HeaderSax scan(header);
      json::sax_parse(data, data + size, &scan, json::input_format_t::cbor, false);
      if (header.complete() || scan.finished_) header.check(source);
    };
    json::sax_parse(data, data + size, &sax, json::input_format_t::cbor);
  } else {
    JsonWalker walker(bytes, source);
    sax.header_scan = [&] {
      Header header;
      if (walker.scan_header(header)) header.check(source);
    };
    walker.parse(sax);
  }

  const JsonWhere root{source, ""};
  const json& j = sax.skeleton;
  if (!j.is_object()) json_fail(root, "expected a cf-graph object, got " + json_short(j));
  // The reading's first fault (a member named twice, a CF that is not one) before the
  // header's values: the header scan has read format and version already, and a second
  // "format" must not be reported as the first one's value.
  if (sax.faulted())
    throw Error("reading '" + source + "' at " + sax.fault_pointer + ": " + sax.fault_what);
  {
    const auto f = j.find("format"), v = j.find("version");
    check_format_and_version(f == j.end() ? nullptr : &*f, v == j.end() ? nullptr : &*v, root);
    const json& u = json_member(j, "units", root);
    if (!u.is_string() || u.get<std::string>() != "mm")
      json_fail(root / "units", "units " + json_short(u) + " are not supported, expected \"mm\"");
  }
  const JsonWhere wm = root / "models";
  const json& jm = json_member(j, "models", root);
  if (!sax.have_cfs) json_fail(root, "missing member \"cfs\"");
  if (!sax.have_transitions) json_fail(root, "missing member \"transitions\"");
  auto impl = std::make_unique<CfGraph::Impl>();
  impl->a = polyhedron_from_json(json_member(jm, "A", wm), wm / "A");
  impl->b = polyhedron_from_json(json_member(jm, "B", wm), wm / "B");

  const JsonLocator where(root);
  impl->cfs = std::move(sax.cfs);
  for (std::size_t i = 0; i < impl->cfs.size(); ++i) {
    const RawPcs& r = sax.raw_pcs[i];
    PcSet& set = impl->cfs[i].pcs;
    for (int k = 0; k < r.num_pcs; ++k) {
      const Pc& pc = r.pcs[static_cast<std::size_t>(k)];
      const char* field = "";
      if (std::string why = check_pc(pc, impl->a, impl->b, &field); !why.empty())
        where.pc_fault(i, static_cast<std::size_t>(k), field, why);
      if (!set.insert(pc))
        json_fail(root / "cfs" / i / "pcs" / static_cast<std::size_t>(k),
                  "PC " + to_string(pc) + " is repeated in this CF");
    }
  }
  sax.raw_pcs = {};

  if (options.validate_schema) {
    if (options.full_schema_check) {
      validate_graph_schema(
          cbor ? json::from_cbor(data, data + size) : json::parse(data, data + size), source);
    } else {
      json skeleton = j;
      skeleton["cfs"] = json::array();
      skeleton["transitions"] = json::array();
      validate_graph_schema(skeleton, source);
    }
  }

  json meta = json::object();
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!is_reserved(it.key())) meta[it.key()] = it.value();
  impl->metadata = meta.dump(-1, ' ', false, json::error_handler_t::replace);
  impl->transitions = std::move(sax.transitions);
  impl->build(where);
  return impl;
}

}  // namespace cf::internal

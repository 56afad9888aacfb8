// Reading a graph file in one streaming pass: JSON through JsonStream (json_stream.hpp), CBOR
// through nlohmann's reader, both as SAX events into GraphSax, from a ByteInput read in
// pieces (docs/graph-format.md, "Reading").
//
// The `cfs` and `transitions` arrays go straight into CfRecords and Transitions; only the
// other members (models, metadata) become a DOM, the "skeleton", at most one value per 32
// bytes of the file, which is validated against the schema with valijson. The item-level
// checks below hold whatever the schema's definitions of a CF, a PC, a pose, a plane and a
// transition say (required members, types, ranges, no unknown members in PCs and witnesses;
// tests/libcf/graph_reader_test.cpp refuses every schema violation of an item through them);
// GraphLoadOptions::full_schema_check runs valijson over each item as well, one at a time.

#include "byte_input.hpp"
#include "graph_schema.hpp"
#include "json_stream.hpp"
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
#include <memory>
#include <string_view>
#include <unordered_set>
#include <utility>

#include <simdjson.h>
#include <istream>
#include <sstream>

namespace cf::internal {

namespace {

constexpr std::size_t kNoFault = static_cast<std::size_t>(-1);
// The root members other than cfs and transitions (the models, the metadata) are held as a
// DOM of 16 to 80 bytes a value (32 for a value in an array, counting its growth): at most one
// value per 32 bytes of the file keeps that near the file's size, and 2^21 values (a model of
// about 500,000 vertices) are always accepted.
constexpr std::size_t kBytesPerCapturedValue = 32;
constexpr std::size_t kMinCapturedValues = std::size_t{1} << 21;

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
  kPlanes,       // in a CF's planes array
  kPlane,        // in one plane, [n_x, n_y, n_z, d]
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
  kCfPlanes,
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

/// A DOM built from SAX events: the open containers, innermost last, and the name of the
/// next member of the innermost object.
struct DomBuilder {
  std::vector<json*> open;
  std::string key;
  /// `v` as the next member or item of the innermost container; where it now is.
  json* add(json v) {
    json* top = open.back();
    if (top->is_object()) {
      json& slot = (*top)[key];
      slot = std::move(v);
      return &slot;
    }
    top->push_back(std::move(v));
    return &top->back();
  }
  void start(bool object) { open.push_back(add(object ? json::object() : json::array())); }
};

/// The full schema check (GraphLoadOptions::full_schema_check): each item of cfs and
/// transitions becomes a DOM of its own, validated against its definition in the schema when
/// it ends, so that the check holds one item at a time. The first violation is kept, to be
/// reported after the reader's own faults.
class ItemSchemaCheck {
 public:
  explicit ItemSchemaCheck(const std::string& source) : source_(source) {}
  bool active() const { return !dom_.open.empty(); }
  void start_item(bool object, bool is_cf, std::size_t index) {
    item_ = object ? json::object() : json::array();
    dom_.open.assign(1, &item_);
    is_cf_ = is_cf;
    index_ = index;
  }
  void start(bool object) { dom_.start(object); }
  void key(std::string_view k) { dom_.key.assign(k.data(), k.size()); }
  void value(json v) { dom_.add(std::move(v)); }
  void end() {
    dom_.open.pop_back();
    if (!dom_.open.empty() || !violation.empty()) return;
    try {
      validate_graph_item(item_, is_cf_, index_, source_);
    } catch (const Error& e) {
      violation = e.what();
    }
  }
  std::string violation;  ///< the first, as the error to throw

 private:
  const std::string& source_;
  json item_;
  DomBuilder dom_;
  bool is_cf_ = false;
  std::size_t index_ = 0;
};

class GraphSax {
 public:
  /// `input_bytes`: the file's size, which bounds what its models and metadata may hold.
  GraphSax(const std::string& source, bool cbor, std::size_t input_bytes)
      : capture_budget_(std::max(kMinCapturedValues, input_bytes / kBytesPerCapturedValue)),
        source_(source),
        cbor_(cbor) {
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
  bool key(std::string& k) { return key(std::string_view(k)); }
  bool key(std::string_view k);
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
  /// Set for the full schema check.
  std::unique_ptr<ItemSchemaCheck> schema_items;
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
  std::string plane_ptr() const { return cf_ptr() + "/planes/" + std::to_string(plane_count_ - 1); }
  std::string tr_ptr() const { return "/transitions/" + std::to_string(transitions.size() - 1); }
  std::string field_ptr() const;
  static const char* container_name(bool object) { return object ? "an object" : "an array"; }

  void capture_value(json value);
  /// One more value in the models and metadata, within capture_budget_.
  void count_captured();
  std::size_t captured_ = 0;
  std::size_t capture_budget_;
  bool item_context(Ctx c) const {
    return c != Ctx::kDocument && c != Ctx::kRoot && c != Ctx::kCapture;
  }

  /// A member named twice in one object: JSON leaves its meaning open and readers differ
  /// (the last wins, the first wins, or, here before, two `cfs` arrays joined), so it is
  /// refused. `seen_` holds, per open item object, a bit per known member read; the root's
  /// names are kept whole; a captured object (models, metadata) is asked itself.
  void duplicate(std::string pointer, std::string_view name) {
    fault(std::move(pointer), "member \"" + printable(std::string(name)) +
                                  "\" appears twice in this object (each name once)");
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
  std::unordered_set<std::string> root_keys_;
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
  // Capture state: the DOM being filled (models, metadata).
  DomBuilder capture_;
  // Per-item state.
  int pc_count_ = 0, row_ = 0, col_ = 0, t_count_ = 0, plane_count_ = 0, plane_col_ = 0;
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
    case Field::kCfPlanes:
      return cf_ptr() + "/planes";
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

void GraphSax::count_captured() {
  if (++captured_ <= capture_budget_) return;
  // Refused at once: the members are held as a DOM, several times their size in the file.
  throw Error("reading '" + source_ + "' at /" + printable(root_key_) +
              ": the members other than cfs and transitions hold more than " +
              std::to_string(capture_budget_) +
              " values; a graph's models and metadata may hold one value per " +
              std::to_string(kBytesPerCapturedValue) + " bytes of the file (at least " +
              std::to_string(kMinCapturedValues) + ")");
}

void GraphSax::capture_value(json value) {
  count_captured();
  capture_.add(std::move(value));
}

bool GraphSax::key(std::string_view k) {
  if (schema_items && schema_items->active()) schema_items->key(k);
  switch (stack_.back()) {
    case Ctx::kRoot:
      root_key_ = k;
      count_captured();  // each root member is held
      field_ = k == "cfs"           ? Field::kRootCfs
               : k == "transitions" ? Field::kRootTransitions
                                    : Field::kRootOther;
      if (!root_keys_.emplace(k).second) duplicate("/" + std::string(k), k);
      if (k != "format" && k != "version" && !(format_ok_ && version_ok_) && !header_scanned_) {
        header_scanned_ = true;
        if (header_scan) header_scan();
      }
      break;
    case Ctx::kCapture:
      capture_.key = k;
      if (capture_.open.back()->is_object() && capture_.open.back()->contains(capture_.key))
        duplicate("/" + root_key_, k);
      break;
    case Ctx::kCf:
      field_ = k == "id"                ? Field::kCfId
               : k == "pcs"             ? Field::kCfPcs
               : k == "witness"         ? Field::kCfWitness
               : k == "dof"             ? Field::kCfDof
               : k == "translation_dof" ? Field::kCfTdof
               : k == "pure_rotation"   ? Field::kCfPure
               : k == "planes"          ? Field::kCfPlanes
                                        : Field::kCfOther;  // CFs may carry extra members
      if (field_ != Field::kCfOther && !first_time(field_)) duplicate(cf_ptr(), k);
      break;
    case Ctx::kPc:
      field_ = k == "type" ? Field::kPcType
               : k == "a"  ? Field::kPcA
               : k == "b"  ? Field::kPcB
                           : Field::kPcOther;
      if (field_ == Field::kPcOther)
        fault(pc_ptr(),
              "unexpected member \"" + printable(std::string(k)) + "\" (a PC has type, a and b)");
      else if (!first_time(field_))
        duplicate(pc_ptr(), k);
      break;
    case Ctx::kWitness:
      field_ = k == "R" ? Field::kWR : k == "t" ? Field::kWT : Field::kWOther;
      if (field_ == Field::kWOther)
        fault(cf_ptr() + "/witness",
              "unexpected member \"" + printable(std::string(k)) + "\" (a witness has R and t)");
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
  if (schema_items && schema_items->active()) schema_items->value(s.to_json());
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
    case Ctx::kPlanes:
      ++plane_count_;
      fault(plane_ptr(), "expected 4 numbers, got " + s.shown());
      break;
    case Ctx::kPlane:
      if (!s.is_number())
        fault(plane_ptr() + "/" + std::to_string(plane_col_),
              "expected a number, got " + s.shown());
      else if (plane_count_ <= PcSet::kMaxPcs && plane_col_ < 4)
        cfs.back().planes[static_cast<std::size_t>(plane_count_ - 1)]
                         [static_cast<std::size_t>(plane_col_)] = s.number();
      ++plane_col_;
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
    case Field::kCfPlanes:
      fault(field_ptr(), "expected an array, got " + s.shown());
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
  // nested arrays overflow the stack. JSON is capped by JsonStream at the same depth.
  if (cbor_ && stack_.size() > kMaxNesting)
    throw Error("reading '" + source_ + "': not valid CBOR: nesting deeper than " +
                std::to_string(kMaxNesting) + " levels");
  const Ctx c = stack_.back();
  if (schema_items && schema_items->active())
    schema_items->start(object);
  else if (schema_items && !faulted() && (c == Ctx::kCfs || c == Ctx::kTransitions))
    schema_items->start_item(object, c == Ctx::kCfs,
                             c == Ctx::kCfs ? cfs.size() : transitions.size());
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
    capture_.open.push_back(&slot);
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
  count_captured();
  capture_.start(object);
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
    case Ctx::kPlanes:
      ++plane_count_;
      if (object) {
        fault(plane_ptr(), "expected 4 numbers, got an object");
      } else {
        plane_col_ = 0;
        next = Ctx::kPlane;
      }
      break;
    case Ctx::kPlane:
      fault(plane_ptr() + "/" + std::to_string(plane_col_),
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
  if (field_ == Field::kCfPlanes && !object) {
    plane_count_ = 0;
    return Ctx::kPlanes;
  }
  if (field_ == Field::kCfOther) return Ctx::kSkip;  // extra members of a CF are allowed, ignored
  if (field_ == Field::kCfPcs) has_pcs_ = true;
  if (field_ == Field::kCfWitness) has_witness_ = true;
  const char* want = field_ == Field::kCfPcs || field_ == Field::kCfPlanes ? "an array"
                     : field_ == Field::kCfWitness                         ? "an object"
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
  if (schema_items && schema_items->active()) schema_items->end();
  const Ctx c = stack_.back();
  stack_.pop_back();
  seen_.pop_back();
  if (c == Ctx::kCapture) {
    capture_.open.pop_back();
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
    case Ctx::kPlanes:
      // One per PC, checked against the PCs once both are read (read_graph).
      if (plane_count_ < 1 || plane_count_ > PcSet::kMaxPcs)
        fault(cf_ptr() + "/planes", "a CF has 1 to 3 planes, got " + std::to_string(plane_count_));
      else
        cfs.back().num_planes = plane_count_;
      break;
    case Ctx::kPlane:
      if (plane_col_ != 4)
        fault(plane_ptr(), "expected 4 numbers, got " + std::to_string(plane_col_));
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

/// A CF's planes as the file gives them, one per PC in the file's order, put in the order of
/// its PcSet.
void order_planes(CfRecord& r, const RawPcs& raw, const JsonWhere& where) {
  if (r.num_planes == 0) return;
  if (r.num_planes != raw.num_pcs)
    json_fail(where, std::to_string(r.num_planes) + " planes for " + std::to_string(raw.num_pcs) +
                         " PCs (one per PC, in the PCs' order)");
  const auto given = r.planes;
  for (int k = 0; k < raw.num_pcs; ++k)
    for (int j = 0; j < r.pcs.size(); ++j)
      if (r.pcs[j] == raw.pcs[static_cast<std::size_t>(k)])
        r.planes[static_cast<std::size_t>(j)] = given[static_cast<std::size_t>(k)];
}

bool is_reserved(const std::string& key) {
  return key == "format" || key == "version" || key == "units" || key == "models" || key == "cfs" ||
         key == "transitions";
}

}  // namespace

std::unique_ptr<CfGraph::Impl> read_graph(const ByteInput& in, bool cbor,
                                          const GraphLoadOptions& options) {
  const std::string& source = in.source();
  GraphSax sax(source, cbor, in.size());
  if (options.validate_schema && options.full_schema_check)
    sax.schema_items = std::make_unique<ItemSchemaCheck>(source);
  if (cbor) {
    sax.header_scan = [&] {
      Header header;
      HeaderSax scan(header);
      ByteInputBuf buf(in);
      std::istream text(&buf);
      json::sax_parse(text, &scan, json::input_format_t::cbor, false);
      if (header.complete() || scan.finished_) header.check(source);
    };
    ByteInputBuf buf(in);
    std::istream text(&buf);
    json::sax_parse(text, &sax, json::input_format_t::cbor);
  } else {
    JsonStream stream(in);
    sax.header_scan = [&] {
      Header header;
      if (stream.scan_header(header.format, header.has_format, header.version, header.has_version))
        header.check(source);
    };
    stream.parse(sax);
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
    order_planes(impl->cfs[i], r, root / "cfs" / i / "planes");
  }
  sax.raw_pcs = {};

  if (options.validate_schema) {
    json skeleton = j;
    skeleton["cfs"] = json::array();
    skeleton["transitions"] = json::array();
    validate_graph_schema(skeleton, source);
    if (sax.schema_items && !sax.schema_items->violation.empty())
      throw Error(sax.schema_items->violation);
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

#pragma once
// Private: a JSON text read in windows and handed to a SAX handler (nlohmann's interface), so
// that a graph file is never held whole nor indexed whole (docs/graph-format.md, "Reading").
//
// simdjson checks and reads every value, but it needs a value's whole text and an index of 4
// bytes per structural character, which for a graph's 2.8 million transitions is larger than
// the file. So the root object is framed here member by member, and an array or object longer
// than kBatchBytes item by item; simdjson parses at most about kBatchBytes at a time, in place.
// Items laid out one a line (as cfgen writes them) go in batches to simdjson's DOM parser,
// which checks a batch whole before anything is emitted (line_batch); any other layout is
// framed item by item by a scan of strings and brackets and read by the On-Demand parser,
// which gives a fault's position (framed_batch). Every byte is checked by simdjson or by the
// framing's strict rules (white space, ':', ',', brackets); errors give the line and column.

#include "byte_input.hpp"

#include <cf/types.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include <simdjson.h>
#include <nlohmann/json.hpp>

namespace cf::internal {

/// Deepest nesting of arrays and objects accepted, in JSON and in CBOR.
inline constexpr std::size_t kMaxNesting = 256;

/// The input's bytes from a cursor on, read in pieces into one buffer that keeps
/// simdjson's padding allocated past its data. Offsets from the cursor stay valid across
/// fill(); pointers do not.
class TextWindow {
 public:
  explicit TextWindow(const ByteInput& in);

  /// At least `n` bytes from the cursor unless the input ends first (then false).
  bool fill(std::size_t n);
  char* cur() { return buf_.data() + pos_; }
  std::size_t avail() const { return len_ - pos_; }
  void advance(std::size_t n) { pos_ += n; }
  /// Skips white space; false when the input ends first.
  bool skip_space();
  /// Offset from the cursor just past the value that starts at `from`; when the input ends
  /// before it does, avail() and `complete` false. The value is framed, not checked. A
  /// container not closed within `limit` bytes stops the scan there: cut_short() is then
  /// true (and `complete` false).
  std::size_t value_end(std::size_t from, bool& complete, std::size_t limit);
  bool cut_short() const { return cut_short_; }
  /// Bytes allocated from `p` on (simdjson reads up to its padding past a value's end).
  std::size_t room(const char* p) const {
    return buf_.size() - static_cast<std::size_t>(p - buf_.data());
  }
  /// "syntax error at line L, column C near 'x': what" for a byte held (else the end).
  [[noreturn]] void fail_at(const char* at, const std::string& what) const;
  const std::string& source() const { return in_.source(); }

 private:
  std::size_t scan_string(std::size_t i, bool& done);
  std::size_t scan_container(std::size_t i, bool& done);
  void drop_consumed();

  const ByteInput& in_;
  std::vector<char> buf_;  // data [0, len_), then at least kSlack bytes
  std::size_t pos_ = 0;    // the cursor
  std::size_t len_ = 0;    // bytes held
  std::size_t read_ = 0;   // input offset of buf_[len_]
  std::size_t line_ = 1;   // line and column of buf_[0]
  std::size_t col_ = 1;
  bool ended_ = false;  // the input has no more bytes
  // Container scan state, kept across refills.
  std::string opens_;  // the open brackets, innermost last
  bool in_string_ = false, escaped_ = false;
  std::size_t stop_at_ = 0;  // the container scan's limit, an offset from the cursor
  bool cut_short_ = false;
};

/// A number simdjson refuses: an integer past 64 bits becomes the nearest double (as
/// nlohmann reads it) with an empty result; anything else gives the reason.
std::string long_integer_value(std::string_view raw, double& d);

/// Drives a SAX handler over a JSON text: strict RFC 8259, UTF-8 checked, every value
/// visited. The root object's `cfs` and `transitions` arrays are read item by item.
class JsonStream {
 public:
  explicit JsonStream(const ByteInput& in) : in_(in), w_(in) {}

  template <class Sax>
  void parse(Sax& sax);

  /// Reads the root object's format and version (as nlohmann values) with a window of its
  /// own, skipping other members unparsed; false when a syntax error stops the scan (the
  /// reading pass reports it).
  bool scan_header(nlohmann::json& format, bool& has_format, nlohmann::json& version,
                   bool& has_version);

 private:
  template <class Sax>
  void framed_value(Sax& sax, std::size_t depth);
  template <class Sax>
  void members(Sax& sax, std::size_t depth);
  template <class Sax>
  void items(Sax& sax, std::size_t depth);
  enum class LineBatch { kNone, kMore, kEnded };
  template <class Sax>
  LineBatch line_batch(Sax& sax);
  template <class Sax>
  bool framed_batch(Sax& sax, std::size_t depth);
  template <class Sax>
  void emit(simdjson::dom::element e, Sax& sax);
  template <class Sax>
  void parse_span(std::size_t begin, std::size_t end, bool as_items, Sax& sax, std::size_t depth);
  std::string member_name();
  /// Skips white space; the input ending there is a fault of structure.
  void skip_space_or_fail();
  /// Moves past a container's opening bracket; true, and past `close` too, when it is empty.
  bool opened_empty(char close);
  /// Offset of the first byte at or after `i` (from the cursor) that is not white space.
  std::size_t skip_space_at(std::size_t i);
  void expect(char c);

  template <class Sax>
  void value(simdjson::ondemand::value v, Sax& sax, std::size_t depth);
  template <class Node, class Sax>
  void scalar(Node& node, simdjson::ondemand::json_type type, Sax& sax, const char* at);
  template <class Sax>
  void number_fallback(simdjson::simdjson_result<std::string_view> token, Sax& sax, const char* at);
  static bool scalar_json(simdjson::ondemand::value v, nlohmann::json& out);

  [[noreturn]] void fail_at(const char* at, const std::string& what);
  /// Faults of simdjson's first pass over a text (invalid UTF-8, an unclosed string, a raw
  /// control character) come before there is a position to give.
  [[noreturn]] void fail_first_pass(simdjson::error_code e);
  void check(simdjson::error_code e, const char* at) {
    if (e != simdjson::SUCCESS) fail_at(at, what(e));
  }
  void check_step(simdjson::error_code e, const char* fallback);
  /// A container at nesting `depth` (its first byte at `at`) within kMaxNesting.
  void check_depth(std::size_t depth, const char* at) {
    if (depth >= kMaxNesting)
      fail_at(at, "nesting deeper than " + std::to_string(kMaxNesting) + " levels");
  }
  static std::string what(simdjson::error_code e);

  const ByteInput& in_;
  TextWindow w_;
  static constexpr std::size_t kBatchBytes = std::size_t{1} << 20;
  static constexpr std::size_t kNoLimit = static_cast<std::size_t>(-1);
  simdjson::ondemand::parser parser_;
  simdjson::ondemand::document doc_;
  // Line batches: items at file depth 2 and deeper, so kMaxNesting - 2 levels below the
  // batch's array; anything deeper goes to the framed path, which reports it.
  simdjson::dom::parser dom_;
  bool iterating_ = false;  // doc_ is valid
  // Bytes a batch borrowed for its brackets, put back before an error is located.
  char* patched_[2] = {nullptr, nullptr};
  char saved_[2] = {0, 0};
  std::string key_, string_;
};

// ---- the templates -------------------------------------------------------------------------

template <class Sax>
void JsonStream::parse(Sax& sax) {
  if (!w_.skip_space()) fail_at(nullptr, "empty input, expected a JSON value");
  framed_value(sax, 0);
  if (w_.skip_space()) fail_at(w_.cur(), "unexpected content after the JSON value");
}

/// The value at the cursor (white space skipped) at nesting `depth`: parsed whole when it
/// ends within kBatchBytes (or is a string or a number, however long), else a container
/// read member by member or item by item, so that no more than about kBatchBytes is ever
/// indexed at once. The root object is always read member by member, and its `cfs` and
/// `transitions` arrays item by item.
template <class Sax>
void JsonStream::framed_value(Sax& sax, std::size_t depth) {
  const char c = *w_.cur();
  const bool container = c == '{' || c == '[';
  if (!container || depth > 0) {
    bool complete = false;
    const std::size_t end = w_.value_end(0, complete, container ? kBatchBytes : kNoLimit);
    if (!w_.cut_short()) {
      if (end == 0) fail_at(w_.cur(), what(simdjson::TAPE_ERROR));
      // A container the input ends inside is refused unread: simdjson's On-Demand parser
      // must not walk unbalanced brackets (it can read past its index).
      if (container && !complete) fail_at(nullptr, what(simdjson::TAPE_ERROR));
      parse_span(0, end, false, sax, depth);
      w_.advance(end);
      return;
    }
  }
  check_depth(depth, w_.cur());
  if (c == '[')
    items(sax, depth + 1);
  else
    members(sax, depth + 1);
}

/// The members of the object at the cursor, each value at nesting `depth`.
template <class Sax>
void JsonStream::members(Sax& sax, std::size_t depth) {
  sax.start_object(static_cast<std::size_t>(-1));
  if (opened_empty('}')) {
    sax.end_object();
    return;
  }
  while (true) {
    key_ = member_name();
    sax.key(key_);
    expect(':');
    skip_space_or_fail();
    if (depth == 1 && (key_ == "cfs" || key_ == "transitions") && *w_.cur() == '[')
      items(sax, 2);
    else
      framed_value(sax, depth);
    skip_space_or_fail();
    const char c = *w_.cur();
    w_.advance(1);
    if (c == '}') break;
    if (c != ',') fail_at(w_.cur() - 1, what(simdjson::TAPE_ERROR));
    skip_space_or_fail();
  }
  sax.end_object();
}

/// The items of the array at the cursor, each at nesting `depth`, in batches of about
/// kBatchBytes.
template <class Sax>
void JsonStream::items(Sax& sax, std::size_t depth) {
  sax.start_array(static_cast<std::size_t>(-1));
  if (opened_empty(']')) {
    sax.end_array();
    return;
  }
  // Line batches know the depth of the graph's items only (the DOM parser's depth limit).
  // A file laid out otherwise (an item over several lines) stops trying them after two
  // misses in a row; a cfgen file never misses.
  int misses = depth == 2 ? 0 : 2;
  while (true) {
    const LineBatch read = misses < 2 ? line_batch(sax) : LineBatch::kNone;
    if (read == LineBatch::kEnded) break;
    misses = read == LineBatch::kNone ? misses + 1 : 0;
    if (read == LineBatch::kNone && framed_batch(sax, depth)) break;
    // The cursor is past a ',': an item follows.
    skip_space_or_fail();
    if (*w_.cur() == ']') fail_at(w_.cur(), what(simdjson::TAPE_ERROR));
  }
  sax.end_array();
}

/// The items in the next kBatchBytes when they are laid out an item a line, as cfgen writes
/// them: up to a line that starts with the array's ']' (kEnded, the cursor past it), or else
/// up to the last line break after an item's ',' (kMore, the cursor past the ','). They are
/// parsed by simdjson's DOM parser as one array, and nothing is emitted unless the whole of
/// it is valid. A raw line break is never inside a JSON string, so the batch is whole items
/// exactly when it parses. kNone (nothing read) otherwise; framed_batch then reads them.
template <class Sax>
JsonStream::LineBatch JsonStream::line_batch(Sax& sax) {
  w_.fill(kBatchBytes);
  const std::size_t n = std::min(w_.avail(), kBatchBytes);
  char* const p = w_.cur();
  // The first line that starts with ']', else the last line break.
  std::size_t cut = 0, close = 0;
  for (const char* q = p; (q = static_cast<const char*>(std::memchr(q, '\n', n - (q - p))));) {
    cut = static_cast<std::size_t>(q - p);
    std::size_t j = cut + 1;
    while (j < w_.avail() && (p[j] == ' ' || p[j] == '\t' || p[j] == '\r')) ++j;
    if (j < w_.avail() && p[j] == ']') {
      close = j;
      break;
    }
    if (++q == p + n) break;
  }
  if (cut == 0) return LineBatch::kNone;
  std::size_t e = cut;  // the line break: the items end before it
  while (e > 0 && (p[e - 1] == ' ' || p[e - 1] == '\r' || p[e - 1] == '\t')) --e;
  if (e == 0 || (p[e - 1] == ',') == (close != 0)) return LineBatch::kNone;
  if (close == 0) --e;  // the ',' becomes the array's ']', the byte before the cursor its '['
  // A batch is at most kBatchBytes and the input's size, plus its two brackets.
  if (dom_.capacity() == 0 &&
      dom_.allocate(std::min(kBatchBytes, in_.size()) + 2, kMaxNesting - 2) != simdjson::SUCCESS)
    return LineBatch::kNone;
  const char before = p[-1], after = p[e];
  p[-1] = '[';
  p[e] = ']';
  simdjson::dom::element root;
  const auto err = dom_.parse(p - 1, e + 2, false).get(root);
  p[-1] = before;
  p[e] = after;
  if (err != simdjson::SUCCESS || !root.is_array()) return LineBatch::kNone;
  for (simdjson::dom::element item : simdjson::dom::array(root)) emit(item, sax);
  w_.advance(close != 0 ? close + 1 : cut);
  return close != 0 ? LineBatch::kEnded : LineBatch::kMore;
}

/// The items of one batch, each framed by TextWindow::value_end and then parsed by simdjson's
/// On Demand parser, which reports a fault with its position; an item longer than a batch
/// is read by framed_value. True when the array ended.
template <class Sax>
bool JsonStream::framed_batch(Sax& sax, std::size_t depth) {
  std::size_t i = 0, end = 0;
  char stop = 0;  // ',' more items, ']' the last, else what stopped the batch (0: the end)
  bool long_item = false, truncated = false;
  while (true) {
    bool complete = false;
    const std::size_t item_end = w_.value_end(i, complete, kBatchBytes);
    if (w_.cut_short()) {
      long_item = true;
      break;
    }
    // An item the input ends inside is not parsed (as in framed_value); those before it are.
    const char first = i < w_.avail() ? w_.cur()[i] : '\0';
    if (!complete && (first == '{' || first == '[')) {
      truncated = true;
      break;
    }
    end = item_end;
    i = skip_space_at(end);
    if (!complete || !w_.fill(i + 1)) break;
    stop = w_.cur()[i];
    if (stop != ',') break;
    i = skip_space_at(i + 1);
    if (end >= kBatchBytes) break;
  }
  // The batch's items first: a fault in them comes before the one that stopped it.
  if (end > 0) parse_span(0, end, true, sax, depth);
  if (truncated) fail_at(nullptr, what(simdjson::TAPE_ERROR));
  if (long_item) {
    // The items before it are read: the long one starts at `i`.
    w_.advance(i);
    framed_value(sax, depth);
    skip_space_or_fail();
    stop = *w_.cur();
    i = 0;
  }
  if (stop == ']') {
    w_.advance(i + 1);
    return true;
  }
  w_.advance(i);
  if (stop != ',' || w_.avail() == 0)
    fail_at(w_.avail() == 0 ? nullptr : w_.cur(), what(simdjson::TAPE_ERROR));
  if (long_item) w_.advance(1);  // the ','
  return false;
}

/// One item of a line batch and what it holds, as SAX events (the DOM parser has checked
/// it, its nesting included).
template <class Sax>
void JsonStream::emit(simdjson::dom::element e, Sax& sax) {
  using simdjson::dom::element_type;
  switch (e.type()) {
    case element_type::ARRAY:
      sax.start_array(static_cast<std::size_t>(-1));
      for (simdjson::dom::element child : simdjson::dom::array(e)) emit(child, sax);
      sax.end_array();
      return;
    case element_type::OBJECT:
      sax.start_object(static_cast<std::size_t>(-1));
      for (simdjson::dom::key_value_pair field : simdjson::dom::object(e)) {
        sax.key(field.key);
        emit(field.value, sax);
      }
      sax.end_object();
      return;
    case element_type::INT64:
      sax.number_integer(std::int64_t(e));
      return;
    case element_type::UINT64:
      sax.number_unsigned(std::uint64_t(e));
      return;
    case element_type::DOUBLE:
      sax.number_float(double(e), string_);
      return;
    case element_type::STRING: {
      const std::string_view str(e);
      string_.assign(str.data(), str.size());
      sax.string(string_);
      return;
    }
    case element_type::BOOL:
      sax.boolean(bool(e));
      return;
    case element_type::NULL_VALUE:
      sax.null();
      return;
  }
}

/// Parses [begin, end) from the cursor with simdjson in place: one value, or (as_items) the
/// items of an array between borrowed brackets.
template <class Sax>
void JsonStream::parse_span(std::size_t begin, std::size_t end, bool as_items, Sax& sax,
                            std::size_t depth) {
  char* b = w_.cur() + begin;
  char* e = w_.cur() + end;
  if (as_items) {
    // The byte before the cursor is kept by the window; the one at `end` is a separator,
    // white space or the padding.
    --b;
    patched_[0] = b;
    patched_[1] = e;
    saved_[0] = *b;
    saved_[1] = *e;
    *b = '[';
    *e = ']';
    ++e;
  }
  const simdjson::padded_string_view text(b, static_cast<std::size_t>(e - b), w_.room(b));
  iterating_ = false;
  if (const auto err = parser_.iterate(text).get(doc_); err != simdjson::SUCCESS)
    fail_first_pass(err);
  iterating_ = true;
  simdjson::ondemand::json_type type{};
  check(doc_.type().get(type), b);
  if (as_items) {
    simdjson::ondemand::array array;
    check(doc_.get_array().get(array), b);
    for (auto item : array) {
      simdjson::ondemand::value element;
      check_step(std::move(item).get(element), b);
      value(element, sax, depth);
    }
  } else if (type == simdjson::ondemand::json_type::object ||
             type == simdjson::ondemand::json_type::array) {
    simdjson::ondemand::value root;
    check(doc_.get_value().get(root), b);
    value(root, sax, depth);
  } else {
    scalar(doc_, type, sax, b);
  }
  // current_location() is OUT_OF_BOUNDS once every token has been read.
  if (const char* rest = nullptr; doc_.current_location().get(rest) == simdjson::SUCCESS)
    fail_at(rest, "unexpected content after the JSON value");
  iterating_ = false;
  if (as_items) {
    *patched_[0] = saved_[0];
    *patched_[1] = saved_[1];
    patched_[0] = patched_[1] = nullptr;
  }
}

template <class Sax>
void JsonStream::value(simdjson::ondemand::value v, Sax& sax, std::size_t depth) {
  using simdjson::ondemand::json_type;
  const char* at = v.raw_json_token().data();  // the value's first byte
  json_type type{};
  check(v.type().get(type), at);
  switch (type) {
    case json_type::object: {
      check_depth(depth, at);
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
        sax.key(key);
        value(field.value(), sax, depth + 1);
      }
      sax.end_object();
      return;
    }
    case json_type::array: {
      check_depth(depth, at);
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
void JsonStream::scalar(Node& node, simdjson::ondemand::json_type type, Sax& sax, const char* at) {
  using simdjson::ondemand::json_type;
  switch (type) {
    case json_type::number: {
      simdjson::ondemand::number n;
      if (node.get_number().get(n) != simdjson::SUCCESS)
        return number_fallback(node.raw_json_token(), sax, at);
      switch (n.get_number_type()) {
        case simdjson::ondemand::number_type::signed_integer:
          sax.number_integer(n.get_int64());
          return;
        case simdjson::ondemand::number_type::unsigned_integer:
          sax.number_unsigned(n.get_uint64());
          return;
        default:
          sax.number_float(n.get_double(), string_);
          return;
      }
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

/// simdjson refuses integers past 64 bits, which JSON allows and nlohmann reads as doubles;
/// any other number it refuses is reported with its position.
template <class Sax>
void JsonStream::number_fallback(simdjson::simdjson_result<std::string_view> token, Sax& sax,
                                 const char* at) {
  double d = 0;
  std::string_view raw;
  if (std::move(token).get(raw) != simdjson::SUCCESS) fail_at(at, "invalid number");
  const std::string why = long_integer_value(raw, d);
  if (!why.empty()) fail_at(at, why);
  sax.number_float(d, string_);
}

}  // namespace cf::internal

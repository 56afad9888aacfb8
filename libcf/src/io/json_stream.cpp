#include "json_stream.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>

namespace cf::internal {

namespace {

// Bytes read from the input at a time, and kept allocated past the data: simdjson reads up
// to its padding past a value, and a batch borrows the byte after its last item.
constexpr std::size_t kPiece = std::size_t{4} << 20;
constexpr std::size_t kSlack = simdjson::SIMDJSON_PADDING + 8;

constexpr std::size_t kNoLimit = static_cast<std::size_t>(-1);

constexpr bool is_space(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

/// Bytes the container scan stops at outside strings, and inside them.
struct ScanTables {
  std::array<bool, 256> outside{}, inside{}, scalar_end{};
  constexpr ScanTables() {
    for (const char c : {'"', '{', '}', '[', ']'}) outside[static_cast<unsigned char>(c)] = true;
    for (const char c : {'"', '\\'}) inside[static_cast<unsigned char>(c)] = true;
    for (const char c : {' ', '\n', '\r', '\t', ',', ']', '}'})
      scalar_end[static_cast<unsigned char>(c)] = true;
  }
};
constexpr ScanTables kScan;

}  // namespace

// ---- TextWindow ----------------------------------------------------------------------------

TextWindow::TextWindow(const ByteInput& in) : in_(in), buf_(std::min(in.size(), kPiece) + kSlack) {}

void TextWindow::drop_consumed() {
  if (pos_ <= 1) return;
  const std::size_t drop = pos_ - 1;  // the byte before the cursor stays (a batch's '[')
  const char* p = buf_.data();
  const char* const end = p + drop;
  const char* last_newline = nullptr;
  while (const void* q = std::memchr(p, '\n', static_cast<std::size_t>(end - p))) {
    ++line_;
    last_newline = static_cast<const char*>(q);
    p = last_newline + 1;
  }
  col_ = last_newline == nullptr ? col_ + drop : static_cast<std::size_t>(end - last_newline);
  std::memmove(buf_.data(), buf_.data() + drop, len_ - drop);
  len_ -= drop;
  pos_ -= drop;
}

bool TextWindow::fill(std::size_t n) {
  if (len_ - pos_ >= n) return true;
  if (ended_) return false;
  drop_consumed();
  const std::size_t need = pos_ + n;
  if (buf_.size() < need + kSlack) buf_.resize(std::max(buf_.size() * 2, need + kSlack));
  while (len_ < need && !ended_) {
    const std::size_t got = in_.read_at(read_, buf_.data() + len_, buf_.size() - kSlack - len_);
    ended_ = got == 0;
    len_ += got;
    read_ += got;
  }
  return len_ - pos_ >= n;
}

bool TextWindow::skip_space() {
  while (true) {
    while (pos_ < len_ && is_space(buf_[pos_])) ++pos_;
    if (pos_ < len_) return true;
    if (!fill(1)) return false;
  }
}

std::size_t TextWindow::value_end(std::size_t from, bool& complete, std::size_t limit) {
  complete = cut_short_ = false;
  stop_at_ = limit > kNoLimit - from ? kNoLimit : from + limit;
  if (!fill(from + 1)) return avail();
  const char c = cur()[from];
  in_string_ = escaped_ = false;
  opens_.clear();
  if (c == '"') {
    in_string_ = true;
    return scan_string(from + 1, complete);
  }
  if (c == '{' || c == '[') return scan_container(from, complete);
  // A number or a literal runs to a delimiter or the end of the input.
  std::size_t i = from;
  while (true) {
    const char* p = cur();
    const std::size_t n = avail();
    while (i < n && !kScan.scalar_end[static_cast<unsigned char>(p[i])]) ++i;
    if (i < n || !fill(i + 1)) break;
  }
  complete = true;
  return i;
}

std::size_t TextWindow::scan_string(std::size_t i, bool& done) {
  while (true) {
    const char* p = cur();
    const std::size_t n = avail();
    for (; i < n; ++i) {
      if (escaped_) {
        escaped_ = false;
        continue;
      }
      while (i < n && !kScan.inside[static_cast<unsigned char>(p[i])]) ++i;
      if (i == n) break;
      if (p[i] == '\\') {
        escaped_ = true;
      } else {
        in_string_ = false;
        done = true;
        return i + 1;
      }
    }
    if (!fill(i + 1)) return avail();
  }
}

std::size_t TextWindow::scan_container(std::size_t i, bool& done) {
  while (true) {
    if (i >= stop_at_) {
      cut_short_ = true;
      return i;
    }
    if (in_string_) {
      bool closed = false;
      i = scan_string(i, closed);
      if (!closed) return i;  // the input ended inside a string
    }
    const char* p = cur();
    const std::size_t n = avail();
    while (i < n && !kScan.outside[static_cast<unsigned char>(p[i])]) ++i;
    if (i == n) {
      if (!fill(i + 1)) return avail();
      continue;
    }
    const char c = p[i++];
    if (c == '"') {
      in_string_ = true;
    } else if (c == '{' || c == '[') {
      opens_ += c;
    } else {
      // A bracket that closes another kind is refused here: simdjson's On-Demand parser
      // must not walk mismatched brackets.
      if (opens_.back() != (c == '}' ? '{' : '['))
        fail_at(cur() + i - 1, simdjson::error_message(simdjson::TAPE_ERROR));
      opens_.pop_back();
      if (opens_.empty()) {
        done = true;
        return i;
      }
    }
  }
}

void TextWindow::fail_at(const char* at, const std::string& what) const {
  const char* const begin = buf_.data();
  const char* const end = begin + len_;
  if (at == nullptr || at < begin || at > end) at = end;
  std::size_t line = line_, col = col_;
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
  throw Error("reading '" + source() + "': not valid JSON: syntax error at line " +
              std::to_string(line) + ", column " + std::to_string(col) + near + ": " + what);
}

// ---- JsonStream ----------------------------------------------------------------------------

std::size_t JsonStream::skip_space_at(std::size_t i) {
  while (w_.fill(i + 1) && is_space(w_.cur()[i])) ++i;
  return std::min(i, w_.avail());
}

void JsonStream::skip_space_or_fail() {
  if (!w_.skip_space()) fail_at(nullptr, what(simdjson::TAPE_ERROR));
}

bool JsonStream::opened_empty(char close) {
  w_.advance(1);
  skip_space_or_fail();
  if (*w_.cur() != close) return false;
  w_.advance(1);
  return true;
}

void JsonStream::expect(char c) {
  skip_space_or_fail();
  if (*w_.cur() != c) fail_at(w_.cur(), what(simdjson::TAPE_ERROR));
  w_.advance(1);
}

std::string JsonStream::member_name() {
  if (*w_.cur() != '"') fail_at(w_.cur(), what(simdjson::TAPE_ERROR));
  bool complete = false;
  const std::size_t end = w_.value_end(0, complete, kNoLimit);
  char* const b = w_.cur();
  const simdjson::padded_string_view text(b, end, w_.room(b));
  iterating_ = false;
  if (const auto e = parser_.iterate(text).get(doc_); e != simdjson::SUCCESS) fail_first_pass(e);
  std::string_view name;
  check(doc_.get_string().get(name), b);
  std::string out(name);
  w_.advance(end);
  return out;
}

void JsonStream::check_step(simdjson::error_code e, const char* fallback) {
  if (e == simdjson::SUCCESS) return;
  const char* at = nullptr;
  if (!iterating_ || doc_.current_location().get(at) != simdjson::SUCCESS) at = fallback;
  fail_at(at, what(e));
}

std::string JsonStream::what(simdjson::error_code e) {
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

void JsonStream::fail_at(const char* at, const std::string& what) {
  for (int k = 0; k < 2; ++k)
    if (patched_[k] != nullptr) *patched_[k] = saved_[k];
  w_.fail_at(at, what);
}

void JsonStream::fail_first_pass(simdjson::error_code e) {
  throw Error("reading '" + in_.source() + "': not valid JSON: " + simdjson::error_message(e));
}

std::string long_integer_value(std::string_view raw, double& d) {
  // The token runs to the next structural character: the number, then at most white space
  // (anything else, '1e400z' say, is not a number).
  std::size_t len = 0;
  while (len < raw.size() && std::strchr("+-.0123456789eE", raw[len]) != nullptr) ++len;
  static const std::string kInvalid =
      "invalid number (RFC 8259: an optional minus, digits without leading zeros, an optional "
      "fraction and exponent)";
  if (raw.find_first_not_of(" \t\n\r", len) != std::string_view::npos) return kInvalid;
  raw = raw.substr(0, len);
  const std::string_view digits = raw.substr(!raw.empty() && raw[0] == '-' ? 1 : 0);
  const bool long_integer = digits.size() >= 20 && digits[0] != '0' &&
                            digits.find_first_not_of("0123456789") == std::string_view::npos;
  const auto r = std::from_chars(raw.data(), raw.data() + raw.size(), d);
  if (long_integer && r.ec == std::errc()) return {};
  if (r.ec == std::errc::result_out_of_range) return "number out of the range of a double";
  return kInvalid;
}

// ---- the header scan -----------------------------------------------------------------------

bool JsonStream::scalar_json(simdjson::ondemand::value v, nlohmann::json& out) {
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
      out = nlohmann::json::object();
      return true;
    case json_type::array:
      out = nlohmann::json::array();
      return true;
    default: {  // null, or a literal the reading pass reports ("nul")
      bool is_null = false;
      if (v.is_null().get(is_null) != simdjson::SUCCESS || !is_null) return false;
      out = nullptr;
      return true;
    }
  }
}

bool JsonStream::scan_header(nlohmann::json& format, bool& has_format, nlohmann::json& version,
                             bool& has_version) {
  TextWindow w(in_);
  simdjson::ondemand::parser parser;
  // Parses [0, end) from the window's cursor as one value: the key's name, or a member's.
  const auto value_of = [&](std::size_t end, nlohmann::json* out, std::string* name) {
    char* const b = w.cur();
    // The whole text plus a closing bracket makes a scalar a document of its own.
    const simdjson::padded_string text("[" + std::string(b, end) + "]");
    simdjson::ondemand::document doc;
    simdjson::ondemand::array array;
    if (parser.iterate(text).get(doc) != simdjson::SUCCESS ||
        doc.get_array().get(array) != simdjson::SUCCESS)
      return false;
    for (auto item : array) {
      simdjson::ondemand::value v;
      if (std::move(item).get(v) != simdjson::SUCCESS) return false;
      if (out != nullptr) return scalar_json(v, *out);
      std::string_view s;
      if (v.get_string().get(s) != simdjson::SUCCESS) return false;
      *name = std::string(s);
      return true;
    }
    return false;
  };
  if (!w.skip_space() || *w.cur() != '{') return false;
  w.advance(1);
  while (w.skip_space() && *w.cur() == '"') {
    bool complete = false;
    std::size_t end = w.value_end(0, complete, kNoLimit);
    std::string name;
    if (!complete || !value_of(end, nullptr, &name)) return false;
    w.advance(end);
    if (!w.skip_space() || *w.cur() != ':') return false;
    w.advance(1);
    if (!w.skip_space()) return false;
    end = w.value_end(0, complete, kNoLimit);
    if (!complete) return false;
    nlohmann::json* const target = name == "format"    ? &format
                                   : name == "version" ? &version
                                                       : nullptr;
    if (target != nullptr) {
      // Only a scalar's text is parsed here; a container is only framed.
      const char c = *w.cur();
      if (c == '{' || c == '[')
        *target = c == '{' ? nlohmann::json::object() : nlohmann::json::array();
      else if (!value_of(end, target, nullptr))
        return false;
      (target == &format ? has_format : has_version) = true;
      if (has_format && has_version) return true;
    }
    w.advance(end);
    if (!w.skip_space() || *w.cur() != ',') break;
    w.advance(1);
  }
  return true;
}

}  // namespace cf::internal

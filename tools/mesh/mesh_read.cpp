// The mesh file readers (OFF, OBJ, STL ascii and binary, PLY ascii and binary), CGAL-free.
//
// Written for hostile input: every count in a header is checked against the bytes that
// follow before anything is allocated for it, every index against the range it must fall
// in (no silent wrap-around of a 20-digit index), every number must be finite, and text
// quoted in a message is made printable. The fuzz targets in fuzz/ drive these functions.

#include "mesh_detail.hpp"

#include <cf/file_io.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string_view>

namespace cf::tools {
namespace {

using cf::printable;
using detail::fail;

std::string quoted(std::string_view t) { return "'" + printable(std::string(t), 40) + "'"; }

/// A number from a file for a message: integers exactly (any size), others with %.17g.
/// (A cast of a double beyond the range of long long is undefined: fuzz_ply found one.)
std::string number_text(double v) {
  char buf[40];
  if (std::abs(v) < 9e18 && v == std::floor(v))
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v));
  else
    std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

std::string lower(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

/// A finite double, the whole token (a leading '+' allowed).
bool parse_double(std::string_view t, double& v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty() || t[0] == '+') return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
}

/// An integer token; `overflow` is set when it has the form of an integer but no int64
/// holds it.
bool parse_int(std::string_view t, long long& v, bool& overflow) {
  overflow = false;
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ptr != t.data() + t.size()) return false;
  if (r.ec == std::errc::result_out_of_range) {
    overflow = true;
    return false;
  }
  return r.ec == std::errc();
}

/// Line-by-line reading with comments ('#' to the end of the line, when `comments`) removed
/// and the line number kept.
class Lines {
 public:
  Lines(std::string_view text, bool comments) : text_(text), comments_(comments) {}
  /// The next line that has a token; false at the end.
  bool next(std::vector<std::string_view>& tokens) {
    while (pos_ < text_.size()) {
      const std::size_t nl = text_.find('\n', pos_);
      const std::size_t end = nl == std::string_view::npos ? text_.size() : nl;
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (comments_) {
        const std::size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
      }
      tokens.clear();
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && is_space(line[i])) ++i;
        std::size_t j = i;
        while (j < line.size() && !is_space(line[j])) ++j;
        if (j > i) tokens.push_back(line.substr(i, j - i));
        i = j;
      }
      if (!tokens.empty()) return true;
    }
    return false;
  }
  int line() const { return line_; }
  std::size_t remaining() const { return pos_ >= text_.size() ? 0 : text_.size() - pos_; }

 private:
  std::string_view text_;
  bool comments_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

/// The raw soup of a file, before identical points are merged.
struct RawSoup {
  std::vector<Vec3> points;
  std::vector<std::vector<std::size_t>> polygons;
};

[[noreturn]] void parse_fail(const std::string& src, int line, const std::string& what) {
  fail(src, "parse error: line " + std::to_string(line) + ": " + what);
}

// --- OFF ---------------------------------------------------------------------------------

// Refuses a token after an OFF's declared facets: a second model, or counts smaller than the
// data, would be dropped without a word.
void expect_off_end(Lines& in, std::string_view text, long long facets, const std::string& src) {
  std::vector<std::string_view> tok;
  if (in.next(tok))
    parse_fail(src, in.line(),
               "byte offset " + std::to_string(tok[0].data() - text.data()) + ": data after the " +
                   std::to_string(facets) +
                   " facets the header declares (a second model, or counts that do not match "
                   "the data)");
}

RawSoup read_off(std::string_view text, const std::string& src) {
  RawSoup s;
  Lines in(text, true);
  std::vector<std::string_view> tok;
  if (!in.next(tok)) fail(src, "the file contains no facets");
  std::size_t k = 0;
  {
    const std::string kw(tok[0]);
    // [ST][C][N][4][n]OFF; the homogeneous (4) and n-dimensional (n) forms are refused.
    const bool off = kw.size() >= 3 && kw.compare(kw.size() - 3, 3, "OFF") == 0;
    if (!off) parse_fail(src, in.line(), "expected the keyword OFF, found " + quoted(tok[0]));
    const std::string prefix = kw.substr(0, kw.size() - 3);
    if (prefix.find('4') != std::string::npos || prefix.find('n') != std::string::npos)
      parse_fail(src, in.line(),
                 "the " + kw + " variant (homogeneous or n-dimensional) is not supported");
    for (char c : prefix)
      if (c != 'S' && c != 'T' && c != 'C' && c != 'N')
        parse_fail(src, in.line(), "expected the keyword OFF, found " + quoted(tok[0]));
    k = 1;
    if (tok.size() > 1 && lower(tok[1]) == "binary")
      parse_fail(src, in.line(),
                 "binary OFF is not supported (write the model as text OFF, or as PLY or STL)");
  }
  // The counts: on the keyword's line or the next.
  if (k >= tok.size()) {
    if (!in.next(tok))
      fail(src, "parse error: the file ends before the counts (vertices facets edges)");
    k = 0;
  }
  if (tok.size() - k < 2) parse_fail(src, in.line(), "expected the counts 'vertices facets edges'");
  long long nv = 0, nf = 0;
  bool overflow = false;
  if (!parse_int(tok[k], nv, overflow) || nv < 0)
    parse_fail(src, in.line(),
               "the vertex count " + quoted(tok[k]) + " is not a non-negative integer");
  if (!parse_int(tok[k + 1], nf, overflow) || nf < 0)
    parse_fail(src, in.line(),
               "the facet count " + quoted(tok[k + 1]) + " is not a non-negative integer");
  // Every vertex takes at least "x y z\n" (6 bytes), every facet at least "3 i j k\n" (8).
  const long double need =
      6.0L * static_cast<long double>(nv) + 8.0L * static_cast<long double>(nf) - 1;
  if (need > static_cast<long double>(in.remaining()))
    fail(src, "parse error: the header says " + std::to_string(nv) + " vertices and " +
                  std::to_string(nf) + " facets, more than the remaining " +
                  std::to_string(in.remaining()) + " bytes of the file can hold");
  s.points.reserve(static_cast<std::size_t>(nv));
  for (long long i = 0; i < nv; ++i) {
    if (!in.next(tok))
      fail(src, "parse error: the file ends after " + std::to_string(i) + " of its " +
                    std::to_string(nv) + " vertices");
    if (tok.size() < 3)
      parse_fail(src, in.line(),
                 "vertex " + std::to_string(i) + " has " + std::to_string(tok.size()) +
                     " numbers, expected x y z");
    double c[3];
    for (int a = 0; a < 3; ++a)
      if (!parse_double(tok[static_cast<std::size_t>(a)], c[a]))
        parse_fail(src, in.line(),
                   "vertex " + std::to_string(i) + ": " + quoted(tok[static_cast<std::size_t>(a)]) +
                       " is not a finite number");
    s.points.emplace_back(c[0], c[1], c[2]);
  }
  s.polygons.reserve(static_cast<std::size_t>(nf));
  for (long long f = 0; f < nf; ++f) {
    if (!in.next(tok))
      fail(src, "parse error: the file ends after " + std::to_string(f) + " of its " +
                    std::to_string(nf) + " facets");
    long long n = 0;
    if (!parse_int(tok[0], n, overflow) || n < 0)
      parse_fail(src, in.line(),
                 "facet " + std::to_string(f) + ": the vertex count " + quoted(tok[0]) +
                     " is not a non-negative integer");
    if (static_cast<unsigned long long>(n) > tok.size() - 1)
      parse_fail(src, in.line(),
                 "facet " + std::to_string(f) + " says it has " + std::to_string(n) +
                     " vertices but its line lists " + std::to_string(tok.size() - 1) + " numbers");
    std::vector<std::size_t> poly;
    poly.reserve(static_cast<std::size_t>(n));
    for (long long j = 1; j <= n; ++j) {
      const std::string_view t = tok[static_cast<std::size_t>(j)];
      long long v = 0;
      const bool ok = parse_int(t, v, overflow);
      if (!ok && !overflow)
        parse_fail(
            src, in.line(),
            "facet " + std::to_string(f) + ": vertex index " + quoted(t) + " is not an integer");
      if (overflow || v < 0 || v >= nv)
        parse_fail(src, in.line(),
                   "facet " + std::to_string(f) + " refers to vertex " +
                       printable(std::string(t), 40) + " but the file has " + std::to_string(nv) +
                       " vertices (0 to " + std::to_string(nv - 1) + ")");
      poly.push_back(static_cast<std::size_t>(v));
    }
    s.polygons.push_back(std::move(poly));
  }
  expect_off_end(in, text, nf, src);
  return s;
}

// --- OBJ ---------------------------------------------------------------------------------

RawSoup read_obj(std::string_view text, const std::string& src) {
  RawSoup s;
  Lines in(text, true);
  std::vector<std::string_view> tok;
  static const char* const kIgnored[] = {
      "vt",         "vn",        "vp",    "o",      "g",     "s",        "usemtl",
      "mtllib",     "l",         "p",     "cstype", "deg",   "bmat",     "step",
      "curv",       "curv2",     "surf",  "parm",   "trim",  "hole",     "scrv",
      "sp",         "end",       "con",   "mg",     "lod",   "usemap",   "maplib",
      "shadow_obj", "trace_obj", "ctech", "stech",  "bevel", "c_interp", "d_interp"};
  while (in.next(tok)) {
    const std::string_view kw = tok[0];
    if (kw == "v") {
      if (tok.size() < 4)
        parse_fail(src, in.line(),
                   "vertex " + std::to_string(s.points.size()) + " has " +
                       std::to_string(tok.size() - 1) + " numbers, expected x y z");
      double c[3];
      for (std::size_t a = 0; a < 3; ++a)
        if (!parse_double(tok[a + 1], c[a]))
          parse_fail(src, in.line(),
                     "vertex " + std::to_string(s.points.size()) + ": " + quoted(tok[a + 1]) +
                         " is not a finite number");
      s.points.emplace_back(c[0], c[1], c[2]);
    } else if (kw == "f" || kw == "fo") {
      std::vector<std::size_t> poly;
      poly.reserve(tok.size() - 1);
      for (std::size_t j = 1; j < tok.size(); ++j) {
        const std::string_view ref = tok[j].substr(0, tok[j].find('/'));
        long long v = 0;
        bool overflow = false;
        const bool ok = parse_int(ref, v, overflow);
        if (!ok && !overflow)
          parse_fail(src, in.line(),
                     "facet " + std::to_string(s.polygons.size()) + ": vertex reference " +
                         quoted(tok[j]) + " is not an integer");
        const auto n = static_cast<long long>(s.points.size());
        if (overflow || v == 0 || v < -n || v > std::numeric_limits<int>::max())
          parse_fail(src, in.line(),
                     "facet " + std::to_string(s.polygons.size()) + " refers to vertex " +
                         printable(std::string(ref), 40) + (v < 0 ? " (relative)" : "") +
                         ", which does not exist (OBJ counts vertices from 1; " +
                         std::to_string(n) + " so far)");
        // Positive references may point forward (checked once all vertices are read).
        poly.push_back(static_cast<std::size_t>(v > 0 ? v - 1 : n + v));
      }
      s.polygons.push_back(std::move(poly));
    } else if (std::find(std::begin(kIgnored), std::end(kIgnored), kw) == std::end(kIgnored)) {
      parse_fail(src, in.line(), "unknown OBJ record " + quoted(kw));
    }
  }
  return s;
}

// --- STL ---------------------------------------------------------------------------------

/// Adds a point, merging identical ones in the order of first appearance (as STL stores
/// every corner of every triangle).
struct PointIndex {
  RawSoup& soup;
  std::map<std::array<double, 3>, std::size_t> seen;
  std::size_t add(double x, double y, double z) {
    const auto [it, fresh] = seen.emplace(std::array<double, 3>{x, y, z}, soup.points.size());
    if (fresh) soup.points.emplace_back(x, y, z);
    return it->second;
  }
};

/// Tokens with their line numbers, for the free-form ascii STL.
class Tokens {
 public:
  explicit Tokens(std::string_view t) : t_(t) {}
  bool next(std::string_view& tok) {
    while (p_ < t_.size() && is_space(t_[p_])) {
      if (t_[p_] == '\n') ++line_;
      ++p_;
    }
    if (p_ >= t_.size()) return false;
    const std::size_t b = p_;
    while (p_ < t_.size() && !is_space(t_[p_])) ++p_;
    tok = t_.substr(b, p_ - b);
    return true;
  }
  void skip_line() {
    while (p_ < t_.size() && t_[p_] != '\n') ++p_;
  }
  int line() const { return line_; }

 private:
  std::string_view t_;
  std::size_t p_ = 0;
  int line_ = 1;
};

RawSoup read_stl_ascii(std::string_view text, const std::string& src) {
  RawSoup s;
  PointIndex index{s, {}};
  Tokens in(text);
  std::string_view tok;
  auto expect = [&](const char* word) {
    if (!in.next(tok))
      fail(src, std::string("parse error: the file ends where '") + word + "' was expected");
    if (lower(tok) != word)
      parse_fail(src, in.line(), std::string("expected '") + word + "', found " + quoted(tok));
  };
  auto number = [&](const char* what) {
    if (!in.next(tok)) fail(src, std::string("parse error: the file ends inside a ") + what);
    double v = 0;
    if (!parse_double(tok, v))
      parse_fail(src, in.line(),
                 std::string("expected a finite number in a ") + what + ", found " + quoted(tok));
    return v;
  };
  expect("solid");
  in.skip_line();  // the solid's name
  while (true) {
    if (!in.next(tok)) fail(src, "parse error: the file ends without 'endsolid'");
    const std::string kw = lower(tok);
    if (kw == "endsolid") {
      in.skip_line();
      if (!in.next(tok)) break;  // done; another solid may follow
      if (lower(tok) != "solid")
        parse_fail(src, in.line(), "expected 'solid' or the end, found " + quoted(tok));
      in.skip_line();
      continue;
    }
    if (kw != "facet")
      parse_fail(src, in.line(), "expected 'facet' or 'endsolid', found " + quoted(tok));
    expect("normal");
    for (int a = 0; a < 3; ++a) number("facet normal");
    expect("outer");
    expect("loop");
    std::vector<std::size_t> tri;
    for (int c = 0; c < 3; ++c) {
      expect("vertex");
      const double x = number("vertex");
      const double y = number("vertex");
      const double z = number("vertex");
      tri.push_back(index.add(x, y, z));
    }
    expect("endloop");
    expect("endfacet");
    s.polygons.push_back(std::move(tri));
  }
  return s;
}

std::uint32_t le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

float lef(const unsigned char* p) {
  const std::uint32_t u = le32(p);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

RawSoup read_stl_binary(std::string_view bytes, const std::string& src) {
  RawSoup s;
  PointIndex index{s, {}};
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::uint32_t n = le32(p + 80);
  s.polygons.reserve(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const unsigned char* q = p + 84 + 50 * static_cast<std::size_t>(t) + 12;
    std::vector<std::size_t> tri;
    for (int c = 0; c < 3; ++c, q += 12) {
      const double x = lef(q), y = lef(q + 4), z = lef(q + 8);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        fail(src, "parse error: triangle " + std::to_string(t) +
                      " of the binary STL has a corner that is not finite");
      tri.push_back(index.add(x, y, z));
    }
    s.polygons.push_back(std::move(tri));
  }
  return s;
}

RawSoup read_stl(std::string_view bytes, const std::string& src) {
  const bool binary_size =
      bytes.size() >= 84 &&
      84 + 50 * static_cast<unsigned long long>(
                    le32(reinterpret_cast<const unsigned char*>(bytes.data()) + 80)) ==
          bytes.size();
  std::size_t b = 0;
  while (b < bytes.size() && is_space(bytes[b])) ++b;
  if (b == bytes.size()) fail(src, "the file contains no facets");
  const bool solid = lower(bytes.substr(b, 5)) == "solid";
  if (solid) {
    try {
      return read_stl_ascii(bytes, src);
    } catch (const Error&) {
      // Some exporters start a binary file's header with "solid".
      if (binary_size) return read_stl_binary(bytes, src);
      throw;
    }
  }
  if (binary_size) return read_stl_binary(bytes, src);
  if (bytes.size() >= 84) {
    const unsigned long long n = le32(reinterpret_cast<const unsigned char*>(bytes.data()) + 80);
    fail(src, "parse error: not an ascii STL (no 'solid'), and as binary STL its header says " +
                  std::to_string(n) + " triangles (" + std::to_string(84 + 50 * n) +
                  " bytes) but the file has " + std::to_string(bytes.size()) + " bytes");
  }
  fail(src,
       "parse error: not a readable STL file: no 'solid' keyword and too short for binary STL (" +
           std::to_string(bytes.size()) + " bytes, at least 84 needed)");
}

// --- PLY ---------------------------------------------------------------------------------

enum class PlyType : std::uint8_t { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool ply_type(std::string_view name, PlyType& t) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kI8},    {"int8", PlyType::kI8},     {"uchar", PlyType::kU8},
      {"uint8", PlyType::kU8},   {"short", PlyType::kI16},   {"int16", PlyType::kI16},
      {"ushort", PlyType::kU16}, {"uint16", PlyType::kU16},  {"int", PlyType::kI32},
      {"int32", PlyType::kI32},  {"uint", PlyType::kU32},    {"uint32", PlyType::kU32},
      {"float", PlyType::kF32},  {"float32", PlyType::kF32}, {"double", PlyType::kF64},
      {"float64", PlyType::kF64}};
  for (const auto& [n, v] : kNames)
    if (name == n) {
      t = v;
      return true;
    }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::kI8:
    case PlyType::kU8:
      return 1;
    case PlyType::kI16:
    case PlyType::kU16:
      return 2;
    case PlyType::kI32:
    case PlyType::kU32:
    case PlyType::kF32:
      return 4;
    default:
      return 8;
  }
}

bool ply_integer(PlyType t) { return t != PlyType::kF32 && t != PlyType::kF64; }

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::kU8;
  PlyType type = PlyType::kF32;
};

struct PlyElement {
  std::string name;
  unsigned long long count = 0;
  std::vector<PlyProperty> props;
};

/// The data section of a PLY file, ascii or binary, read value by value.
class PlyData {
 public:
  /// data: the bytes after the header, which ends at byte offset `base` of the file.
  PlyData(std::string_view data, std::size_t base, int format, const std::string& src,
          int header_lines)
      : d_(data), base_(base), format_(format), src_(src), line_(header_lines + 1) {}

  /// Refuses anything but white space (ascii) or nothing (binary) after the last element: a
  /// second model, or counts that do not match the data, would be dropped without a word.
  void expect_end() {
    std::size_t q = p_;
    int line = line_;
    if (format_ == 0)
      for (; q < d_.size() && is_space(d_[q]); ++q) line += d_[q] == '\n';
    if (q >= d_.size()) return;
    const std::string where = format_ == 0 ? "line " + std::to_string(line) + ", " : "";
    fail(src_, "parse error: " + where + "byte offset " + std::to_string(base_ + q) + ": " +
                   std::to_string(d_.size() - q) +
                   " bytes of data after the last element the header declares (a second "
                   "model, or element counts that do not match the data)");
  }

  double value(PlyType t, const char* what) {
    if (format_ == 0) {
      // ascii
      while (p_ < d_.size() && is_space(d_[p_])) {
        if (d_[p_] == '\n') ++line_;
        ++p_;
      }
      if (p_ >= d_.size())
        fail(src_, std::string("parse error: the file ends inside the data, reading ") + what);
      const std::size_t b = p_;
      while (p_ < d_.size() && !is_space(d_[p_])) ++p_;
      const std::string_view tok = d_.substr(b, p_ - b);
      double v = 0;
      if (!parse_double(tok, v))
        parse_fail(src_, line_,
                   std::string("expected a finite number for ") + what + ", found " + quoted(tok));
      if (ply_integer(t) && v != std::floor(v))
        parse_fail(src_, line_,
                   std::string("expected an integer for ") + what + ", found " + quoted(tok));
      return v;
    }
    const std::size_t n = ply_size(t);
    if (d_.size() - p_ < n)
      fail(src_, std::string("parse error: the file ends inside the data, reading ") + what);
    unsigned char b[8];
    std::memcpy(b, d_.data() + p_, n);
    p_ += n;
    if (format_ == 2) std::reverse(b, b + n);  // big endian to little endian
    switch (t) {
      case PlyType::kI8:
        return static_cast<double>(static_cast<std::int8_t>(b[0]));
      case PlyType::kU8:
        return b[0];
      case PlyType::kI16: {
        std::int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::kU16: {
        std::uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::kI32: {
        std::int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::kU32: {
        std::uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::kF32: {
        float v;
        std::memcpy(&v, b, 4);
        return finite(v, what);
      }
      default: {
        double v;
        std::memcpy(&v, b, 8);
        return finite(v, what);
      }
    }
  }
  /// Binary floats may be NaN or infinite: refused like the text "nan" (and a NaN would
  /// break the ordering of the point index).
  double finite(double v, const char* what) const {
    if (!std::isfinite(v))
      fail(src_,
           std::string("parse error: ") + what + " in the binary data is not a finite number");
    return v;
  }
  /// Bytes left; in ascii a value takes at least 2 (a digit and a separator).
  std::size_t remaining() const { return d_.size() - p_; }
  std::size_t min_bytes(PlyType t) const { return format_ == 0 ? 2 : ply_size(t); }
  int line() const { return line_; }

 private:
  std::string_view d_;
  std::size_t base_;  // byte offset of d_ in the file
  int format_;        // 0 ascii, 1 little endian, 2 big endian
  const std::string& src_;
  std::size_t p_ = 0;
  int line_;
};

RawSoup read_ply(std::string_view bytes, const std::string& src) {
  // Header: lines up to "end_header".
  std::size_t pos = 0;
  int line = 0;
  auto next_line = [&](std::string_view& l) {
    if (pos >= bytes.size()) return false;
    const std::size_t nl = bytes.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? bytes.size() : nl;
    l = bytes.substr(pos, end - pos);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    pos = end + 1;
    ++line;
    return true;
  };
  std::string_view l;
  if (!next_line(l) || l != "ply")
    parse_fail(src, 1, "expected 'ply' on the first line, found " + quoted(l));
  int format = -1;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (next_line(l)) {
    std::vector<std::string_view> t;
    for (std::size_t i = 0; i < l.size();) {
      while (i < l.size() && is_space(l[i])) ++i;
      std::size_t j = i;
      while (j < l.size() && !is_space(l[j])) ++j;
      if (j > i) t.push_back(l.substr(i, j - i));
      i = j;
    }
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      ended = true;
      break;
    }
    if (t[0] == "format") {
      if (t.size() < 2)
        parse_fail(src, line, "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (t[1] == "ascii")
        format = 0;
      else if (t[1] == "binary_little_endian")
        format = 1;
      else if (t[1] == "binary_big_endian")
        format = 2;
      else
        parse_fail(src, line, "unknown PLY format " + quoted(t[1]));
    } else if (t[0] == "element") {
      long long n = 0;
      bool overflow = false;
      if (t.size() != 3 || !parse_int(t[2], n, overflow) || n < 0)
        parse_fail(src, line,
                   "expected 'element NAME COUNT' with a non-negative count, found " + quoted(l));
      elements.push_back({std::string(t[1]), static_cast<unsigned long long>(n), {}});
    } else if (t[0] == "property") {
      if (elements.empty()) parse_fail(src, line, "a property before any element");
      PlyProperty p;
      if (t.size() == 5 && t[1] == "list") {
        p.list = true;
        if (!ply_type(t[2], p.count_type) || !ply_type(t[3], p.type))
          parse_fail(src, line, "unknown type in " + quoted(l));
        if (!ply_integer(p.count_type))
          parse_fail(src, line, "a list's count type must be an integer type");
        p.name = std::string(t[4]);
      } else if (t.size() == 3) {
        if (!ply_type(t[1], p.type)) parse_fail(src, line, "unknown type " + quoted(t[1]));
        p.name = std::string(t[2]);
      } else {
        parse_fail(src, line,
                   "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', found " +
                       quoted(l));
      }
      elements.back().props.push_back(p);
    } else {
      parse_fail(src, line, "unknown PLY header line " + quoted(l));
    }
  }
  if (!ended) fail(src, "parse error: the PLY header has no 'end_header'");
  if (format < 0) fail(src, "parse error: the PLY header has no 'format' line");

  PlyData data(bytes.substr(std::min(pos, bytes.size())), std::min(pos, bytes.size()), format, src,
               line);
  // Counts against the size: every item of every element takes at least its minimum bytes.
  long double need = 0;
  for (const PlyElement& e : elements) {
    if (e.count > 0 && e.props.empty())
      fail(src, "parse error: element '" + printable(e.name, 40) + "' has " +
                    std::to_string(e.count) + " items but no properties");
    std::size_t per = 0;
    for (const PlyProperty& p : e.props) per += data.min_bytes(p.list ? p.count_type : p.type);
    need += static_cast<long double>(e.count) * static_cast<long double>(per);
  }
  if (need > static_cast<long double>(data.remaining()) + 1)
    fail(src, "parse error: the header's element counts need at least " +
                  std::to_string(static_cast<unsigned long long>(std::min(need, 1e19L))) +
                  " bytes of data, but the file has " + std::to_string(data.remaining()) +
                  " after the header");

  RawSoup s;
  bool have_vertices = false;
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, ilist = -1;
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const PlyProperty& p = e.props[k];
      if (is_vertex && !p.list) {
        if (p.name == "x") ix = static_cast<int>(k);
        if (p.name == "y") iy = static_cast<int>(k);
        if (p.name == "z") iz = static_cast<int>(k);
      }
      if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index"))
        ilist = static_cast<int>(k);
    }
    if (is_vertex) {
      if (ix < 0 || iy < 0 || iz < 0)
        fail(src, "parse error: the PLY element 'vertex' lacks a property x, y or z");
      have_vertices = true;
      s.points.reserve(static_cast<std::size_t>(e.count));
    }
    if (is_face) {
      if (ilist < 0)
        fail(src, "parse error: the PLY element 'face' has no list property 'vertex_indices'");
      s.polygons.reserve(static_cast<std::size_t>(e.count));
    }
    for (unsigned long long i = 0; i < e.count; ++i) {
      double c[3] = {0, 0, 0};
      std::vector<std::size_t> poly;
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const PlyProperty& p = e.props[k];
        if (!p.list) {
          const double v = data.value(p.type, "a property value");
          if (static_cast<int>(k) == ix) c[0] = v;
          if (static_cast<int>(k) == iy) c[1] = v;
          if (static_cast<int>(k) == iz) c[2] = v;
          continue;
        }
        const double nd = data.value(p.count_type, "a list count");
        if (nd < 0 || nd * static_cast<double>(data.min_bytes(p.type)) >
                          static_cast<double>(data.remaining()) + 1)
          fail(src, "parse error: item " + std::to_string(i) + " of element '" +
                        printable(e.name, 40) + "' has a list of " + number_text(nd) +
                        " values, more than the rest of the file holds");
        const auto n = static_cast<std::size_t>(nd);
        const bool keep = static_cast<int>(k) == ilist;
        if (keep) poly.reserve(n);
        for (std::size_t j = 0; j < n; ++j) {
          const double v = data.value(p.type, "a list value");
          if (!keep) continue;
          if (!ply_integer(p.type) && v != std::floor(v))
            fail(src, "parse error: facet " + std::to_string(i) + ": vertex index " +
                          number_text(v) + " is not an integer");
          if (v < 0 || v > static_cast<double>(std::numeric_limits<int>::max()))
            fail(src, "parse error: facet " + std::to_string(i) + " refers to vertex " +
                          number_text(v) + ", which does not exist");
          poly.push_back(static_cast<std::size_t>(v));
        }
      }
      if (is_vertex) s.points.emplace_back(c[0], c[1], c[2]);
      if (is_face) s.polygons.push_back(std::move(poly));
    }
  }
  if (!have_vertices) fail(src, "parse error: the PLY file has no element 'vertex'");
  data.expect_end();
  return s;
}

}  // namespace

MeshFormat mesh_format_of(const std::string& path) {
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".off") return MeshFormat::kOff;
  if (ext == ".obj") return MeshFormat::kObj;
  if (ext == ".stl") return MeshFormat::kStl;
  if (ext == ".ply") return MeshFormat::kPly;
  fail(path, "unknown file extension '" +
                 printable(std::filesystem::path(path).extension().string(), 40) +
                 "' (expected .off, .obj, .stl or .ply)");
}

PolygonSoup parse_polygon_soup(std::string_view bytes, MeshFormat format,
                               const std::string& source) {
  if (bytes.empty()) fail(source, "the file is empty");
  RawSoup raw;
  switch (format) {
    case MeshFormat::kOff:
      raw = read_off(bytes, source);
      break;
    case MeshFormat::kObj:
      raw = read_obj(bytes, source);
      break;
    case MeshFormat::kStl:
      raw = read_stl(bytes, source);
      break;
    case MeshFormat::kPly:
      raw = read_ply(bytes, source);
      break;
  }
  if (raw.points.empty() || raw.polygons.empty()) fail(source, "the file contains no facets");
  if (raw.points.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail(source, "too many vertices");

  // Merge points with identical coordinates into the first occurrence. Every point keeps its
  // input index (duplicates are left unused), so messages and index rules use file order.
  PolygonSoup soup;
  soup.points.reserve(raw.points.size());
  std::vector<int> remap(raw.points.size());
  std::map<std::array<double, 3>, int> first;
  for (std::size_t i = 0; i < raw.points.size(); ++i) {
    const Vec3& p = raw.points[i];
    soup.points.push_back(p);
    remap[i] = first.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(i))
                   .first->second;
  }
  soup.polygons.reserve(raw.polygons.size());
  for (std::size_t f = 0; f < raw.polygons.size(); ++f) {
    std::vector<int> poly;
    poly.reserve(raw.polygons[f].size());
    for (std::size_t i : raw.polygons[f]) {
      if (i >= raw.points.size())
        fail(source, "parse error: facet " + std::to_string(f) + " refers to vertex " +
                         std::to_string(i) + " but the file has " +
                         std::to_string(raw.points.size()) + " vertices");
      poly.push_back(remap[i]);
    }
    soup.polygons.push_back(std::move(poly));
  }
  return soup;
}

PolygonSoup read_polygon_soup(const std::string& path) {
  const MeshFormat format = mesh_format_of(path);
  std::string bytes, why;
  if (!cf::read_input_file(path, bytes, why))
    throw cf::FileError("loading '" + path + "': cannot open file: " + why);
  return parse_polygon_soup(bytes, format, path);
}

}  // namespace cf::tools

#include "graph_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace cf::internal {

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

void append_escaped(std::string& out, std::string_view v) {
  out +=
      nlohmann::json(std::string(v)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {

/// Big-endian bytes of an unsigned integer of `bytes` bytes.
void append_be(std::string& out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

}  // namespace

// ---- JsonSink ------------------------------------------------------------------------------

void JsonSink::unsigned_integer(std::uint64_t v) {
  separate();
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out_.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

// ---- CborSink ------------------------------------------------------------------------------

void CborSink::head(unsigned major, std::uint64_t argument) {
  const auto type = static_cast<std::uint64_t>(major) << 5;
  if (argument <= 0x17) {
    out_ += static_cast<char>(type | argument);
  } else if (argument <= 0xff) {
    out_ += static_cast<char>(type | 0x18);
    append_be(out_, argument, 1);
  } else if (argument <= 0xffff) {
    out_ += static_cast<char>(type | 0x19);
    append_be(out_, argument, 2);
  } else if (argument <= 0xffffffff) {
    out_ += static_cast<char>(type | 0x1a);
    append_be(out_, argument, 4);
  } else {
    out_ += static_cast<char>(type | 0x1b);
    append_be(out_, argument, 8);
  }
}

void CborSink::integer(std::int64_t v) {
  if (v >= 0)
    head(0, static_cast<std::uint64_t>(v));
  else
    head(1, static_cast<std::uint64_t>(-(v + 1)));
}

void CborSink::number(double v) {
  if (std::isnan(v)) {
    out_ += std::string("\xf9\x7e\x00", 3);
    return;
  }
  if (std::isinf(v)) {
    out_ += std::string(v > 0 ? "\xf9\x7c\x00" : "\xf9\xfc\x00", 3);
    return;
  }
  // A float32 where it holds the value exactly, as nlohmann's to_cbor writes.
  const auto f = static_cast<float>(v);
  if (std::abs(v) <= static_cast<double>(std::numeric_limits<float>::max()) &&
      static_cast<double>(f) == v) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &f, sizeof bits);
    out_ += static_cast<char>(0xfa);
    append_be(out_, bits, 4);
    return;
  }
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  out_ += static_cast<char>(0xfb);
  append_be(out_, bits, 8);
}

void CborSink::string(std::string_view v) {
  head(3, v.size());
  out_.append(v.data(), v.size());
}

}  // namespace cf::internal

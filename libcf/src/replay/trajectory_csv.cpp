// POSES.csv read a buffer at a time (cf/replay.hpp).

#include <cf/file_io.hpp>
#include <cf/replay.hpp>

#include "io/input_file.hpp"
#include "replay/c_numeric.hpp"

#include <Eigen/Geometry>

#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include <unistd.h>

namespace cf {

namespace {

constexpr const char* kHeader = "t,tx,ty,tz,qw,qx,qy,qz";
constexpr const char* kColumns[] = {"t", "tx", "ty", "tz", "qw", "qx", "qy", "qz"};
// Bytes asked of the file per read, and the longest line taken: a pose row is under 200
// bytes, so a longer line is not one (a binary file, a file with no line breaks).
constexpr std::size_t kChunk = 1 << 16;
constexpr std::size_t kMaxLine = 1 << 16;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

}  // namespace

struct TrajectoryCsvReader::Impl {
  std::string source;
  int fd = -1;  // -1: everything is in `buffer`
  std::string buffer;
  std::size_t pos = 0;  // start of the first unread line in `buffer`
  bool eof = false;
  long line = 0;
  bool header = false;
  long rows = 0;
  double last_t = 0;
  long last_line = 0;
  std::string field;  // one field, NUL-terminated for strtod

  ~Impl() {
    if (fd >= 0) ::close(fd);
  }

  [[noreturn]] void fail(long at, const std::string& why) const {
    throw Error(source + ":" + std::to_string(at) + ": " + why);
  }

  // Tops the buffer up from the file; false when nothing more comes.
  bool refill() {
    if (fd < 0 || eof) return false;
    buffer.erase(0, pos);
    pos = 0;
    const std::size_t old = buffer.size();
    buffer.resize(old + kChunk);
    while (true) {
      const ssize_t n = ::read(fd, buffer.data() + old, kChunk);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        const int e = errno;
        buffer.resize(old);
        throw FileError(source + ": cannot read the trajectory: " + internal::read_error(e));
      }
      buffer.resize(old + static_cast<std::size_t>(n));
      if (n == 0) eof = true;
      return n > 0;
    }
  }

  // The next line without its '\n'; false at the end of the input.
  bool next_line(std::string_view& out) {
    while (true) {
      const std::size_t nl = buffer.find('\n', pos);
      if (nl != std::string::npos) {
        out = std::string_view(buffer).substr(pos, nl - pos);
        pos = nl + 1;
        ++line;
        return true;
      }
      if (buffer.size() - pos > kMaxLine)
        fail(line + 1,
             "a line longer than " + std::to_string(kMaxLine) + " bytes: not a trajectory CSV");
      if (!refill()) break;
    }
    if (pos == buffer.size()) return false;
    out = std::string_view(buffer).substr(pos);  // a last line without '\n'
    pos = buffer.size();
    ++line;
    return true;
  }

  double number(std::string_view text, const char* column) {
    auto shown = [&text] { return printable(std::string(text)); };
    if (text.empty()) fail(line, std::string("column '") + column + "' is empty");
    // Decimal only: strtod also reads hexadecimal ("0x1p4"), which no CSV writer means.
    if (text.find_first_of("xX") != std::string_view::npos)
      fail(line, std::string("column '") + column + "' is not a decimal number: '" + shown() + "'");
    field.assign(text);
    errno = 0;
    char* end = nullptr;
    const double v = strtod_l(field.c_str(), &end, internal::c_numeric());
    // ERANGE also reports an underflow (5e-324, a subnormal), whose result is the nearest double.
    const bool overflow = errno == ERANGE && std::abs(v) > DBL_MIN;
    if (end != field.c_str() + field.size() || overflow || !std::isfinite(v))
      fail(line, std::string("column '") + column + "' is not a finite number: '" + shown() + "'");
    return v;
  }

  void check_header(std::string_view s) {
    std::string joined;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = s.find(',', start);
      joined += trim(s.substr(start, comma == std::string_view::npos ? comma : comma - start));
      if (comma == std::string_view::npos) break;
      joined += ',';
      start = comma + 1;
    }
    if (joined != kHeader)
      fail(line, std::string("expected the header '") + kHeader + "', found '" +
                     printable(std::string(s)) + "'");
    header = true;
  }

  void parse_row(std::string_view s, TrajectorySample& out) {
    double v[8];
    int n = 0;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = s.find(',', start);
      const std::string_view f =
          trim(s.substr(start, comma == std::string_view::npos ? comma : comma - start));
      if (n < 8) v[n] = number(f, kColumns[n]);
      ++n;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (n != 8)
      fail(line, "expected 8 columns (" + std::string(kHeader) + "), found " + std::to_string(n));
    if (std::string why = quaternion_problem(v[4], v[5], v[6], v[7]); !why.empty()) fail(line, why);
    if (rows > 0 && !(v[0] > last_t)) {
      char buf[160];
      const internal::CNumericScope c_numbers;
      std::snprintf(buf, sizeof buf,
                    "time %.9g s does not increase (previous row, line %ld: %.9g s)", v[0],
                    last_line, last_t);
      fail(line, buf);
    }
    out.t_s = v[0];
    out.X_WD.t_BA = Vec3(v[1], v[2], v[3]);
    out.X_WD.R_BA = Eigen::Quaterniond(v[4], v[5], v[6], v[7]).normalized().toRotationMatrix();
    out.q = {v[4], v[5], v[6], v[7]};
    out.line = line;
    last_t = v[0];
    last_line = line;
    ++rows;
  }
};

TrajectoryCsvReader TrajectoryCsvReader::open(const std::string& path) {
  // Never blocks on a FIFO; a directory or a device is refused before reading.
  std::string why;
  const int fd = internal::open_input_file(path, why, static_cast<std::size_t>(-1));
  if (fd < 0) throw FileError(path + ": cannot open the trajectory: " + why);
  TrajectoryCsvReader reader(std::string(), path);
  reader.impl_->fd = fd;
  return reader;
}

TrajectoryCsvReader::TrajectoryCsvReader(std::string text, std::string source)
    : impl_(std::make_unique<Impl>()) {
  impl_->buffer = std::move(text);
  impl_->source = std::move(source);
}

TrajectoryCsvReader::~TrajectoryCsvReader() = default;
TrajectoryCsvReader::TrajectoryCsvReader(TrajectoryCsvReader&&) noexcept = default;
TrajectoryCsvReader& TrajectoryCsvReader::operator=(TrajectoryCsvReader&&) noexcept = default;

bool TrajectoryCsvReader::next(TrajectorySample& sample) {
  Impl& in = *impl_;
  std::string_view raw;
  while (in.next_line(raw)) {
    const std::string_view s = trim(raw);
    if (s.empty() || s[0] == '#') continue;
    if (!in.header) {
      in.check_header(s);
      continue;
    }
    in.parse_row(s, sample);
    return true;
  }
  if (!in.header)
    in.fail(std::max(in.line, 1L),
            std::string("empty file: expected the header '") + kHeader + "'");
  if (in.rows == 0) in.fail(in.line, "no pose rows after the header");
  return false;
}

}  // namespace cf

#include "replay_io.hpp"

#include <Eigen/Geometry>

#include <cf/file_io.hpp>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include <locale.h>
#include <unistd.h>

namespace cf::replay {

namespace {

constexpr const char* kInputHeader = "t,tx,ty,tz,qw,qx,qy,qz";

std::string trim(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(
        trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// The "C" numeric locale: numbers are read and written with a '.' whatever locale the
// process runs in (in Python, locale.setlocale(LC_ALL, '') under de_DE made the CSV's
// numbers '0,199000', their commas read as column separators).
locale_t c_numeric() {
  static const locale_t c = newlocale(LC_NUMERIC_MASK, "C", static_cast<locale_t>(nullptr));
  return c;
}

// This thread formats in the C numeric locale while it lives.
class CNumeric {
 public:
  CNumeric() : old_(uselocale(c_numeric())) {}
  ~CNumeric() { uselocale(old_); }
  CNumeric(const CNumeric&) = delete;
  CNumeric& operator=(const CNumeric&) = delete;

 private:
  locale_t old_;
};

[[noreturn]] void fail(const std::string& source, int line, const std::string& why) {
  throw Error(source + ":" + std::to_string(line) + ": " + why);
}

double number(const std::string& field, const char* column, const std::string& source, int line) {
  if (field.empty()) fail(source, line, std::string("column '") + column + "' is empty");
  errno = 0;
  char* end = nullptr;
  // Decimal only: strtod also reads hexadecimal ("0x1p4"), which no CSV writer means.
  if (field.find_first_of("xX") != std::string::npos)
    fail(
        source, line,
        std::string("column '") + column + "' is not a decimal number: '" + printable(field) + "'");
  const double v = strtod_l(field.c_str(), &end, c_numeric());
  // ERANGE also reports an underflow (5e-324, a subnormal), whose result is the nearest double.
  const bool overflow = errno == ERANGE && std::abs(v) > DBL_MIN;
  if (end != field.c_str() + field.size() || overflow || !std::isfinite(v))
    fail(source, line,
         std::string("column '") + column + "' is not a finite number: '" + printable(field) + "'");
  return v;
}

}  // namespace

std::vector<Sample> parse_trajectory(const std::string& text, const std::string& source) {
  static const char* const kColumns[] = {"t", "tx", "ty", "tz", "qw", "qx", "qy", "qz"};
  std::vector<Sample> out;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  bool header = false;
  while (std::getline(in, raw)) {
    ++line;
    const std::string s = trim(raw);
    if (s.empty() || s[0] == '#') continue;
    const std::vector<std::string> f = split(s);
    if (!header) {
      std::string joined;
      for (std::size_t i = 0; i < f.size(); ++i) joined += (i ? "," : "") + f[i];
      if (joined != kInputHeader)
        fail(source, line,
             std::string("expected the header '") + kInputHeader + "', found '" + printable(s) +
                 "'");
      header = true;
      continue;
    }
    if (f.size() != 8)
      fail(source, line,
           "expected 8 columns (" + std::string(kInputHeader) + "), found " +
               std::to_string(f.size()));
    double v[8];
    for (int i = 0; i < 8; ++i)
      v[i] = number(f[static_cast<std::size_t>(i)], kColumns[i], source, line);
    Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    if (std::string why = quaternion_problem(v[4], v[5], v[6], v[7]); !why.empty())
      fail(source, line, why);
    q.normalize();
    Sample smp;
    smp.t = v[0];
    smp.pose.R_BA = q.toRotationMatrix();
    smp.pose.t_BA = Vec3(v[1], v[2], v[3]);
    smp.q = {v[4], v[5], v[6], v[7]};
    smp.line = line;
    if (!out.empty() && !(smp.t > out.back().t)) {
      char buf[160];
      const CNumeric c_numbers;
      std::snprintf(buf, sizeof buf,
                    "time %.9g s does not increase (previous row, line %d: %.9g s)", smp.t,
                    out.back().line, out.back().t);
      fail(source, line, buf);
    }
    out.push_back(smp);
  }
  if (!header)
    fail(source, std::max(line, 1),
         std::string("empty file: expected the header '") + kInputHeader + "'");
  if (out.empty()) fail(source, line, "no pose rows after the header");
  return out;
}

std::vector<Sample> read_trajectory(const std::string& path) {
  // Never blocks on a FIFO; a directory or a device is refused before reading.
  std::string text, why;
  if (!read_input_file(path, text, why))
    throw FileError(path + ": cannot open the trajectory: " + why);
  return parse_trajectory(text, path);
}

const char* output_header() {
  return "t,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz,FAx,FAy,FAz,MAx,MAy,MAz,status,regimes,"
         "proxy_tx,proxy_ty,proxy_tz,proxy_qw,proxy_qx,proxy_qy,proxy_qz,Fcx,Fcy,Fcz,Mcx,Mcy,Mcz,"
         "discontinuities";
}

std::string format_row(const Row& r) {
  const CNumeric c_numbers;
  // The proxy's attitude as a unit quaternion with qw >= 0 (one of the two that name it).
  Eigen::Quaterniond q(r.X_WP.R_BA);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  // The time as its shortest round-trip decimal, so that any two distinct times stay distinct
  // (ticks of 1e-7 s too) and a time read from a trajectory is written as it was given.
  char t[32];
  *std::to_chars(t, t + sizeof t - 1, r.t).ptr = '\0';
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%s,%d,%s,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%s,%s,"
                "%.9g,%.9g,%.9g,%.12f,%.12f,%.12f,%.12f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%s",
                t, r.cf, r.pcs.c_str(), r.motion.c_str(), r.F_W.x(), r.F_W.y(), r.F_W.z(),
                r.M_W.x(), r.M_W.y(), r.M_W.z(), r.F_A.x(), r.F_A.y(), r.F_A.z(), r.M_A.x(),
                r.M_A.y(), r.M_A.z(), r.status.c_str(), r.regimes.c_str(), r.X_WP.t_BA.x(),
                r.X_WP.t_BA.y(), r.X_WP.t_BA.z(), q.w(), q.x(), q.y(), q.z(), r.Fc_W.x(),
                r.Fc_W.y(), r.Fc_W.z(), r.Mc_W.x(), r.Mc_W.y(), r.Mc_W.z(),
                r.discontinuities.c_str());
  return buf;
}

void write_file_atomic(const std::string& path, const std::string& text,
                       const std::vector<std::string>& inputs) {
  write_outputs({OutputFile{path, text}}, inputs, "writing");
}

namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string fmt_tick(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A "nice" tick step near range / 6.
double nice_step(double range) {
  if (!(range > 0)) return 1;
  const double raw = range / 6;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * p) return m * p;
  return 10 * p;
}

}  // namespace

std::string svg_plot(const std::vector<Row>& rows, const std::string& title) {
  const CNumeric c_numbers;
  const double W = 1100, left = 70, right = 20, top = 40, panel_h = 240, gap = 50;
  const double plot_w = W - left - right;
  const double H = top + 2 * panel_h + gap + 50;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << left << "\" y=\"20\" font-size=\"14\">" << esc(title) << "</text>\n";
  if (rows.empty()) {
    o << "<text x=\"" << left << "\" y=\"60\">no rows</text>\n</svg>\n";
    return o.str();
  }
  const double t0 = rows.front().t;
  const double t1 = std::max(rows.back().t, t0 + 1e-9);
  auto X = [&](double t) { return left + (t - t0) / (t1 - t0) * plot_w; };

  // Bands: runs of equal (cf, motion).
  static const char* const kBand[] = {"#eef3fb", "#fbf3e6", "#eefaf0", "#f7eefa"};
  struct Band {
    std::size_t a, b;
  };
  std::vector<Band> bands;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (bands.empty() || rows[i].cf != rows[bands.back().a].cf ||
        rows[i].motion != rows[bands.back().a].motion)
      bands.push_back({i, i});
    bands.back().b = i;
  }

  const char* const colors[] = {"#d62728", "#2ca02c", "#1f77b4"};
  for (int panel = 0; panel < 2; ++panel) {
    const double y0 = top + panel * (panel_h + gap);
    double lo = 0, hi = 0;
    for (const Row& r : rows) {
      const Vec3& v = panel == 0 ? r.F_W : r.M_W;
      lo = std::min(lo, v.minCoeff());
      hi = std::max(hi, v.maxCoeff());
    }
    if (hi - lo < 1e-9) {
      hi += 1;
      lo -= 1;
    }
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
    auto Y = [&](double v) { return y0 + (hi - v) / (hi - lo) * panel_h; };

    for (std::size_t k = 0; k < bands.size(); ++k) {
      const Band& b = bands[k];
      const double xa = X(rows[b.a].t);
      const double xb = b.b + 1 < rows.size() ? X(rows[b.b + 1].t) : X(rows[b.b].t);
      const std::string label =
          (rows[b.a].cf >= 0 ? "CF " + std::to_string(rows[b.a].cf) : std::string("no CF")) + " " +
          rows[b.a].motion;
      o << "<rect x=\"" << fmt(xa) << "\" y=\"" << fmt(y0) << "\" width=\""
        << fmt(std::max(xb - xa, 0.5)) << "\" height=\"" << fmt(panel_h) << "\" fill=\""
        << kBand[k % 4] << "\"><title>" << esc(label) << " (" << fmt_tick(rows[b.a].t) << "-"
        << fmt_tick(rows[b.b].t) << " s)</title></rect>\n";
      if (xb - xa > 12) {
        const double ty = y0 + 4;
        o << "<text transform=\"translate(" << fmt(xa + 10) << "," << fmt(ty)
          << ") rotate(90)\" fill=\"#666\">" << esc(label) << "</text>\n";
      }
    }
    // Axes and grid.
    o << "<rect x=\"" << left << "\" y=\"" << fmt(y0) << "\" width=\"" << plot_w << "\" height=\""
      << panel_h << "\" fill=\"none\" stroke=\"#444\"/>\n";
    const double ys = nice_step(hi - lo);
    for (double v = std::ceil(lo / ys) * ys; v <= hi; v += ys) {
      o << "<line x1=\"" << left << "\" x2=\"" << left + plot_w << "\" y1=\"" << fmt(Y(v))
        << "\" y2=\"" << fmt(Y(v)) << "\" stroke=\"#ccc\" stroke-dasharray=\"2,3\"/>\n";
      o << "<text x=\"" << left - 5 << "\" y=\"" << fmt(Y(v) + 4) << "\" text-anchor=\"end\">"
        << fmt_tick(v) << "</text>\n";
    }
    const double xs = nice_step(t1 - t0);
    for (double t = std::ceil(t0 / xs) * xs; t <= t1 + 1e-12; t += xs) {
      o << "<text x=\"" << fmt(X(t)) << "\" y=\"" << fmt(y0 + panel_h + 14)
        << "\" text-anchor=\"middle\">" << fmt_tick(t) << "</text>\n";
    }
    o << "<text transform=\"translate(15," << fmt(y0 + panel_h / 2)
      << ") rotate(-90)\" text-anchor=\"middle\">"
      << (panel == 0 ? "force F (N, world)" : "moment M (N mm, world)") << "</text>\n";

    // Series, with min/max per pixel column so that spikes survive: the rendered wrench (full),
    // then the contact wrench (dashed; it differs while the proxy holds A out of B).
    const int cols = static_cast<int>(plot_w);
    for (int series = 0; series < 6; ++series) {
      const int c = series % 3;
      const bool contact = series >= 3;
      o << "<polyline fill=\"none\" stroke=\"" << colors[c] << "\" stroke-width=\"1.2\""
        << (contact ? " stroke-dasharray=\"4,3\" opacity=\"0.7\"" : "") << " points=\"";
      int col = -1;
      double mn = 0, mx = 0, last = 0;
      auto flush = [&]() {
        if (col < 0) return;
        const double x = left + col;
        o << fmt(x) << "," << fmt(Y(mx)) << " " << fmt(x) << "," << fmt(Y(mn)) << " " << fmt(x)
          << "," << fmt(Y(last)) << " ";
      };
      for (const Row& r : rows) {
        const double v =
            (contact ? (panel == 0 ? r.Fc_W : r.Mc_W) : (panel == 0 ? r.F_W : r.M_W))(c);
        const int cc = std::min(cols - 1, static_cast<int>((X(r.t) - left)));
        if (cc != col) {
          flush();
          col = cc;
          mn = mx = v;
        }
        mn = std::min(mn, v);
        mx = std::max(mx, v);
        last = v;
      }
      flush();
      o << "\"/>\n";
      const char* names[2][2][3] = {{{"Fx", "Fy", "Fz"}, {"Mx", "My", "Mz"}},
                                    {{"Fcx", "Fcy", "Fcz"}, {"Mcx", "Mcy", "Mcz"}}};
      o << "<text x=\"" << fmt(left + plot_w - 260 + 45 * series) << "\" y=\"" << fmt(y0 - 6)
        << "\" fill=\"" << colors[c] << "\">" << names[contact ? 1 : 0][panel][c]
        << (contact ? " (dashed)" : "") << "</text>\n";
    }
  }
  o << "<text x=\"" << fmt(left + plot_w / 2) << "\" y=\"" << fmt(H - 10)
    << "\" text-anchor=\"middle\">time (s)"
    << "</text>\n";
  o << "</svg>\n";
  return o.str();
}

}  // namespace cf::replay

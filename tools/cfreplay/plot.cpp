#include "plot.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <locale>
#include <sstream>

namespace cf::replay {

namespace {

// The motion types drawn as events (bit k of Bin::events), and their colours.
constexpr const char* kEventTypes[] = {"MT1", "MT3", "MT4", "MT5"};
constexpr const char* kEventColours[] = {"#9467bd", "#ff7f0e", "#8c564b", "#e377c2"};
constexpr int kNumEvents = 4;
constexpr const char* kAxisColours[] = {"#d62728", "#2ca02c", "#1f77b4"};
constexpr const char* kBandFills[] = {"#eef3fb", "#fbf3e6", "#eefaf0", "#f7eefa"};

std::uint8_t event_bits(const std::string& motion) {
  for (int k = 0; k < kNumEvents; ++k)
    if (motion == kEventTypes[k]) return static_cast<std::uint8_t>(1u << k);
  return 0;
}

PlotRecorder::Bin merged(const PlotRecorder::Bin& a, const PlotRecorder::Bin& b) {
  if (!a.used) return b;
  if (!b.used) return a;
  PlotRecorder::Bin m = a;
  m.t_last = b.t_last;
  m.last = b.last;
  for (int s = 0; s < PlotRecorder::kSeries; ++s) {
    m.lo[s] = std::min(a.lo[s], b.lo[s]);
    m.hi[s] = std::max(a.hi[s], b.hi[s]);
  }
  m.events = static_cast<std::uint8_t>(a.events | b.events);
  return m;
}

}  // namespace

void PlotRecorder::place(double t, int& bin) {
  if (ticks_ == 0) {
    t0_ = t;
    bin = 0;
    return;
  }
  if (!(t > t0_)) {  // not after the first tick (a replay's times increase): its bin
    bin = 0;
    return;
  }
  if (width_ == 0) width_ = t - t0_;  // the second tick opens bin 1
  auto index = [&] { return static_cast<long>(std::floor((t - t0_) / width_)); };
  // Past the last bin: halve the resolution, each bin the merge of two, until the tick fits.
  while (index() >= kBins) {
    for (int i = 0; i < kBins / 2; ++i) bins_[i] = merged(bins_[2 * i], bins_[2 * i + 1]);
    std::fill(bins_.begin() + kBins / 2, bins_.end(), Bin{});
    width_ *= 2;
  }
  bin = static_cast<int>(std::max(0L, index()));
}

void PlotRecorder::add(const ReplayRow& row) {
  int k = 0;
  place(row.t_s, k);
  std::array<float, kSeries> v{};
  for (int c = 0; c < 3; ++c) {
    v[c] = static_cast<float>(row.F_W[c]);
    v[3 + c] = static_cast<float>(row.Fc_W[c]);
    v[6 + c] = static_cast<float>(row.M_W[c]);
    v[9 + c] = static_cast<float>(row.Mc_W[c]);
  }
  v[12] = static_cast<float>((row.X_WD.t_BA - row.X_WP.t_BA).norm());
  Bin one;
  one.used = true;
  one.t_first = one.t_last = row.t_s;
  one.first = one.lo = one.hi = one.last = v;
  one.events = event_bits(row.motion);
  bins_[k] = merged(bins_[k], one);
  add_band(row);
  t_end_ = row.t_s;
  ++ticks_;
}

void PlotRecorder::add_band(const ReplayRow& row) {
  if (!bands_.empty() && bands_.back().cf == row.cf && bands_.back().motion == row.motion) {
    bands_.back().t_b = row.t_s;
    return;
  }
  if (!bands_.empty()) bands_.back().t_b = row.t_s;
  bands_.push_back({row.t_s, row.t_s, row.cf, row.motion, row.pcs});
  if (bands_.size() > kMaxBands) compact_bands();
}

void PlotRecorder::compact_bands() {
  // Runs narrower than `narrow` next to each other become one band of several CFs; the open
  // (last) band stays as it is. The events stay in the bins, each tick of them.
  for (double narrow = std::max(width_, 1e-300); bands_.size() > kMaxBands / 2; narrow *= 2) {
    std::vector<Band> out;
    for (std::size_t i = 0; i < bands_.size(); ++i) {
      const Band& b = bands_[i];
      const bool short_run = i + 1 < bands_.size() && b.t_b - b.t_a < narrow;
      if (short_run && !out.empty() && out.back().cf == -2) {
        out.back().t_b = b.t_b;
      } else if (short_run) {
        out.push_back({b.t_a, b.t_b, -2, "", ""});
      } else {
        out.push_back(b);
      }
    }
    bands_.swap(out);
  }
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

// Numbers through std::to_chars: the same text in any locale the process runs in.
std::string fmt(double v) {
  char b[64];
  return std::string(b, std::to_chars(b, b + sizeof b, v, std::chars_format::fixed, 2).ptr);
}

std::string fmt_tick(double v) {
  char b[64];
  return std::string(b, std::to_chars(b, b + sizeof b, v, std::chars_format::general, 4).ptr);
}

// A time in a tooltip: six significant digits tell ticks of 1 ms apart up to 1000 s.
std::string fmt_time(double t) {
  char b[64];
  return std::string(b, std::to_chars(b, b + sizeof b, t, std::chars_format::general, 6).ptr);
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

// Width in pixels of `text` at the plot's 11 px sans-serif: an upper bound on an average
// glyph, so that laid-out text never overlaps.
double text_width(const std::string& text) { return 6.5 * static_cast<double>(text.size()); }

// `text` cut to fit `px` pixels, "..." marking the cut.
std::string fit(const std::string& text, double px) {
  const auto n = static_cast<std::size_t>(std::max(0.0, px / 6.5));
  if (text.size() <= n) return text;
  return n > 3 ? text.substr(0, n - 3) + "..." : std::string();
}

// The figure's geometry: pixels, left to right and top down.
struct Frame {
  double width = 1100, left = 70, right = 20;
  double plot_w() const { return width - left - right; }
  double t0 = 0, t1 = 1;  // s, the time axis
  double x(double t) const { return left + (t - t0) / (t1 - t0) * plot_w(); }
};

// One panel: its place, its value range and its series.
struct Panel {
  const char* axis_label;
  double y0 = 0, height = 0, lo = 0, hi = 0;
  std::vector<int> series;  // indices into the bins' series
  double y(double v) const { return y0 + (hi - v) / (hi - lo) * height; }
};

struct LegendEntry {
  std::string label, colour;
  bool dashed = false, block = false;
};

// Lays the entries out in rows that fit the plot's width; returns the height used.
double draw_legend(std::ostringstream& o, const Frame& f, double y,
                   const std::vector<LegendEntry>& entries) {
  double x = f.left;
  const double row_h = 16;
  for (const LegendEntry& e : entries) {
    const double w = 24 + text_width(e.label) + 14;
    if (x > f.left && x + w > f.left + f.plot_w()) {
      x = f.left;
      y += row_h;
    }
    if (e.block)
      o << "<rect x=\"" << fmt(x) << "\" y=\"" << fmt(y - 8)
        << "\" width=\"18\" height=\"9\" fill=\"" << e.colour << "\"/>\n";
    else
      o << "<line x1=\"" << fmt(x) << "\" x2=\"" << fmt(x + 18) << "\" y1=\"" << fmt(y - 4)
        << "\" y2=\"" << fmt(y - 4) << "\" stroke=\"" << e.colour << "\" stroke-width=\"1.5\""
        << (e.dashed ? " stroke-dasharray=\"4,3\"" : "") << "/>\n";
    o << "<text x=\"" << fmt(x + 24) << "\" y=\"" << fmt(y) << "\">" << esc(e.label) << "</text>\n";
    x += w;
  }
  return y + row_h;
}

std::vector<LegendEntry> legend_entries() {
  std::vector<LegendEntry> e = {{"x", kAxisColours[0]},
                                {"y", kAxisColours[1]},
                                {"z", kAxisColours[2]},
                                {"rendered (full)", "#444"},
                                {"contact: what B exerts on A (dashed)", "#444", true},
                                {"device beyond the proxy", "#444"}};
  for (int k = 0; k < kNumEvents; ++k)
    e.push_back({std::string(kEventTypes[k]) + " event", kEventColours[k], false, true});
  return e;
}

void draw_bands(std::ostringstream& o, const Frame& f, const std::vector<Panel>& panels,
                const std::vector<PlotRecorder::Band>& bands, double t_end) {
  for (std::size_t k = 0; k < bands.size(); ++k) {
    const PlotRecorder::Band& b = bands[k];
    const double xa = f.x(b.t_a), xb = f.x(k + 1 < bands.size() ? b.t_b : t_end);
    const std::string label =
        b.cf == -2 ? std::string("several CFs")
                   : (b.cf >= 0 ? "CF " + std::to_string(b.cf) : std::string("no CF")) + " " +
                         b.motion + (b.pcs.empty() ? "" : " " + b.pcs);
    for (std::size_t p = 0; p < panels.size(); ++p) {
      o << "<rect x=\"" << fmt(xa) << "\" y=\"" << fmt(panels[p].y0) << "\" width=\""
        << fmt(std::max(xb - xa, 0.5)) << "\" height=\"" << fmt(panels[p].height) << "\" fill=\""
        << (b.cf == -2 ? "#e8e8e8" : kBandFills[k % 4]) << "\"><title>" << esc(label) << " ("
        << fmt_time(b.t_a) << "-" << fmt_time(b.t_b) << " s)</title></rect>\n";
      // Labels in the first panel only, read downwards, cut to its height.
      if (p == 0 && xb - xa > 12)
        o << "<text transform=\"translate(" << fmt(xa + 10) << "," << fmt(panels[p].y0 + 4)
          << ") rotate(90)\" fill=\"#666\">" << esc(fit(label, panels[p].height - 8))
          << "</text>\n";
    }
  }
}

void draw_axes(std::ostringstream& o, const Frame& f, const Panel& p) {
  o << "<rect x=\"" << fmt(f.left) << "\" y=\"" << fmt(p.y0) << "\" width=\"" << fmt(f.plot_w())
    << "\" height=\"" << fmt(p.height) << "\" fill=\"none\" stroke=\"#444\"/>\n";
  const double ys = nice_step(p.hi - p.lo);
  for (double v = std::ceil(p.lo / ys) * ys; v <= p.hi; v += ys) {
    o << "<line x1=\"" << fmt(f.left) << "\" x2=\"" << fmt(f.left + f.plot_w()) << "\" y1=\""
      << fmt(p.y(v)) << "\" y2=\"" << fmt(p.y(v))
      << "\" stroke=\"#ccc\" stroke-dasharray=\"2,3\"/>\n";
    o << "<text x=\"" << fmt(f.left - 5) << "\" y=\"" << fmt(p.y(v) + 4)
      << "\" text-anchor=\"end\">" << fmt_tick(std::abs(v) < ys * 1e-9 ? 0.0 : v) << "</text>\n";
  }
  const double xs = nice_step(f.t1 - f.t0);
  for (double t = std::ceil(f.t0 / xs) * xs; t <= f.t1 + xs * 1e-9; t += xs)
    o << "<text x=\"" << fmt(f.x(t)) << "\" y=\"" << fmt(p.y0 + p.height + 14)
      << "\" text-anchor=\"middle\">" << fmt_tick(t) << "</text>\n";
  o << "<text transform=\"translate(15," << fmt(p.y0 + p.height / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">" << p.axis_label << "</text>\n";
}

// Each series as min and max per bin, so that a spike of one tick survives; clipped to its
// panel.
void draw_series(std::ostringstream& o, const Frame& f, const Panel& p, int clip,
                 const std::vector<PlotRecorder::Bin>& bins) {
  o << "<clipPath id=\"panel" << clip << "\"><rect x=\"" << fmt(f.left) << "\" y=\"" << fmt(p.y0)
    << "\" width=\"" << fmt(f.plot_w()) << "\" height=\"" << fmt(p.height) << "\"/></clipPath>\n";
  for (int s : p.series) {
    const bool contact = s < 12 && (s / 3) % 2 == 1;
    o << "<polyline clip-path=\"url(#panel" << clip << ")\" fill=\"none\" stroke=\""
      << (s == 12 ? "#444" : kAxisColours[s % 3]) << "\" stroke-width=\"1.2\""
      << (contact ? " stroke-dasharray=\"4,3\" opacity=\"0.7\"" : "") << " points=\"";
    for (const PlotRecorder::Bin& b : bins) {
      if (!b.used) continue;
      const double xa = f.x(b.t_first), xb = f.x(b.t_last), xm = (xa + xb) / 2;
      o << fmt(xa) << "," << fmt(p.y(b.first[s])) << " " << fmt(xm) << "," << fmt(p.y(b.hi[s]))
        << " " << fmt(xm) << "," << fmt(p.y(b.lo[s])) << " " << fmt(xb) << ","
        << fmt(p.y(b.last[s])) << " ";
    }
    o << "\"/>\n";
  }
}

// A strip above the first panel, a row per event type: a mark at least 2 px wide for every
// bin holding such a tick, a faint line down the first panel, and the type's name where
// there is room for it.
void draw_events(std::ostringstream& o, const Frame& f, const Panel& first, double strip_y,
                 const std::vector<PlotRecorder::Bin>& bins) {
  double label_end = -1e300;
  for (const PlotRecorder::Bin& b : bins) {
    if (!b.used || b.events == 0) continue;
    const double xa = f.x(b.t_first), w = std::max(f.x(b.t_last) - xa, 2.0);
    std::string names;
    for (int k = 0; k < kNumEvents; ++k) {
      if (!(b.events & (1u << k))) continue;
      names += (names.empty() ? "" : ",") + std::string(kEventTypes[k]);
      o << "<rect x=\"" << fmt(xa) << "\" y=\"" << fmt(strip_y + 4 * k) << "\" width=\"" << fmt(w)
        << "\" height=\"4\" fill=\"" << kEventColours[k] << "\"><title>" << kEventTypes[k]
        << (b.t_last > b.t_first ? " between " + fmt_time(b.t_first) + " and " + fmt_time(b.t_last)
                                 : " at " + fmt_time(b.t_first))
        << " s</title></rect>\n";
      o << "<line x1=\"" << fmt(xa) << "\" x2=\"" << fmt(xa) << "\" y1=\"" << fmt(first.y0)
        << "\" y2=\"" << fmt(first.y0 + first.height) << "\" stroke=\"" << kEventColours[k]
        << "\" stroke-width=\"1\" opacity=\"0.35\"/>\n";
    }
    if (xa >= label_end) {
      o << "<text x=\"" << fmt(xa) << "\" y=\"" << fmt(strip_y - 3) << "\" font-size=\"10\">"
        << names << "</text>\n";
      label_end = xa + text_width(names) + 4;
    }
  }
}

// Each panel's range: its series' extremes and zero, padded by 5%.
void set_range(Panel& p, const std::vector<PlotRecorder::Bin>& bins) {
  p.lo = p.hi = 0;
  for (const PlotRecorder::Bin& b : bins)
    for (int s : p.series)
      if (b.used) {
        p.lo = std::min(p.lo, static_cast<double>(b.lo[s]));
        p.hi = std::max(p.hi, static_cast<double>(b.hi[s]));
      }
  if (p.hi - p.lo < 1e-9) p.hi += 1;
  const double pad = 0.05 * (p.hi - p.lo);
  if (p.lo < 0) p.lo -= pad;
  p.hi += pad;
}

}  // namespace

std::string PlotRecorder::svg(const std::string& title) const {
  Frame f;
  f.t0 = t0_;
  f.t1 = std::max(t_end_, t0_ + 1e-9);
  std::ostringstream body;
  body.imbue(std::locale::classic());
  body << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  body << "<text x=\"" << fmt(f.left) << "\" y=\"20\" font-size=\"14\">" << esc(title)
       << "</text>\n";
  double height = 80;
  if (ticks_ == 0) {
    body << "<text x=\"" << fmt(f.left) << "\" y=\"60\">no rows</text>\n";
  } else {
    const double legend_end = draw_legend(body, f, 42, legend_entries());
    const double strip_y = legend_end + 14;
    std::vector<Panel> panels = {
        {"force F (N, world)", strip_y + 22, 220, 0, 0, {0, 1, 2, 3, 4, 5}},
        {"moment M (N mm, world)", 0, 220, 0, 0, {6, 7, 8, 9, 10, 11}},
        {"beyond the proxy (mm)", 0, 110, 0, 0, {12}}};
    for (std::size_t p = 1; p < panels.size(); ++p)
      panels[p].y0 = panels[p - 1].y0 + panels[p - 1].height + 40;
    for (Panel& p : panels) set_range(p, bins_);
    draw_bands(body, f, panels, bands_, t_end_);
    for (std::size_t p = 0; p < panels.size(); ++p) {
      draw_axes(body, f, panels[p]);
      draw_series(body, f, panels[p], static_cast<int>(p), bins_);
    }
    draw_events(body, f, panels[0], strip_y, bins_);
    height = panels.back().y0 + panels.back().height + 45;
    body << "<text x=\"" << fmt(f.left + f.plot_w() / 2) << "\" y=\"" << fmt(height - 10)
         << "\" text-anchor=\"middle\">time (s)</text>\n";
  }
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fmt(f.width) + "\" height=\"" +
         fmt(height) + "\" font-family=\"sans-serif\" font-size=\"11\">\n" + body.str() +
         "</svg>\n";
}

}  // namespace cf::replay

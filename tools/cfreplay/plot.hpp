#pragma once
// cfreplay's SVG plot, gathered tick by tick in bounded memory: a replay of 10 million ticks
// plots from a few megabytes, as one of 100 ticks does.

#include <cf/replay.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cf::replay {

/// Gathers what the plot shows and draws it: the rendered wrench (full lines) and the
/// contact wrench B exerts on A (dashed), in panels of force and moment, and a panel of how
/// far the device is pressed in beyond the proxy; behind them, bands for the runs of one
/// (CF, motion) labelled with their CF, motion type and PCs; above them, a mark for every
/// tick of motion type MT1, MT3, MT4 or MT5, however short.
class PlotRecorder {
 public:
  /// Series per bin: F_W, Fc_W, M_W, Mc_W (3 each), then the depth beyond the proxy.
  static constexpr int kSeries = 13;
  /// Time bins kept: at least two per pixel column of the plot, so min and max survive.
  static constexpr int kBins = 2048;
  /// Bands kept before runs narrower than a bin are merged into "several CFs".
  static constexpr std::size_t kMaxBands = 4096;

  void add(const ReplayRow& row);
  /// The SVG, titled `title`; "no rows" when add() was never called.
  std::string svg(const std::string& title) const;

  struct Bin {
    bool used = false;
    double t_first = 0, t_last = 0;  // s
    std::array<float, kSeries> first{}, lo{}, hi{}, last{};
    std::uint8_t events = 0;  // bit k: a tick of kEventTypes[k]
  };
  struct Band {
    double t_a = 0, t_b = 0;  // s: its first tick, and the next band's first (or its last)
    int cf = -1;              // -2: several short runs merged
    std::string motion, pcs;
  };

 private:
  void place(double t, int& bin);
  void add_band(const ReplayRow& row);
  void compact_bands();

  double t0_ = 0, width_ = 0;  // s: the first tick, and each bin's span (0 until a second tick)
  double t_end_ = 0;           // s: the last tick
  long ticks_ = 0;
  std::vector<Bin> bins_ = std::vector<Bin>(kBins);
  std::vector<Band> bands_;
};

}  // namespace cf::replay

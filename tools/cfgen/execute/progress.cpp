#include "cfgen/execute/progress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace cf::gen {

std::string human_duration(double s) {
  char buf[48];
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 60) {
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  } else if (s < 3600) {
    const long t = std::lround(s);
    std::snprintf(buf, sizeof buf, "%ld min %02ld s", t / 60, t % 60);
  } else {
    const long m = std::lround(s / 60);
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", m / 60, m % 60);
  }
  return buf;
}

double stage_seconds_left(const ProgressEvent& e) {
  if (e.finished) return 0;
  if (e.done == 0 || e.seconds <= 0) return -1;
  return static_cast<double>(e.total - std::min(e.done, e.total)) * e.seconds /
         static_cast<double>(e.done);
}

std::string progress_line(const ProgressEvent& e) {
  std::string line = e.stage + ": ";
  if (e.finished) {
    line += std::to_string(e.total) + " " + e.unit;
    if (!e.result.empty()) line += ", " + e.result;
    return line + " in " + human_duration(e.seconds);
  }
  line += std::to_string(e.done) + "/" + std::to_string(e.total) + " " + e.unit;
  if (e.done > 0 && e.seconds > 0) {
    const double rate = static_cast<double>(e.done) / e.seconds;  // per s
    char buf[32];
    std::snprintf(buf, sizeof buf, rate >= 10 ? "%.0f/s" : "%.2g/s", rate);
    line += std::string(", ") + buf;
    if (e.total > e.done) line += ", " + human_duration(stage_seconds_left(e)) + " left";
  }
  return line;
}

void ProgressPrinter::operator()(const ProgressEvent& e) {
  if (!terminal_) {
    if (e.finished) os_ << prefix_ << progress_line(e) << '\n' << std::flush;
    return;
  }
  std::string line = prefix_ + progress_line(e);
  if (run_seconds_ > 0) {
    // The prediction until the run outlives it, then what the stage under way still needs.
    const double elapsed = std::chrono::duration<double>(Clock::now() - run_start_).count();
    const double left = std::max(run_seconds_ - elapsed, stage_seconds_left(e));
    line += left > 0 ? "; run: about " + human_duration(left) + " left" : "; run: finishing";
  }
  // Pad over the rest of a longer previous line.
  os_ << '\r' << line << std::string(shown_ > line.size() ? shown_ - line.size() : 0, ' ')
      << std::flush;
  shown_ = line.size();
}

void ProgressPrinter::set_run(double seconds) {
  run_seconds_ = seconds;
  run_start_ = Clock::now();
}

void ProgressPrinter::finish() {
  if (terminal_ && shown_ > 0) os_ << '\n' << std::flush;
  shown_ = 0;
}

}  // namespace cf::gen

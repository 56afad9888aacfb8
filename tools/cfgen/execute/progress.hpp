#pragma once
// Progress of a long cfgen run, for a person: an updating line on a terminal, one plain line
// per finished stage otherwise (a log file, a batch job's output).

#include "cfgen/enumerate/stage.hpp"

#include <cstddef>
#include <ostream>
#include <string>

namespace cf::gen {

/// Writes ProgressEvents to a stream. On a terminal: one line, rewritten in place, with the
/// rate and the estimated time left of the stage under way. Otherwise: one line per finished
/// stage, no carriage returns.
class ProgressPrinter {
 public:
  ProgressPrinter(std::ostream& os, bool terminal, std::string prefix = "cfgen: ")
      : os_(os), terminal_(terminal), prefix_(std::move(prefix)) {}
  /// The whole run is predicted to take `seconds` from now (0: not predicted): the updating
  /// line then also gives the time left of the run.
  void set_run(double seconds);
  void operator()(const ProgressEvent& e);
  /// Ends the updating line (terminal only); call once the run is over.
  void finish();

 private:
  std::ostream& os_;
  bool terminal_;
  std::string prefix_;
  std::size_t shown_ = 0;   // length of the line on screen (terminal)
  double run_seconds_ = 0;  // s, the run's predicted length; 0: not predicted
  Clock::time_point run_start_;
};

/// "4.2 s", "3 min 05 s", "2 h 10 min": a duration for people.
std::string human_duration(double seconds);

/// s left of a stage under way at its rate so far; negative when not known yet.
double stage_seconds_left(const ProgressEvent& e);

/// The line printed for an event: stage, counts, rate and time left (or the result).
std::string progress_line(const ProgressEvent& e);

}  // namespace cf::gen

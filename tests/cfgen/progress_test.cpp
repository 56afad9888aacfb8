// cfgen's progress display (tools/cfgen/execute/progress.hpp): what a person sees on a terminal and
// in a log file.
#include "cfgen/execute/progress.hpp"

#include <catch2/catch.hpp>

#include <sstream>

using cf::gen::ProgressEvent;
using cf::gen::ProgressPrinter;

namespace {
ProgressEvent tick(std::size_t done, double seconds) {
  ProgressEvent e{"level 2", "candidate sets", done, 1000, seconds, false, {}};
  return e;
}
ProgressEvent end_of_stage() {
  return ProgressEvent{"level 2", "candidate sets", 1000, 1000, 8.0, true, "16 valid"};
}
}  // namespace

TEST_CASE("durations read as people write them", "[progress]") {
  CHECK(cf::gen::human_duration(4.24) == "4.2 s");
  CHECK(cf::gen::human_duration(185) == "3 min 05 s");
  CHECK(cf::gen::human_duration(7800) == "2 h 10 min");
  CHECK(cf::gen::human_duration(-1) == "?");
}

TEST_CASE("a stage under way shows the rate and the time left", "[progress]") {
  // 250 of 1000 in 2 s: 125/s, 750 left take 6 s.
  CHECK(cf::gen::progress_line(tick(250, 2.0)) ==
        "level 2: 250/1000 candidate sets, 125/s, 6.0 s left");
  // Nothing done yet: no rate to show.
  CHECK(cf::gen::progress_line(tick(0, 0.5)) == "level 2: 0/1000 candidate sets");
  CHECK(cf::gen::progress_line(end_of_stage()) ==
        "level 2: 1000 candidate sets, 16 valid in 8.0 s");
}

TEST_CASE("on a terminal, one line is rewritten in place", "[progress]") {
  std::ostringstream os;
  ProgressPrinter p(os, true);
  p(tick(250, 2.0));
  p(tick(500, 4.0));
  p(end_of_stage());
  p.finish();
  const std::string s = os.str();
  CHECK(s.find('\n') == s.size() - 1);  // one line, ended once
  CHECK(s.rfind('\r') != std::string::npos);
  CHECK(s.find("cfgen: level 2: 500/1000 candidate sets, 125/s, 4.0 s left") != std::string::npos);
  // The last state padded over the longer line before it.
  const std::string last = s.substr(s.rfind('\r') + 1);
  CHECK(last.rfind("cfgen: level 2: 1000 candidate sets, 16 valid in 8.0 s", 0) == 0);
}

TEST_CASE("in a log, one plain line per finished stage", "[progress]") {
  std::ostringstream os;
  ProgressPrinter p(os, false);
  p(tick(250, 2.0));
  p(end_of_stage());
  p(tick(10, 1.0));
  p.finish();
  CHECK(os.str() == "cfgen: level 2: 1000 candidate sets, 16 valid in 8.0 s\n");
}

TEST_CASE("with the run predicted, the line gives the run's time left too", "[progress]") {
  std::ostringstream os;
  ProgressPrinter p(os, true);
  p.set_run(100);
  p(tick(250, 2.0));
  // The prediction, less the microseconds since it was set: 1 min 40 s.
  CHECK(os.str().find("6.0 s left; run: about 1 min 40 s left") != std::string::npos);
  // A run past its prediction: what the stage under way still needs, at its rate.
  std::ostringstream late;
  ProgressPrinter q(late, true);
  q.set_run(1e-9);
  q(tick(250, 2.0));
  CHECK(late.str().find("; run: about 6.0 s left") != std::string::npos);
}

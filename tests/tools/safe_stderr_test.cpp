// The tools' stderr filter (tools/safe_stderr.hpp): control bytes and broken UTF-8 become
// visible \xHH, text and valid UTF-8 pass unchanged.

#include "safe_stderr.hpp"

#include <catch2/catch.hpp>

#include <sstream>
#include <string>

namespace {

// `text` written through the filter, whole or one byte at a time.
std::string filtered(const std::string& text, bool bytewise = false) {
  std::ostringstream sink;
  {
    cf::cli::TerminalSafeBuf buf(sink.rdbuf());
    std::ostream out(&buf);
    if (bytewise)
      for (char c : text) out << c;
    else
      out << text;
  }
  return sink.str();
}

}  // namespace

TEST_CASE("terminal escapes in a message become visible") {
  CHECK(filtered("loading 'a.off': no such file\n") == "loading 'a.off': no such file\n");
  CHECK(filtered("\x1b[2J\x1b[31mred.off") == "\\x1B[2J\\x1B[31mred.off");
  CHECK(filtered("title\x1b]0;x\x07.") == "title\\x1B]0;x\\x07.");
  CHECK(filtered("del\x7f") == "del\\x7F");
  // Progress lines redraw with a carriage return; tabs and newlines stay.
  CHECK(filtered("50%\r60%\tok\n") == "50%\r60%\tok\n");
}

TEST_CASE("valid UTF-8 passes, C1 controls and broken sequences do not") {
  CHECK(filtered("mod\xc3\xa8le \xe6\xa8\xa1\xe5\x9e\x8b.off") ==
        "mod\xc3\xa8le \xe6\xa8\xa1\xe5\x9e\x8b.off");
  CHECK(filtered("mod\xc3\xa8le.off", true) == "mod\xc3\xa8le.off");  // split across writes
  CHECK(filtered("csi\x9b"
                 "31m") == "csi\\x9B31m");  // raw C1
  CHECK(filtered("csi\xc2\x9b"
                 "31m") == "csi\\xC2\\x9B31m");         // C1 encoded as UTF-8
  CHECK(filtered("cut\xc3") == "cut\\xC3");             // truncated at the end
  CHECK(filtered("cut\xe6\xa8x") == "cut\\xE6\\xA8x");  // interrupted
  CHECK(filtered("overlong\xc0\xaf") == "overlong\\xC0\\xAF");
  CHECK(filtered("\xff\xfe") == "\\xFF\\xFE");
}

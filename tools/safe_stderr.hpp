#pragma once
/// @file
/// What the tools print to stderr cannot drive the terminal (docs/bad-input.md, "Terminal
/// escapes"): a path given on the command line goes into messages as typed, and a name
/// holding ESC [ 2 J would clear the screen. Text from inside files is already quoted with
/// cf::printable; this filter covers the paths and anything else a message carries.

#include <array>
#include <cstdio>
#include <iostream>
#include <streambuf>

namespace cf::cli {

/// A stream buffer that passes text through to `out`, writing as \xHH every control byte
/// (C0 but newline, carriage return and tab; DEL; the C1 controls, raw or UTF-8 encoded)
/// and every byte that is not part of a valid UTF-8 sequence. Valid UTF-8 (a name in
/// another script) passes unchanged.
class TerminalSafeBuf : public std::streambuf {
 public:
  explicit TerminalSafeBuf(std::streambuf* out) : out_(out) {}
  ~TerminalSafeBuf() override { drop_partial(); }

 protected:
  int_type overflow(int_type ch) override {
    if (ch != traits_type::eof()) put(static_cast<unsigned char>(ch));
    return traits_type::not_eof(ch);
  }
  int sync() override { return out_->pubsync(); }

 private:
  void escape(unsigned char b) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02X", b);
    out_->sputn(buf, 4);
  }
  // A partial sequence cut short: its bytes were not UTF-8.
  void drop_partial() {
    for (int i = 0; i < have_; ++i) escape(seq_[static_cast<std::size_t>(i)]);
    have_ = need_ = 0;
  }
  static int length_of(unsigned char lead) {
    if (lead >= 0xC2 && lead <= 0xDF) return 2;
    if (lead >= 0xE0 && lead <= 0xEF) return 3;
    if (lead >= 0xF0 && lead <= 0xF4) return 4;
    return 0;  // a continuation byte, an overlong lead (C0, C1) or beyond U+10FFFF
  }
  void put(unsigned char b) {
    if (need_ > 0 && (b & 0xC0) == 0x80) {
      seq_[static_cast<std::size_t>(have_++)] = b;
      if (have_ < need_) return;
      // U+0080..U+009F are the C1 controls (CSI among them).
      const bool c1 = seq_[0] == 0xC2 && seq_[1] <= 0x9F;
      if (c1)
        drop_partial();
      else
        out_->sputn(reinterpret_cast<const char*>(seq_.data()), have_);
      have_ = need_ = 0;
      return;
    }
    drop_partial();
    if (b >= 0x80) {
      need_ = length_of(b);
      if (need_ == 0) return escape(b);
      seq_[0] = b;
      have_ = 1;
      return;
    }
    if ((b < 0x20 && b != '\n' && b != '\r' && b != '\t') || b == 0x7F) return escape(b);
    out_->sputc(static_cast<char>(b));
  }

  std::streambuf* out_;
  std::array<unsigned char, 4> seq_{};
  int have_ = 0, need_ = 0;
};

/// For a tool's main: std::cerr goes through a TerminalSafeBuf while this lives.
class TerminalSafeStderr {
 public:
  TerminalSafeStderr() : buf_(std::cerr.rdbuf()), old_(std::cerr.rdbuf(&buf_)) {}
  ~TerminalSafeStderr() {
    std::cerr.flush();
    std::cerr.rdbuf(old_);
  }
  TerminalSafeStderr(const TerminalSafeStderr&) = delete;
  TerminalSafeStderr& operator=(const TerminalSafeStderr&) = delete;

 private:
  TerminalSafeBuf buf_;
  std::streambuf* old_;
};

}  // namespace cf::cli

// libFuzzer target for cfreplay's trajectory reader (parse_trajectory). A cf::Error is the
// expected answer to bad input; anything else is a finding.

#include "replay_io.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)cf::replay::parse_trajectory(text, "fuzz");
  } catch (const cf::Error&) {
  }
  return 0;
}

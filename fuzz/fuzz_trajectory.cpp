// libFuzzer target for the trajectory reader (cf::TrajectoryCsvReader, libcf): every sample
// read to the end. A cf::Error is the expected answer to bad input; anything else is a finding.

#include <cf/replay.hpp>
#include <cf/types.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  cf::TrajectoryCsvReader reader(std::string(reinterpret_cast<const char*>(data), size), "fuzz");
  try {
    cf::TrajectorySample sample;
    while (reader.next(sample)) {
    }
  } catch (const cf::Error&) {
  }
  return 0;
}

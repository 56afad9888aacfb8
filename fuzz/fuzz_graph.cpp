// libFuzzer target for the graph loader (FUZZ_CBOR: 0 JSON, 1 CBOR): CfGraph::from_bytes
// with the schema check, as cfinspect and cfreplay load a graph. A cf::Error is the
// expected answer to bad input; anything else is a finding.

#include <cf/graph.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

#ifndef FUZZ_CBOR
#error "define FUZZ_CBOR"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  cf::GraphLoadOptions options;
  options.full_schema_check = (size % 2) == 0;  // both checks, on alternate inputs
  try {
    const cf::CfGraph g = cf::CfGraph::from_bytes(bytes, "fuzz", FUZZ_CBOR != 0, options);
    (void)g.to_json();
  } catch (const cf::Error&) {
  }
  return 0;
}

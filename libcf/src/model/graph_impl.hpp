#pragma once
// Private: the representation behind cf::CfGraph and the checks its readers share.

#include <cf/graph.hpp>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace cf::internal {

/// Hash of one PC (type and both indices).
struct PcHash {
  std::size_t operator()(const Pc& pc) const noexcept {
    const std::uint64_t k = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(pc.a)) << 32) |
                            static_cast<std::uint32_t>(pc.b);
    return std::hash<std::uint64_t>()(k * 0x9E3779B97F4A7C15ull ^
                                      static_cast<std::uint64_t>(pc.type));
  }
};

/// Says where a fault is, in the caller's terms: "CF 3" for from_parts, "'g.json' at
/// /cfs/3" for load. The checks below use it to build their messages.
class FaultLocator {
 public:
  virtual ~FaultLocator() = default;
  [[noreturn]] virtual void cf_fault(std::size_t cf, const std::string& what) const = 0;
  /// `pc` indexes the PCs as the caller gave them (before sorting into a PcSet).
  [[noreturn]] virtual void pc_fault(std::size_t cf, std::size_t pc, const char* field,
                                     const std::string& what) const = 0;
  [[noreturn]] virtual void transition_fault(std::size_t t, const char* field,
                                             const std::string& what) const = 0;
  [[noreturn]] virtual void metadata_fault(const std::string& what) const = 0;
};

/// Empty when the witness is a rigid pose (R a rotation within 1e-6, everything finite),
/// else the reason. `field` is set to "R" or "t".
std::string check_witness(const Pose& pose, const char** field);

}  // namespace cf::internal

namespace cf {

struct CfGraph::Impl {
  Polyhedron a, b;
  std::vector<CfRecord> cfs;
  std::vector<Transition> transitions;
  std::unordered_map<PcSet, CfId> index;          ///< PC set -> CF, for constant-time find
  std::unordered_set<Pc, internal::PcHash> held;  ///< every PC some CF holds
  std::vector<std::vector<Transition>> out;       ///< per CF, sorted by target id
  std::string metadata;                           ///< JSON object text, canonical dump

  /// Checks everything that does not need the original PC order (repeated PC sets, PCs
  /// sharing a contact plane, transitions) and builds the index and the out lists. PC index ranges
  /// are the caller's job (check_pc), so that it can point at the PC as given.
  void build(const internal::FaultLocator& where);
};

}  // namespace cf

namespace cf::internal {
/// Empty when `meta` is a JSON object without the graph's own members, else the reason.
std::string check_metadata(const nlohmann::json& meta);
}  // namespace cf::internal

namespace cf::internal {
class ByteInput;
/// Reads a graph file (io/graph_reader.cpp): one streaming pass, then the checks. The input
/// is read in pieces, never whole (docs/graph-format.md, "Reading").
/// @throws cf::Error naming the input's source, the JSON pointer and the problem.
std::unique_ptr<CfGraph::Impl> read_graph(const ByteInput& in, bool cbor,
                                          const GraphLoadOptions& options);
}  // namespace cf::internal

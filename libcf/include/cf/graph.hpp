#pragma once
/// @file
/// Contact formations and the CF graph of section 5 of docs/spec.md (the PC vocabulary is
/// cf/pc.hpp). The graph is immutable once built or loaded; Boost.Graph and nlohmann live
/// behind it.

#include <cf/pc.hpp>
#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cf {

using CfId = Id<struct CfTag>;

/// Prior-motion kinds a transition allows (docs/spec.md, section 4).
enum class TransitionKind : std::uint8_t { kGain, kLose, kChange };
/// "gain", "lose", "change" as in the graph file.
const char* to_string(TransitionKind kind);
/// Parses "gain", "lose", "change"; std::nullopt for anything else.
std::optional<TransitionKind> transition_kind_from_string(std::string_view name);

/// One contact formation of the graph, with what the run time needs that is cheap to store.
struct CfRecord {
  PcSet pcs;
  Pose witness;  ///< a pose of A realising exactly these PCs with the interiors disjoint
  /// Instantaneous freedoms at the witness: dimension of the space of twists of A that keep
  /// every PC (0..6), of pure translations, and whether some pure rotation keeps the CF.
  int dof = -1;              ///< -1 when not stored in the file
  int translation_dof = -1;  ///< -1 when not stored
  bool pure_rotation = false;
  /// Contact plane of each PC (in PC order) at the witness, world frame: {n_x, n_y, n_z, d}
  /// with n the unit normal pointing into A and n . x == d (mm). Written by cfgen for
  /// inspection and for applications; num_planes == 0 when not stored (the run time
  /// recomputes planes at the current pose).
  std::array<std::array<double, 4>, 3> planes{};
  int num_planes = 0;
};

/// A directed graph edge between two CFs.
struct Transition {
  CfId from;
  CfId to;
  TransitionKind kind = TransitionKind::kGain;
};

/// The JSON Schema of the graph file (schemas/cf-graph.schema.json) as it was when the
/// library was built; it refers to the model schema by its `$id`.
const char* graph_schema_text();

/// Options of CfGraph::load.
struct GraphLoadOptions {
  /// Check the file against schemas/cf-graph.schema.json (embedded in the library) with
  /// valijson. By default valijson checks the document without the items of `cfs` and
  /// `transitions` (the models, the metadata, the top level), and the reader checks those
  /// items itself with rules that refuse whatever the schema refuses (required members,
  /// types, ranges, no unknown members in PCs and witnesses), which keeps 100,000 CFs well
  /// under a second.
  bool validate_schema = true;
  /// Also run valijson over every CF and transition, one at a time (about 7 times slower;
  /// `cfinspect --full-schema`).
  bool full_schema_check = false;
};

/// The CF graph of a model pair (docs/spec.md, section 5). Immutable; share one `const CfGraph`
/// between threads.
class CfGraph {
 public:
  /// Builds and checks a graph from its parts (what cfgen produces).
  /// @param metadata_json  a JSON object text with extra top-level members to write
  ///   (statistics, parameters); "{}" for none.
  /// @throws cf::Error when an index is out of range for the element kind its PC type
  ///   names, a CF has no PC, two PCs of a CF share a contact plane (the same face of A or
  ///   of B), a PC set repeats, dof/translation_dof are out of 0..6/0..3, a transition
  ///   names a missing CF, loops, repeats, or its kind does not fit the two PC sets
  ///   (gain: to = from + one PC; lose: the reverse; change: same count), or the metadata
  ///   is not a JSON object or overrides a member of the graph itself.
  static CfGraph from_parts(Polyhedron a, Polyhedron b, std::vector<CfRecord> cfs,
                            std::vector<Transition> transitions,
                            const std::string& metadata_json = "{}");

  /// Loads a graph file (JSON, or CBOR when the name ends in .cbor), checks it against the
  /// schema and for internal consistency. The file is read in pieces, never whole: the
  /// memory needed is the graph's records (docs/graph-format.md, "Reading").
  /// @throws cf::Error naming the file, the JSON pointer and the problem.
  static CfGraph load(const std::string& path);
  static CfGraph load(const std::string& path, const GraphLoadOptions& options);
  /// Same as load, from the file's bytes already in memory; `source` names them in errors.
  static CfGraph from_bytes(const std::string& bytes, const std::string& source, bool cbor,
                            const GraphLoadOptions& options = GraphLoadOptions());

  /// Writes the graph (JSON, or CBOR when the name ends in .cbor) to a temporary file and
  /// renames it into place, so that the file is whole or absent.
  /// @throws cf::Error when the file cannot be written.
  void save(const std::string& path) const;
  /// The JSON text of the graph file; deterministic for the same graph. indent < 0: one
  /// line; otherwise one member per line at the top level, short containers inline, one
  /// line per CF and per transition (the layout save() writes, with indent 1).
  std::string to_json(int indent = -1) const;

  CfGraph();
  ~CfGraph();
  CfGraph(CfGraph&&) noexcept;
  CfGraph& operator=(CfGraph&&) noexcept;

  const Polyhedron& model_a() const;
  const Polyhedron& model_b() const;
  std::size_t num_cfs() const;
  /// @throws cf::Error when id is not a CF of the graph.
  const CfRecord& cf(CfId id) const;
  std::size_t num_transitions() const;
  /// In file order. @throws cf::Error when i >= num_transitions().
  const Transition& transition(std::size_t i) const;

  /// The CF with exactly this PC set, in constant time.
  std::optional<CfId> find(const PcSet& pcs) const;
  /// True when some CF of the graph holds this PC, in constant time.
  bool holds(const Pc& pc) const;
  /// Transitions leaving `id` (to, kind), sorted by target id.
  /// @throws cf::Error when id is not a CF of the graph.
  const std::vector<Transition>& out_transitions(CfId id) const;
  /// True when the graph has a transition from `from` to `to` (false for invalid ids);
  /// O(log out-degree).
  bool adjacent(CfId from, CfId to) const;
  /// The extra top-level members of the file (statistics, parameters) as JSON text.
  const std::string& metadata_json() const;

  struct Impl;  ///< the representation, complete only inside libcf

 private:
  /// An empty graph when default-constructed or moved from.
  const Impl& impl() const;
  std::unique_ptr<const Impl> impl_;
};

}  // namespace cf

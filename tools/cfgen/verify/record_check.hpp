#pragma once
/// @file
/// Whether a graph's CF record is what the generator would have written: its witness passes
/// Verifier::verify (the one definition of a witness) and its stored freedoms are the ones
/// at that witness. `cfinspect` re-checks every CF of a graph with it.

#include "cfgen/verify/verifier.hpp"

#include <cf/graph.hpp>

#include <string>

namespace cf::gen {

/// The check of every record of one graph: its models analysed once, verify set to the
/// tolerances the graph records. Thread-safe: check() may run on many threads at once.
class RecordCheck {
 public:
  /// `defaults`: the tolerances for those the graph does not record (recorded_params).
  /// @throws cf::Error as recorded_params, or when a model's face cannot be partitioned.
  RecordCheck(const CfGraph& g, const SearchParams& defaults);
  RecordCheck(const RecordCheck&) = delete;
  RecordCheck& operator=(const RecordCheck&) = delete;
  /// check_record with this graph's verifier.
  std::string check(const CfRecord& r) const;

 private:
  ModelInfo a_, b_;  // before verifier_, which refers to them
  Verifier verifier_;
};

/// Empty when `r` holds: verify accepts its witness for its PCs (exactly those PCs touch,
/// locally without penetration, every other element pair at least min_clearance apart,
/// neither solid inside the other) and the freedoms it stores (dof, translation_dof,
/// pure_rotation; those the file leaves out are not compared) equal Verifier::freedoms at
/// the witness. Otherwise why not, one line without the CF's id.
std::string check_record(const Verifier& v, const CfRecord& r);

/// The verification tolerances a graph was generated with: the members touch_tol_mm,
/// min_clearance_mm, good_clearance_mm, min_margin_mm and angle_margin_rad of the metadata
/// object "parameters" (docs/graph-format.md), each missing one taken from `defaults`.
/// @throws cf::Error when a member present is not a positive finite number.
SearchParams recorded_params(const CfGraph& g, SearchParams defaults);

/// mm: the precision the generator measured of `model` ("A" or "B"), the member of
/// /parameters/precision_mm (ModelInfo::precision_mm); 0 when the graph does not say.
/// @throws cf::Error when the value is not a finite number >= 0.
double recorded_precision(const CfGraph& g, const char* model);

}  // namespace cf::gen

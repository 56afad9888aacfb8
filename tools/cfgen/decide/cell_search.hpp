#pragma once
/// @file
/// Branch and bound over rotation space for one candidate set (docs/generator.md, "Deciding
/// a set"): cells of axis-angle coordinates are refuted by the set's relaxation
/// (cell_relaxation.hpp) or split, until every cell is refuted, a rotation is found at which
/// the relaxation holds, or the cells reach the resolution or the budget.

#include "cfgen/decide/cell_relaxation.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <cstddef>
#include <vector>

namespace cf::gen {

struct CellSearchLimits {
  double resolution = 1.5e-5;     // rad: cells of a smaller half-width are not split
  std::size_t max_cells = 20000;  // cells examined before the search gives up
};

/// A refuted cell and why (CellRelaxation::refute), for the certificate file.
struct CellEvidence {
  RotationCell cell;
  CellRelaxation::Refutation refutation;
  bool outside_ball = false;  // the cell holds no axis-angle vector of length <= pi
};

struct CellSearchResult {
  enum class Outcome {
    kRefuted,    // every cell refuted: no pose makes the set's PCs hold
    kRealised,   // the relaxation holds at some rotation: the cells cannot refute the set
    kUndecided,  // a cell at the resolution, or the budget, was left open
  } outcome = Outcome::kUndecided;
  std::size_t cells = 0;     // cells examined
  double smallest_half = 0;  // rad: the half-width of the smallest cell examined
};

/// Searches the rotation space for `pcs`. evidence: when given, receives every refuted cell
/// (the cells tile the whole space when the outcome is kRefuted).
CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits,
                              std::vector<CellEvidence>* evidence = nullptr);

}  // namespace cf::gen

#pragma once
/// @file
/// Branch and bound over poses for one candidate set (docs/generator.md, "Refuting a set over
/// cells of rotation space"): cells of axis-angle coordinates, each with a box of translations,
/// are refuted by the set's relaxation (cell_relaxation.hpp) or by a point of one solid deep
/// inside the other (deep_points.hpp), or split, until every cell is refuted, a witness is
/// found, or the cells reach the resolution or the budget.

#include "cfgen/decide/cell_relaxation.hpp"
#include "cfgen/decide/witness.hpp"

#include <cstddef>
#include <vector>

namespace cf::gen {

struct CellSearchLimits {
  double resolution = 1.5e-5;     // rad, and times the models' size in mm: cells are not split
                                  // below this in rotation and in translation
  std::size_t max_cells = 20000;  // cells examined before the search gives up
  double touch_tol = 1e-9;        // mm: elements this close touch (SearchParams::touch_tol)
  double margin = 0;       // mm: contacts at least this far inside their elements (CellRelaxation)
  double local_slack = 0;  // sine: local non-penetration margin at every contact (CellRelaxation)
  double search_below = 0.05;  // rad: open rotation cells this small are searched for a witness
};

/// Angles [centre - half, centre + half] (rad) of the rotations R0 Rot(n_A, theta) that
/// turn the face of the set's first f-f PC against its face of B (R0 n_A = -n_B, the
/// shortest such turn). half = 0: not used.
struct Arc {
  double centre = 0;
  double half = 0;
};

/// A refuted cell and why, for the certificate file.
struct CellEvidence {
  RotationCell cell;            // the rotations, for a set without an f-f PC
  Arc arc;                      // the rotations, for a set with one (then `cell` is not used)
  Mat3 R_c = Mat3::Identity();  // the rotation at the centre, as the relaxation used it
  TurnBound turn;               // how far the cell's rotations turn A's vectors from R_c
  Vec3 t_lo = Vec3::Zero(), t_hi = Vec3::Zero();  // mm: the translations of A's pivot
  CellRelaxation::Refutation refutation;          // kDeep: `deep` says which point
  bool outside_ball = false;  // the cell holds no axis-angle vector of length <= pi
  bool deep_of_a = true;      // kDeep: a point of A inside B, else of B inside A
  int deep_point = -1;        // kDeep: its index in DeepPoints::points
};

struct CellSearchResult {
  enum class Outcome {
    kRefuted,    // every cell refuted: no pose makes the set's PCs hold without penetration
    kWitness,    // a witness was found near a cell's centre (`witness`)
    kUndecided,  // a cell at the resolution, or the budget, was left open
  } outcome = Outcome::kUndecided;
  Witness witness;           // kWitness: the witness found, verified
  std::size_t cells = 0;     // cells examined
  double smallest_half = 0;  // rad: the half-width of the smallest rotation cell or arc examined
};

/// Searches the poses of `pcs`: over cubes of rotation space, or, when the set has an f-f PC,
/// over arcs of its circle of rotations. search: when given, each open rotation cell below
/// limits.search_below is searched for a witness near its centre's rotation (projected onto
/// the rotational conditions; WitnessSearch::find with seeds_only), and a witness ends the
/// search. evidence: when given, receives every refuted
/// cell (they tile the whole space when the outcome is kRefuted).
CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits, const WitnessSearch* search = nullptr,
                              std::vector<CellEvidence>* evidence = nullptr);

}  // namespace cf::gen

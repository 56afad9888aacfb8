#pragma once
/// @file
/// Branch and bound over poses for one candidate set (docs/generator.md, "Refuting a set over
/// cells of rotation space"): cells of axis-angle coordinates, each with a box of translations,
/// are refuted by the set's relaxation (cell_relaxation.hpp) or by a point of one solid deep
/// inside the other (deep_points.hpp), or split, until every cell is refuted, a witness is
/// found, or the cells reach the resolution or the budget.

#include "cfgen/decide/cell_relaxation.hpp"
#include "cfgen/decide/witness.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <cstddef>
#include <vector>

namespace cf::gen {

/// rad: how far a rotation of an arc cell may be from the f-f's circle, for a pose that meets
/// the f-f's alignment to rot_tol: its rotation is within that angle of the circle (a turn by
/// a moves a unit vector by at most a); twice it for rounding.
inline double off_circle(double rot_tol) { return 2 * rot_tol; }

/// The decision's default resolution (cfgen --resolution): rad in rotation, and in units of D
/// (the smaller model's bounding-box diagonal) in translation.
constexpr double kResolution = 1.5e-5;

struct CellSearchLimits {
  double resolution = kResolution;  // rad, and times `scale` in mm: cells are not split below
                                    // this in rotation and in translation
  double scale = 0;  // mm: the translation resolution's unit, D; 0: the larger model's diagonal
  std::size_t max_cells = 20000;  // cells examined before the search gives up
  double touch_tol = 1e-9;        // mm: elements this close touch (SearchParams::touch_tol)
  double margin = 0;       // mm: contacts at least this far inside their elements (CellRelaxation)
  double local_slack = 0;  // sine: local non-penetration margin at every contact (CellRelaxation)
  double search_below = 0.05;     // rad: open rotation cells this small are searched for a witness
  double rot_tol = kRotAccepted;  // rad: what a pose may leave of a rotational condition
  double deep_extra = 0;  // mm: a deep point must lie this much deeper than the cell lets it move
};

/// How far the maps of a pair's symmetries miss (PairSymmetries::error): elements of A
/// and B are moved at most `length` (mm, both models' errors added) from the image elements,
/// and their directions turned at most `angle` (rad).
struct MapError {
  double length = 0;
  double angle = 0;
};

/// `limits` loosened so that a refutation of a set also refutes its images under maps that
/// miss by `e` (docs/certificates.md, "Images"): the image of a pose of an image within the
/// tolerances of `limits` is a pose of the set within those returned.
CellSearchLimits loosened(CellSearchLimits limits, const MapError& e);

/// The limits a run's decision uses (docs/generator.md, "What the search could not decide"):
/// the verifier's touch tolerance and local slack, and the contact margin of a THIN pose
/// (thin_params), so that a refutation shows that no pose realises the set with any room, a
/// witness or a THIN pose; at most max_cells cells; cells not split below `resolution` rad,
/// and `resolution` times the search's length scale D in translation.
CellSearchLimits decision_limits(const WitnessSearch& search, std::size_t max_cells,
                                 double resolution = kResolution);

/// Angles [centre - half, centre + half] (rad) of the rotations R0 Rot(n_A, theta) that
/// turn the face of the set's first f-f PC against its face of B (R0 n_A = -n_B, the
/// shortest such turn). half = 0: not used.
struct Arc {
  double centre = 0;
  double half = 0;
};

/// One node of the branch and bound's tree (docs/certificates.md, "The tree"): a set of poses,
/// split into its children or refuted as a leaf.
struct CellNode {
  enum class Kind {
    kSplitRotation,     // children: the 8 cubes, or the 2 arcs, of half the width
    kSplitTranslation,  // children: the box cut across `axis` at `at`
    kNarrow,            // children: the narrowed box, and the slabs cut off (kProgram leaves)
    kOutsideBall,       // leaf: the cube holds no axis-angle vector of length <= pi
    kRefuted,           // leaf: refuted by the relaxation or a deep point (`refutation`)
  } kind = Kind::kRefuted;
  int parent = -1;              // index in CellTree::nodes; -1 for the root
  RotationCell cell;            // the rotations, for a set without an f-f PC
  Arc arc;                      // the rotations, for a set with one (then `cell` is not used)
  Mat3 R_c = Mat3::Identity();  // the rotation at the centre, as the relaxation used it
  TurnBound turn;               // how far the node's rotations turn A's vectors from R_c
  Vec3 t_lo = Vec3::Zero(), t_hi = Vec3::Zero();  // mm: the translations of A's pivot
  int axis = -1;                                  // kSplitTranslation: the axis cut
  double at = 0;                                  // kSplitTranslation: mm, where
  CellRelaxation::Refutation refutation;          // kRefuted (kDeep: `deep_*` say which point)
  bool deep_of_a = true;                          // kDeep: a point of A inside B, else of B in A
  int deep_point = -1;                            // kDeep: its index in DeepPoints::points
};

/// The tree of a search, parents before children; complete (every leaf refuted) when the
/// search's outcome is kRefuted.
struct CellTree {
  Vec3 pivot = Vec3::Zero();   // mm, A's frame (CellRelaxation::pivot)
  int circle_pc = -1;          // the f-f PC whose circle the arcs are on; -1: cubes
  Mat3 R0 = Mat3::Identity();  // the circle's rotation at angle 0 (R0 n_A = -n_B)
  Vec3 axis = Vec3::Zero();    // the circle's axis, n_A (A's frame)
  std::vector<CellNode> nodes;
};

struct CellSearchResult {
  enum class Outcome {
    kRefuted,    // every cell refuted: no pose makes the set's PCs hold without penetration
    kWitness,    // a witness was found near a cell's centre (`witness`)
    kUndecided,  // a cell at the resolution, or the budget, was left open
  } outcome = Outcome::kUndecided;
  Witness witness;           // kWitness: the witness found, verified
  std::size_t cells = 0;     // cells examined, those outside the ball of rotations not counted
  double smallest_half = 0;  // rad: the half-width of the smallest rotation cell or arc examined
};

/// Searches the poses of `pcs`: over cubes of rotation space, or, when the set has an f-f PC,
/// over arcs of its circle of rotations. search: when given, each open rotation cell below
/// limits.search_below is searched for a witness near its centre's rotation (projected onto
/// the rotational conditions; WitnessSearch::find with seeds_only), and a witness ends the
/// search. tree: when given, receives the search's tree with the evidence of every leaf
/// (Farkas certificates, the slabs of each narrowing with theirs).
CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits, const WitnessSearch* search = nullptr,
                              CellTree* tree = nullptr);

}  // namespace cf::gen

#pragma once
// Independent test oracle: is a CF's pose unambiguous for the run time's identification
// (docs/runtime.md, "Identification": exactly one CF's PCs touch, no pair they do not dominate
// is within epsilon, nor tilted within its angular tolerance of a touching element)? Decided
// with the oracle's own geometry only.
//
// A pose where the oracle classifies the CF `cf` (its PCs touch, interiors disjoint) is
// unambiguous for a detection band epsilon when:
//
//  1. every e-e PC of the CF crosses at an angle beyond its near-parallel tolerance (the
//     tolerance of the shorter edge) plus the angular margin: the run time reads e-e only
//     between edges that are not near-parallel;
//  2. every element pair of a PC type (v-f, f-v, e-e, e-f, f-e, f-f) that no PC of the CF
//     dominates (its A element in the closure of the PC's A element and its B element in
//     the closure of the PC's B element: another reading of the same touch) is farther apart
//     than epsilon plus the distance margin (closed elements, Euclidean distance), or is an
//     e-f, f-e or f-f pair whose angle (edge against plane, or between the two planes) is
//     beyond its angular tolerance plus the angular margin. Such a pair is within the band
//     only where it shares a point with a PC (an edge or a face at a touching vertex or
//     edge, leaning away); its own point pairs are pairs of this list too.
//
// The angular tolerance is the run time's documented rule (docs/runtime.md, "Tolerances"):
// atan(epsilon / L) clamped to [min, max], L the extent of the contact region: for e-f and
// f-e the part of the edge whose projection lies over the face (the whole edge when it lies
// beside it), for f-f the overlap of the two faces (A's face projected on B's plane) along
// the tilt, for e-e the shorter edge. An f-f pair whose projected faces do not overlap gets
// the largest tolerance.

#include "classify.hpp"

#include <string>

namespace oracle {

struct BandParams {
  double eps = 1.0;           // mm, the detection band (cf::Params::epsilon_mm)
  double min_tol = 1e-3;      // rad, clamp of the derived angular tolerance (runtime defaults)
  double max_tol = 0.1;       // rad
  double dist_margin = 0.05;  // mm, added to eps
  double ang_margin = 0.1;    // share of the angular tolerance added to it
};

/// The angular tolerance of a contact region of extent L (mm).
double band_tolerance(const BandParams& p, double L);

struct Ambiguity {
  bool unambiguous = true;
  std::string why;  // the first pair or PC that makes the pose ambiguous
  int leaning = 0;  // pairs within the band passed by their angle
};

/// Decides condition 1 and 2 above at pose X for the CF `cf` (the oracle's PCs at X).
Ambiguity check_unambiguous(const Poly& A, const Poly& B, const Pose& X, const CfKey& cf,
                            const BandParams& p);

/// Distance between a segment p-q and the closed face f of P (all in P's frame).
double seg_face_dist(const Poly& P, const Face& f, const Vec3& p, const Vec3& q);

}  // namespace oracle

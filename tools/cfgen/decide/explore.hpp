#pragma once
// Growing the set of CFs by motion: from a CF's witness, the translations that keep some of
// its PCs and break the others, followed to the exact first contact. Every contact set met on
// the way is reported with the pose that realises it; the caller verifies it. This reaches
// CFs that the candidate enumeration cannot propose (a CF whose sub-sets are not all valid)
// and places A where obstacles leave it room, which a translation chosen inside the contact
// region alone does not (a face against a wall that another wall crowds).

#include "cfgen/decide/witness.hpp"

#include <vector>

namespace cf::gen {

/// A contact set met by a motion, with the pose where it holds.
struct Discovery {
  PcSet pcs;
  Pose pose;
};

/// Exact first contact of A, posed at `pose` and translated along `d` (B frame), with B:
/// the smallest s in (s_min, s_max] at which a pair of closed elements that did not touch at
/// s = 0 meets (vertex-face, face-vertex and edge-edge events, which between closed
/// polyhedral surfaces include every other). Pairs that a PC of `kept` dominates are
/// ignored: touching them does not change the contact set. `d` is a unit vector, s in mm.
/// Returns +infinity when there is no contact up to s_max.
double first_contact_translation(const Polyhedron& A, const Polyhedron& B, const Pose& pose,
                                 const Vec3& d, double s_min, double s_max, double tol,
                                 const PcSet& kept);

/// First contact of A, posed at `pose` and turned about the axis through p along unit u
/// (B frame, right-handed), with B: the smallest angle in (phi_min, phi_max] (rad) at which a
/// vertex meets a face (solved in closed form) or two edges meet (sign changes of the lines'
/// meeting condition on 192 samples, refined by bisection). Pairs a PC of `kept` dominates
/// are ignored. Returns +infinity when none.
double first_contact_rotation(const Polyhedron& A, const Polyhedron& B, const Pose& pose,
                              const Vec3& p, const Vec3& u, double phi_min, double phi_max,
                              double tol, const PcSet& kept);

/// Contact sets reached from the CF `pcs`, realised at `witness`, by rotations about axes
/// that keep some PCs (through a point PC's contact point, along a line PC's edge, or along a
/// PC's normal) and, when the others are broken, turn them away; and by tipping a line or
/// plane PC about one of its boundary elements into the neighbouring PC that element makes
/// (an f-f about an edge of either face, an e-f or f-e about an end of its edge), the other
/// PCs kept. Deterministic.
std::vector<Discovery> explore_rotations(const WitnessSearch& search, const PcSet& pcs,
                                         const Pose& witness);

/// Other witnesses of a CF of point PCs (v-f, f-v, e-e), turned about its contact point (one
/// PC: 24 turns about six axes) or about the line through its two contact points (two PCs:
/// four turns), kept when the same PCs still hold and verify. A CF of point PCs holds over a
/// range of orientations; the translations from one witness alone reach only the CFs that
/// orientation allows. Empty for other CFs.
std::vector<Pose> turned_witnesses(const WitnessSearch& search, const PcSet& pcs,
                                   const Pose& witness);

/// Contact sets reached from the CF `pcs`, realised at `witness`, by translations that keep
/// every PC (sliding) and by those that break some PCs and keep the others. Deterministic.
std::vector<Discovery> explore_translations(const WitnessSearch& search, const PcSet& pcs,
                                            const Pose& witness);

}  // namespace cf::gen

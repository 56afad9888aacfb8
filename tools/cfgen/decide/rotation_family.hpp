#pragma once
// Families of rotations that meet a set of PCs' rotational conditions (private to
// cfgen/decide): solved, sampled, projected onto and walked along.

#include "cfgen/verify/analysis.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <initializer_list>
#include <optional>
#include <utility>
#include <vector>

namespace cf::gen::internal {

/// Each rotation turned by each angle (rad) about each coordinate axis, both ways: the
/// rotations a little around given ones, in a fixed order.
std::vector<Mat3> turned_about_axes(const std::vector<Mat3>& rots,
                                    std::initializer_list<double> angles);

/// Appends R unless a rotation within 1e-7 (Frobenius) of it is in `out` already.
void add_unique(std::vector<Mat3>& out, const Mat3& R);

/// Rotations R = Rot(axis, theta) * R0 satisfying all constraints; finitely many or samples.
/// finite_out: whether the conditions leave finitely many.
std::vector<Mat3> align_family(const RotConstraints& c, const std::vector<Mat3>& seeds, int samples,
                               bool* finite_out = nullptr);

/// Every rotation meeting three perpendicularity conditions (c.perp.size() == 3, no
/// alignment), each to kRotAccepted: at most eight, found from the resultant of the second
/// and third conditions over the family that meets the first, so that the answer depends on
/// the conditions alone, not on a starting rotation. Nothing when the conditions leave a
/// continuum (they are dependent) or are not three perpendicularities.
std::optional<std::vector<Mat3>> perp_roots(const RotConstraints& c);

/// Gauss-Newton projection of R onto { (R u_i) . w_i == 0 }; false when it does not converge.
bool project_perp(const RotConstraints& c, Mat3& R);

/// The rotations near R that meet the conditions: R projected onto them (an alignment's
/// family through R's spin, or the perpendicularity conditions by Gauss-Newton); R itself
/// when there are none; empty when the projection fails.
std::vector<Mat3> project_onto(const RotConstraints& c, const Mat3& R);

/// Walks a one-parameter family of rotations (one alignment with its spin free, or two
/// perpendicularity conditions) away from R by steps of about h rad, at most n steps along
/// each branch: the rotations along each branch, R excluded. Where the two conditions'
/// gradients coincide (an axis-aligned pose, where branches of the family cross), each branch
/// is entered by a small turn about a coordinate axis projected back onto the conditions.
/// Empty for other families.
std::vector<std::vector<Mat3>> walk_family(const RotConstraints& c, const Mat3& R, double h, int n);

/// Each PC of `pcs` asks the translation t of A (x_B = R x_A + t) to put its contact on one
/// plane, n_i . t = h_i (R): the plane of its face, or for an e-e the plane through B's edge
/// parallel to both edges. Where three such normals lie in one plane at every rotation of a
/// family (two PCs on the faces beside an edge of B and an e-e on that edge), the planes meet
/// only where z . h = 0, z the left null vector of the rows oriented by n_1 x n_2: a condition
/// on the rotation alone, met at isolated points of the family. Two PCs on parallel planes
/// (two parallel edges of A on the facing walls of a slot) meet only where h_2 = s h_1, s the
/// sign of n_1 . n_2: A's width across them must be the slot's. Returns z . h (mm) at R, or
/// h_2 - s h_1 for two PCs; nothing when the set has not two or three PCs or the normals are
/// independent at R: further than `dependent` (a sine, or the determinant of three unit
/// normals) from dependent; direction_tol on models known to a precision, whose parallel
/// faces are parallel only to it.
std::optional<double> translation_residual(const Polyhedron& A, const Polyhedron& B,
                                           const PcSet& pcs, const Mat3& R,
                                           double dependent = 1e-9);

/// Rotations that meet the perpendicularity conditions of `c` (no alignment) and make the
/// PCs' planes meet (translation_residual == 0), where the residual is defined: R projected
/// onto them by Gauss-Newton (false when that fails), and the curve of such rotations walked
/// from R by steps of h rad, at most n each way (both ways, R excluded).
/// `dependent` as translation_residual's.
bool project_consistent(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs,
                        const RotConstraints& c, Mat3& R, double dependent = 1e-9);
std::vector<std::vector<Mat3>> walk_consistent(const Polyhedron& A, const Polyhedron& B,
                                               const PcSet& pcs, const RotConstraints& c,
                                               const Mat3& R, double h, int n,
                                               double dependent = 1e-9);

/// Spins phi (rad) at which R0 Rot(axis, phi) (axis: unit, A's frame) holds every PC of `pcs`
/// locally admissible, its local margin (Verifier::local_margin) above min_local: the centres
/// 2 pi k / samples of equal arcs of the whole turn, and where a centre is not admissible but
/// the margin's bound over its arc (local_margin_bound) leaves room, the centres of its halves,
/// down to arcs of 2e-3 rad. A range of admissible spins narrower than the samples' spacing
/// (a vertex whose cone fits a face only just) is found wherever it is at least that wide.
/// Ascending, from -pi / samples; empty when no spin is admissible. best: when given, the
/// spin of the largest local margin evaluated and that margin (-inf when the bound ruled out
/// every arc), admissible or not.
std::vector<double> admissible_spins(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                                     const Vec3& axis, const Mat3& R0, int samples,
                                     double min_local, std::pair<double, double>* best = nullptr);

}  // namespace cf::gen::internal

#pragma once
/// @file
/// Two e-e PCs at mirror corners (docs/generator.md, "Two e-e PCs at mirror corners"): A's two
/// edges leave a convex corner v on one face, B's two leave a saddle corner w on one face, the
/// corners' angles are equal and their handedness opposite, and no edge's normal cone is wider
/// than pi/2, each to within a tolerance that shrinks with the slack. Then no pose realises the
/// two contacts at once with the verifier's local slack, whatever the rest of the models. A
/// certificate (docs/certificates.md, "Rules", `mirror-corners`).

#include <cf/pc.hpp>
#include <cf/polyhedron.hpp>

namespace cf::gen {

/// True when the theorem proves that no pose realises PCs p and q of A against B together with
/// each one's local margin (crossing sine and normal-cone terms, Verifier::local_margin) at least
/// `slack` (a sine, > 0): both are e-e and the six conditions of docs/certificates.md
/// (`mirror-corners`) hold by more than their rounding, on the models' unit edge directions and
/// face normals.
bool mirror_corners(const Polyhedron& A, const Polyhedron& B, const Pc& p, const Pc& q,
                    double slack);

}  // namespace cf::gen

#pragma once
/// @file
/// Two e-e PCs at mirror corners (docs/generator.md, "Two e-e PCs at mirror corners"): A's two
/// edges leave a convex corner v on one face, B's two leave a saddle corner w on one face, the
/// corners' angles are equal, their handedness opposite and no dihedral angle of the four edges
/// below 90 degrees. Then no pose realises the two contacts at once, whatever the rest of the
/// models. The conditions are decided exactly on the models' coordinates, so the rule is a
/// certificate (docs/certificates.md, "Rules", `mirror-corners`).

#include <cf/pc.hpp>
#include <cf/polyhedron.hpp>

namespace cf::gen {

/// True when the theorem proves that no pose realises PCs p and q of A against B together:
/// both are e-e and the six conditions of docs/certificates.md (`mirror-corners`) hold, each
/// decided in exact rational arithmetic on the vertex coordinates (faces that are not exactly
/// planar, or any condition that fails or only nearly holds, give false). A floating-point
/// screen rejects most pairs before any exact arithmetic.
bool mirror_corners(const Polyhedron& A, const Polyhedron& B, const Pc& p, const Pc& q);

}  // namespace cf::gen

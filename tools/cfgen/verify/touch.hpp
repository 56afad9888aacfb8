#pragma once
// Open-set touching (docs/spec.md, section 4): faces without their boundary, edges without their
// end points. Two closed elements at distance zero may meet only on their boundaries; those pairs
// do not touch, their boundary elements do.

#include <cf/geometry.hpp>
#include <cf/polyhedron.hpp>

#include <optional>

namespace cf::gen {

/// Element `a` of A (posed) and element `b` of B, known to be within `tol` as closed sets:
/// do their open sets share a point (within tol)?
bool open_touch(const Polyhedron& A, const Pose& pose, ElementKind ka, int a, const Polyhedron& B,
                ElementKind kb, int b, double tol);

/// Centroid (B's frame) of the largest piece of the overlap of A's face a, posed, with B's
/// face b, the two lying in one plane; nullopt when they do not overlap.
std::optional<Vec3> face_overlap_centroid(const Polyhedron& A, const Pose& pose, int a,
                                          const Polyhedron& B, int b);

}  // namespace cf::gen

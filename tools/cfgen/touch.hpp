#pragma once
// Open-set touching (SPEC section 4): faces without their boundary, edges without their end
// points. Two closed elements at distance zero may meet only on their boundaries; those pairs
// do not touch, their boundary elements do.

#include <cf/geometry.hpp>
#include <cf/polyhedron.hpp>

namespace cf::gen {

/// Element `a` of A (posed) and element `b` of B, known to be within `tol` as closed sets:
/// do their open sets share a point (within tol)?
bool open_touch(const Polyhedron& A, const Pose& pose, ElementKind ka, int a, const Polyhedron& B,
                ElementKind kb, int b, double tol);

}  // namespace cf::gen

#pragma once
// Independent test oracle: rigid motions of A and their first contact with B.
//
// Translation: the time of impact is exact, the minimum over vertex(A)-face(B),
// face(A)-vertex(B) and edge-edge events, each a linear equation.
// Rotation about a fixed axis: vertex-face and face-vertex events solve
// a cos(theta) + b sin(theta) = c in closed form; edge-edge events (the two lines become
// coplanar, a trigonometric polynomial of degree 2) are found by sampling and bisection to
// ~1e-15 rad. Events already holding at the start (contacts the motion keeps) are skipped:
// their function is identically zero, or their root is at the start and the motion leaves.
//
// A missed event is never a false result: every pose the sampler reaches is verified by the
// Classifier before it counts.

#include "classify.hpp"

namespace oracle {

struct Motion {
  bool rotation = false;
  Vec3 u = Vec3::UnitX();  // translation direction (unit)
  Vec3 c = Vec3::Zero();   // rotation axis point (world)
  Vec3 w = Vec3::UnitZ();  // rotation axis direction (unit)
};

/// The pose after moving A from X0 by lambda (mm or rad) along M.
Pose apply_motion(const Pose& X0, const Motion& M, double lambda);

/// First contact parameter in (lam_min, lam_max]; kInf when nothing is met; 0 when the motion
/// at once pushes a vertex that touches a face (within tol) into it. tol: how far outside an
/// element an event point may lie and still count.
double time_of_impact(const Poly& A, const Poly& B, const Pose& X0, const Motion& M, double lam_max,
                      double tol);

}  // namespace oracle

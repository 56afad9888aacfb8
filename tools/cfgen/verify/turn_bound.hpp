#pragma once
/// @file
/// A bound on how far a set of rotations turns A's vectors (docs/generator.md, "Refuting a
/// set over cells of poses").

#include <cf/types.hpp>

namespace cf::gen {

/// How far the rotations of a set turn a vector x of A's frame from where the set's central
/// rotation R_c takes it: at most any |x| + about |x x axis|. A cube of rotation space turns
/// every vector alike (any = turn_bound(cell)); rotations R_c Rot(axis, d), |d| <= h, turn
/// a vector by at most h times its distance from the axis (about = h), and leave the axis
/// where it is.
struct TurnBound {
  double any = 0;            // per unit length
  double about = 0;          // per unit distance from the axis
  Vec3 axis = Vec3::Zero();  // unit, A's frame
  double of(const Vec3& x) const {
    // Nothing turned (the verifier's own margin, on every pose it checks): no norms.
    if (any == 0 && about == 0) return 0;
    return any * x.norm() + about * x.cross(axis).norm();
  }
  double unit() const { return any + about; }  // the most a unit vector moves
};

}  // namespace cf::gen

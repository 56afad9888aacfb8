#pragma once
/// @file
/// Cells of rotation space for the decision's branch and bound (docs/generator.md, "Deciding
/// a set"): cubes in axis-angle coordinates r (rotation by |r| rad about r / |r|). Every
/// rotation has coordinates in the ball |r| <= pi, so cells covering that ball cover SO(3).

#include "cfgen/verify/turn_bound.hpp"

#include <cf/types.hpp>

#include <array>

namespace cf::gen {

/// The cube of axis-angle vectors within `half` (rad, each coordinate) of `centre`.
struct RotationCell {
  Vec3 centre = Vec3::Zero();  // rad
  double half = 0;             // rad
};

/// The cell of half-width pi about the identity: it holds the whole ball |r| <= pi.
RotationCell whole_rotation_space();

/// The rotation with axis-angle coordinates r (Rodrigues' formula).
Mat3 rotation_at(const Vec3& r);

/// A bound on how far any rotation of the cell moves a vector from where the rotation at the
/// centre takes it, per unit of its length: |R x - R_c x| <= turn_bound(cell) |x| for every R
/// of the cell. The angle between R and R_c is at most the distance of their coordinates
/// (Hartley and Kahl 2009, "Global optimization through rotation space search", lemma 1),
/// at most sqrt(3) half, and a turn by angle a moves a unit vector by 2 sin(a / 2) <= a.
double turn_bound(const RotationCell& cell);

/// True when no point of the cell lies in the ball |r| <= pi: its rotations are all
/// rotations of other cells too.
bool outside_rotation_ball(const RotationCell& cell);

/// The eight cells of half the width that tile the cell, in a fixed order.
std::array<RotationCell, 8> split(const RotationCell& cell);

}  // namespace cf::gen

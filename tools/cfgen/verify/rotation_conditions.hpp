#pragma once
/// @file
/// The rotational conditions of a set of PCs: a face-face PC aligns A's face normal against
/// B's, an edge-face or face-edge PC keeps the edge parallel to the face.

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <utility>
#include <vector>

namespace cf::gen {

struct RotConstraints {
  std::vector<std::pair<Vec3, Vec3>> align;  // R a == b
  std::vector<std::pair<Vec3, Vec3>> perp;   // (R u) . w == 0
};

constexpr double kRotTol = 1e-9;  // residual accepted for rotational contact conditions
/// The residual a witness's rotation may leave in each condition: |R a - b| for an alignment,
/// |(R u) . w| for a perpendicularity (satisfies()); refutations allow it too.
constexpr double kRotAccepted = 10 * kRotTol;

/// Whether R meets every condition of `c` to kRotAccepted.
inline bool satisfies(const RotConstraints& c, const Mat3& R) {
  for (const auto& [a, b] : c.align)
    if ((R * a - b).norm() > kRotAccepted) return false;
  for (const auto& [u, w] : c.perp)
    if (std::abs((R * u).dot(w)) > kRotAccepted) return false;
  return true;
}

/// The conditions the PCs of `pcs` put on A's rotation R_BA.
RotConstraints rotation_constraints(const PcSet& pcs, const Polyhedron& A, const Polyhedron& B);

}  // namespace cf::gen

#pragma once
/// @file
/// The rotational conditions of a set of PCs: a face-face PC aligns A's face normal against
/// B's, an edge-face or face-edge PC keeps the edge parallel to the face. Each holds to a
/// tolerance: kRotAccepted on exact models, more on models that hold their files' geometry
/// only to a precision (docs/generator.md, "Rotational conditions").

#include "cfgen/verify/analysis.hpp"

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <cstddef>
#include <utility>
#include <vector>

namespace cf::gen {

constexpr double kRotTol = 1e-9;  // residual accepted for rotational contact conditions
/// The residual a witness's rotation may leave in each condition of exact models: |R a - b|
/// for an alignment, |(R u) . w| for a perpendicularity (satisfies()); refutations allow it
/// too.
constexpr double kRotAccepted = 10 * kRotTol;
/// On models that hold their geometry to precisions p_A and p_B (ModelInfo::precision_mm), a
/// condition between elements of extents l_a and l_b (an edge's length, a face's width)
/// holds to kRotPerPrecision (p_A / l_a + p_B / l_b): each element's direction is known to
/// about 2 p / l, and at that tilt an element moves its ends by about the touch tolerance,
/// 4 (p_A + p_B) (tools/cfgen/generate.hpp, kTouchPerPrecision).
constexpr double kRotPerPrecision = 4;

struct RotConstraints {
  std::vector<std::pair<Vec3, Vec3>> align;  // R a == b
  std::vector<std::pair<Vec3, Vec3>> perp;   // (R u) . w == 0
  /// rad: the residual each condition may leave (condition_tol); kRotAccepted where a
  /// condition has none (conditions built by hand).
  std::vector<double> align_tol, perp_tol;

  double align_tol_of(std::size_t i) const {
    return i < align_tol.size() ? align_tol[i] : kRotAccepted;
  }
  double perp_tol_of(std::size_t i) const {
    return i < perp_tol.size() ? perp_tol[i] : kRotAccepted;
  }
  /// The largest tolerance of a condition (kRotAccepted for none).
  double max_tol() const;
};

/// Whether R meets every condition of `c` to its tolerance.
inline bool satisfies(const RotConstraints& c, const Mat3& R) {
  for (std::size_t i = 0; i < c.align.size(); ++i)
    if ((R * c.align[i].first - c.align[i].second).norm() > c.align_tol_of(i)) return false;
  for (std::size_t i = 0; i < c.perp.size(); ++i)
    if (std::abs((R * c.perp[i].first).dot(c.perp[i].second)) > c.perp_tol_of(i)) return false;
  return true;
}

/// rad: the tolerance of a rotational condition between element (ka, ia) of `a` and (kb, ib)
/// of `b` (kRotPerPrecision above), at least kRotAccepted.
double condition_tol(const ModelInfo& a, ElementKind ka, int ia, const ModelInfo& b, ElementKind kb,
                     int ib);

/// rad: the largest condition_tol of any pair of elements of `a` and `b`.
double max_condition_tol(const ModelInfo& a, const ModelInfo& b);

/// Sine to which two directions of the models count as parallel, or a direction as in a
/// plane: 1e-9 (rounding) on exact models, what max_condition_tol leaves over kRotAccepted on
/// models known to a precision (two faces at a right angle in the design are at one to
/// 1e-7 rad in a float32 file).
double direction_tol(const ModelInfo& a, const ModelInfo& b);

/// mm: how far a line or plane PC's element of A may lie off the other element's line or
/// plane, beyond touching, when its condition leaves what the models' precision allows over
/// kRotAccepted: that excess times the element's extent (an f-f's face of A across, an e-f's
/// or f-e's edge). 0 for a point PC and on exact models, whose witnesses meet their
/// conditions to rounding.
double tilt_allowance(const ModelInfo& a, const ModelInfo& b, const Pc& pc);

/// The conditions the PCs of `pcs` put on A's rotation R_BA, each with its condition_tol.
RotConstraints rotation_constraints(const PcSet& pcs, const ModelInfo& a, const ModelInfo& b);

}  // namespace cf::gen

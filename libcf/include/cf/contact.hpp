#pragma once
/// @file
/// Contacts detected at a pose: the candidate principal contacts of SPEC section 6, each
/// with its distance, point of action and task frame.

#include <cf/graph.hpp>
#include <cf/types.hpp>

namespace cf {

/// Geometric category of a PC (paper section 2).
enum class PcExtent : std::uint8_t { kPoint, kLine, kPlane };
PcExtent extent(PcType type);

/// One contact between an element of A and an element of B at the current pose.
struct ContactPc {
  Pc pc;
  /// mm, signed distance along the task frame's y axis: > 0 apart, < 0 interpenetrating.
  /// Paper eq. (1) uses it as d_j.
  double distance = 0;
  /// mm, world frame: the contact point (point PC) or the centroid of the contact region
  /// (line and plane PCs), taken on A.
  Vec3 p_W = Vec3::Zero();
  /// Task frame in the world: columns are its x, y, z axes; y is the contact-plane normal
  /// pointing into A; origin on the contact plane at the contact point or region centroid.
  Mat3 R_WT = Mat3::Identity();
  Vec3 origin_W = Vec3::Zero();  ///< mm, world frame
  /// Non-negative residual of the type's geometric conditions (angle misfit in rad for
  /// parallel types, plus distance / epsilon): smaller fits better. Used to rank
  /// interpretations.
  double misfit = 0;
};

}  // namespace cf

#pragma once
/// @file
/// Parameters of the haptic force model (SPEC section 2 and section 6, paper section 4).
/// Defaults are the paper's values; every choice the paper leaves open is a named option
/// here and described in docs/force-model.md.

#include <cf/types.hpp>

#include <cstdint>

namespace cf {

/// How s_pj of eqs. (3)-(4) is measured (SPEC section 6).
enum class FrictionDisplacement : std::uint8_t {
  /// Tangential displacement of p_j since the PC last entered sticking (a stick anchor).
  /// Independent of the servo rate. When eq. (3) fails the anchor is dragged along so that
  /// it trails p_j at the eq. (3) bound.
  kStickAnchor,
  /// The paper's literal reading: the tangential displacement of p_j over one servo tick.
  kPerTick,
};

/// Where the mass centre of A is taken (paper section 3.1 uses the vertex mean).
enum class CentroidChoice : std::uint8_t { kVertexMean, kVolume };

/// About which point the haptic moment is reported (paper section 5 uses A's frame origin).
enum class MomentReference : std::uint8_t {
  kAOrigin,    ///< A's frame origin (paper eq. (9))
  kACentroid,  ///< A's mass centre (Params::centroid)
  kAPoint,     ///< Params::moment_point_A, a point fixed in A (e.g. where the device holds it)
};

/// All parameters of contact detection thresholds, friction, gravity and smoothing.
struct Params {
  // --- Paper's experimental values (paper section 6, SPEC section 2) ---
  double mass_kg = 0.5;             ///< m, mass of A
  double gravity_N_per_kg = 9.8;    ///< g, acting along -y of the world
  double stiffness_N_per_mm = 2.3;  ///< K of eq. (1)
  double kp_N_per_mm = 1.6;         ///< K_p of eqs. (3)-(4)
  double mu_static = 0.7;           ///< mu of eqs. (2), (3), (6)
  double mu_kinetic = 0.08;         ///< mu_D of eq. (5) (SPEC reading)
  double epsilon_mm = 1.0;          ///< contact threshold of eq. (1)

  // --- Friction ---
  FrictionDisplacement friction_displacement = FrictionDisplacement::kStickAnchor;

  // --- Mass centre and moment ---
  CentroidChoice centroid = CentroidChoice::kVertexMean;
  MomentReference moment_reference = MomentReference::kAOrigin;
  Vec3 moment_point_A = Vec3::Zero();  ///< mm, A's frame; the reference with kAPoint

  // --- Freedoms and the "approximately along" test of paper Fig. 10 ---
  /// Relative singular-value tolerance for the null space of the contact constraints: a
  /// direction is free when its constraint singular value is below this fraction of the
  /// largest (constraint rows are unit normals and moment arms divided by the model size).
  double freedom_rank_tolerance = 1e-6;
  /// rad. A pose change is "approximately along" the freedoms when the angle between its
  /// twist (translation of A's origin, rotation vector times the model size) and the space
  /// of freedoms is at most this; the same angle bounds the rotation axis alone.
  double motion_angle_tolerance_rad = 0.35;  // 20 degrees
  /// mm. Pose changes whose largest point displacement over A is below this count as no
  /// motion at all (they pass the "along" test trivially).
  double motion_noise_mm = 1e-9;

  // --- Contacts approaching in a plane the CF leaves apart ---
  /// Identification gains a contact of a new plane when it touches (within
  /// IdentificationParams::touch_distance), not when it comes within epsilon; true renders
  /// such approaching contacts with eq. (1) meanwhile (normal force only), so that the force
  /// rises from 0 at epsilon as eq. (1) intends instead of stepping by up to K epsilon at the
  /// gain. false: only the CF's PCs push (docs/force-model.md).
  bool render_approaching = true;

  // --- Smoothing (paper section 4.5). Both off by default so that eq. (1) holds exactly. ---
  /// N. When > 0 and the prior motion is compliant (MT2..MT5), a PC keeps its previous F_cy
  /// while the new eq. (1) value differs from the held one by less than this (a deadband
  /// against the held value, so slow drifts still update: rate independent).
  double hold_fcy_threshold_N = 0.0;
  /// s. When > 0 the total contact force and moment are low-pass filtered across ticks with
  /// this time constant: factor = 1 - exp(-dt / tau), so the filter is rate independent.
  double interpolation_time_constant_s = 0.0;
};

}  // namespace cf

#pragma once
/// @file
/// The proxy of section 6b of docs/spec.md: a 6-DOF god-object pose X_WP of A that moves towards
/// the device pose X_WD each tick as far as B allows, never penetrating B by more than
/// ProxyParams::penetration_tolerance_mm, and the spring-damper coupling between the two that the
/// operator feels. docs/force-model.md ("The proxy") gives the model and its defaults.

#include <cf/contact.hpp>
#include <cf/types.hpp>

#include <array>

namespace cf {

/// One hard constraint of the last proxy solve: a point contact of the proxy with B.
struct ProxyContact {
  Pc pc;                           ///< a v-f, f-v or e-e contact detected at the proxy pose
  Vec3 p_W = Vec3::Zero();         ///< mm, contact point on A
  Vec3 n_W = Vec3::UnitY();        ///< unit normal into A
  double distance_mm = 0;          ///< at the pose of the last linearisation
  double normal_load_N = 0;        ///< the constraint's multiplier: B pushing the proxy out
  Vec3 friction_W = Vec3::Zero();  ///< N, tangential constraint force on the proxy
  bool sliding = false;            ///< friction at its kinetic bound this tick
};

/// What the proxy step did this tick.
struct ProxyResult {
  static constexpr int kMaxContacts = 64;
  Pose X_WD;  ///< the device pose given
  Pose X_WP;  ///< the proxy pose: where A is rendered (identification, PCs, forces)
  /// Some constraint held the proxy back this tick (otherwise X_WP equals X_WD exactly).
  bool constrained = false;
  int substeps = 0;    ///< sub-steps of the swept motion
  int iterations = 0;  ///< solver sweeps, over all sub-steps
  /// The hard constraints at the final sub-step: its point contacts, or the kMaxContacts
  /// nearest when it had more.
  std::array<ProxyContact, kMaxContacts> contacts{};
  int num_contacts = 0;
  /// Point contacts of the final sub-step left out of its solve (the farthest ones, beyond
  /// kMaxContacts); a pass moves no point of A by more than 0.75 epsilon, so only those
  /// nearer than that could be crossed.
  int dropped_contacts = 0;
  /// N and N mm about A's grip point at X_WD, world axes: the coupling's wrench on the
  /// operator's hand, k (X_WP - X_WD) + b (velocity difference).
  Vec3 F_coupling_W = Vec3::Zero();
  Vec3 M_coupling_W = Vec3::Zero();
  /// N and N mm about the grip point at X_WP, world axes: what B exerts on the proxy
  /// through the hard constraints (normal loads and friction). At rest it balances the
  /// coupling.
  Vec3 F_constraint_W = Vec3::Zero();
  Vec3 M_constraint_W = Vec3::Zero();
};

}  // namespace cf

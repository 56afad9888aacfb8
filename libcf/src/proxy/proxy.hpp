#pragma once
// The proxy stage (docs/spec.md, section 6b): its model part (A's metric about the grip point, the
// swept motion's reach) and its per-thread state, and the step itself. servo.cpp calls it.

#include <cf/contact.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>
#include <cf/proxy.hpp>

#include "../detect/detect.hpp"

#include <array>

namespace cf::internal {

struct ProxyModel {
  /// @throws cf::Error naming a proxy parameter out of range.
  ProxyModel(const Polyhedron& a, const Polyhedron& b, const Params& params);
  ProxyParams prm;
  // Detection through the lookahead band (ProxyParams::lookahead_epsilons), null when off.
  // A superset of the stages' point contacts: the band and its in-plane tolerance widened,
  // the angular tolerance not (a wider one would read crossing edges as parallel ones).
  DetectModelPtr look;
  double epsilon_mm = 1;
  double mu_static = 0.7, mu_kinetic = 0.08;
  Mat3 J_A = Mat3::Identity();     // mm^2, A's inertia per unit mass about the grip point, A's axes
  Mat3 Jinv_A = Mat3::Identity();  // 1/mm^2
  double reach_mm = 0;             // largest distance of A's vertices from the grip point
};

struct ProxyState {
  bool has_prev = false;
  Pose X_WP;                  // the proxy now (after the last step)
  Pose X_WD_prev, X_WP_prev;  // for the coupling's velocities
  double t_prev_s = 0;
  // The contacts that slid at the end of the last tick (kinetic friction this tick).
  std::array<Pc, ProxyResult::kMaxContacts> sliding{};
  int num_sliding = 0;
  // The last solve's constraint forces (N: normal, then along the task frame's x and z),
  // by contact: the next solve starts from them (warm start).
  std::array<Pc, ProxyResult::kMaxContacts> warm_pc{};
  std::array<std::array<double, 3>, ProxyResult::kMaxContacts> warm_lambda{};
  int num_warm = 0;
  ProxyResult result;
  DetectStatePtr look;  // for ProxyModel::look
  ContactSet look_contacts;
};

/// A state for `pm` (its lookahead detection's state sized).
void init_proxy_state(const ProxyModel& pm, ProxyState& s);

/// Advances the proxy towards the device pose X_WD (docs/spec.md, section 6b) and fills s.result
/// (coupling included): the stage behind cf::move_proxy. Detects with `ds` into `at` (the stages'
/// own contact set), so that the stages at the final proxy pose find its contacts there. No heap
/// allocation.
void advance_proxy(const ProxyModel& pm, const DetectModel& dm, DetectState& ds, DetectedAt& at,
                   ProxyState& s, const Pose& X_WD, double t_s);

}  // namespace cf::internal

#pragma once
/// @file
/// One servo tick of section 6 of docs/spec.md as stages, each a free function of the immutable
/// CfModel, the thread's CfState and the previous stage's result (after FCL's
/// request/result structs and Box2D's free functions):
///
///     const Pose X_WA = cf::move_proxy(model, state, X_WD, t_s).X_WP;  // docs/spec.md, section 6b
///     const ContactSet& contacts = cf::detect(model, state, X_WA);
///     const Identification& id   = cf::identify(model, state, contacts);
///     const PriorMotion motion   = cf::classify_motion(model, state, id);
///     const HapticResult& out    = cf::compute_force(model, state, X_WA, t_s, id, motion);
///
/// or all at once, with the coupling added, by cf::step(model, state, X_WD, t_s). None
/// allocates. An
/// application may replace a stage (fill an Identification itself, say) and call the next.
/// Every function throws cf::Error when `state` was made for another model.

#include <cf/contact.hpp>
#include <cf/force.hpp>
#include <cf/identifier.hpp>
#include <cf/model.hpp>
#include <cf/motion.hpp>
#include <cf/proxy.hpp>
#include <cf/state.hpp>
#include <cf/types.hpp>

#include <array>
#include <cstdint>

namespace cf {

/// How the tick was rendered.
enum class RenderStatus : std::uint8_t {
  kNoContact,           ///< A touches nothing: gravity only
  kOk,                  ///< a CF of the graph, reached by a listed transition (or kept)
  kNoFittingCf,         ///< contacts but no CF of the graph fits: conservative laws
  kUnlistedTransition,  ///< the CF is in the graph but the graph has no transition from the
                        ///< previous one (fast motion): conservative laws
};
/// "no_contact", "ok", "no_fitting_cf", "unlisted_transition".
const char* to_string(RenderStatus status);

/// Everything one servo tick produces.
struct HapticResult {
  double t_s = 0;
  CfId cf;    ///< invalid (-1) when none
  PcSet pcs;  ///< the rendered CF's PCs (empty when none)
  MotionType motion = MotionType::kNone;
  RenderStatus status = RenderStatus::kNoContact;
  /// The identification's own status word (cf::to_string(IdStatus)), for diagnostics.
  const char* identification = "";
  int num_detected = 0;  ///< candidate PCs the detector found
  /// N, the rendered force, world axes: F_c + F_g at X_WP, plus the coupling with the proxy
  /// on (docs/force-model.md "The proxy").
  Vec3 F_W = Vec3::Zero();
  Vec3 M_W = Vec3::Zero();  ///< N mm, the rendered moment about the reference point, world axes
  Vec3 F_A = Vec3::Zero();  ///< N, F_W in A's axes (at X_WP)
  Vec3 M_A = Vec3::Zero();  ///< N mm, M_W in A's axes (paper eq. (9))
  Pose X_WD;                ///< the device pose given to the tick
  Pose X_WP;                ///< where A was rendered: the proxy pose (X_WD with the proxy off)
  /// N and N mm about the reference point, world axes: what B exerts on A, eqs. (1)-(8)
  /// at X_WP plus the proxy's constraint forces. At rest it balances the coupling.
  Vec3 F_contact_W = Vec3::Zero();
  Vec3 M_contact_W = Vec3::Zero();
  /// N, per rendered PC (in the order of force->pcs): the normal load the proxy's hard
  /// constraints add to F_cy there (the multipliers of its point contacts: its corners). So
  /// PC j's load is force->pcs[j].F_cy + constraint_load_N[j]. Zeros with the proxy off.
  std::array<double, ForceResult::kMaxPcs> constraint_load_N{};
  /// The proxy step (poses, constraints, coupling); null with the proxy off. Points into
  /// the state; valid until its next step.
  const ProxyResult* proxy = nullptr;
  /// Per-PC diagnostics (type, task frame, distance, s_pj, regime, force), the freedoms and
  /// the contact/gravity split. Points into the state; valid until its next compute_force.
  const ForceResult* force = nullptr;
};

/// Stage 0 (with ProxyParams::enabled): moves the proxy towards the device pose X_WD (mm,
/// B's frame) as far as B allows (docs/spec.md, section 6b) and computes the coupling. The stages
/// below then run at the proxy pose. The result lives in `state` until the next move_proxy.
const ProxyResult& move_proxy(const CfModel& model, CfState& state, const Pose& X_WD, double t_s);

/// Stage 1: the candidate PCs at the pose X_WA of A (mm, in B's frame, which is the world),
/// in canonical PC order with `dominated` and `plane` set (docs/runtime.md). The result
/// lives in `state` until the next detect.
const ContactSet& detect(const CfModel& model, CfState& state, const Pose& X_WA);

/// Stage 2: the CF among the interpretations of `contacts` (detect's result, or a set the
/// application made in the same form), preferring the state's previous CF, then a graph
/// neighbour of it, then the best fit. Does not change the previous CF. The result lives in
/// `state` until the next identify.
const Identification& identify(const CfModel& model, CfState& state, const ContactSet& contacts);

/// Stage 3: the prior motion (paper section 4.2) from the state's previous CF to `id`'s CF,
/// looked up in the graph; `transition_in_graph` is false when the graph lists no such
/// transition. Then `id`'s CF becomes the previous CF (none after a tick without contacts;
/// unchanged when the contacts fit no CF). The MT2 case (a, b or c) is left to compute_force,
/// which needs this tick's loads for eq. (3).
PriorMotion classify_motion(const CfModel& model, CfState& state, const Identification& id);

/// Stage 4: the haptic force and moment at time t_s (s, increasing across calls) and pose
/// X_WA: eqs. (1)-(9) on `id`'s CF with `motion`'s rules, or the conservative laws on every
/// contact when no CF or no listed transition fits (docs/force-model.md).
const HapticResult& compute_force(const CfModel& model, CfState& state, const Pose& X_WA,
                                  double t_s, const Identification& id, const PriorMotion& motion);

/// One servo tick at the device pose X_WD: with the proxy on (the default), move_proxy,
/// then the four stages at the proxy pose, and the coupling added to the rendered wrench;
/// with it off, the four stages at X_WD (the paper's literal model).
const HapticResult& step(const CfModel& model, CfState& state, const Pose& X_WD, double t_s);

}  // namespace cf

#pragma once
/// @file
/// One servo tick of SPEC section 6 as four stages, each a free function of the immutable
/// CfModel, the thread's CfState and the previous stage's result (after FCL's
/// request/result structs and Box2D's free functions):
///
///     const ContactSet& contacts = cf::detect(model, state, X_WA);
///     const Identification& id   = cf::identify(model, state, contacts);
///     const PriorMotion motion   = cf::classify_motion(model, state, id);
///     const HapticResult& out    = cf::compute_force(model, state, X_WA, t_s, id, motion);
///
/// or all four at once with cf::step(model, state, X_WA, t_s). None allocates. An
/// application may replace a stage (fill an Identification itself, say) and call the next.
/// Every function throws cf::Error when `state` was made for another model.

#include <cf/contact.hpp>
#include <cf/force.hpp>
#include <cf/identifier.hpp>
#include <cf/model.hpp>
#include <cf/motion.hpp>
#include <cf/state.hpp>
#include <cf/types.hpp>

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
  int num_detected = 0;     ///< candidate PCs the detector found
  Vec3 F_W = Vec3::Zero();  ///< N, haptic force F_c + F_g, world axes
  Vec3 M_W = Vec3::Zero();  ///< N mm, haptic moment about the reference point, world axes
  Vec3 F_A = Vec3::Zero();  ///< N, in A's axes
  Vec3 M_A = Vec3::Zero();  ///< N mm, in A's axes (paper eq. (9))
  /// Per-PC diagnostics (type, task frame, distance, s_pj, regime, force), the freedoms and
  /// the contact/gravity split. Points into the state; valid until its next compute_force.
  const ForceResult* force = nullptr;
};

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

/// The four stages in order: one servo tick.
const HapticResult& step(const CfModel& model, CfState& state, const Pose& X_WA, double t_s);

}  // namespace cf

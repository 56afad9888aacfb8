#pragma once
/// @file
/// The run-time servo loop of SPEC section 6 in one call: detect and identify the CF at the
/// pose of A, classify the prior motion, compute the haptic force and moment. Created once
/// per graph; step() allocates nothing.

#include <cf/contact.hpp>
#include <cf/force.hpp>
#include <cf/graph.hpp>
#include <cf/identifier.hpp>
#include <cf/motion.hpp>
#include <cf/params.hpp>

#include <cstdint>
#include <memory>

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
  CfId cf;                                 ///< invalid (-1) when none
  PcSet pcs;                               ///< the rendered CF's PCs (empty when none)
  MotionType motion = MotionType::kNone;
  RenderStatus status = RenderStatus::kNoContact;
  /// The identification's own status word (CfIdentifier), for diagnostics.
  const char* identification = "";
  int num_detected = 0;                    ///< candidate PCs the detector found
  Vec3 F_W = Vec3::Zero();  ///< N, haptic force F_c + F_g, world axes
  Vec3 M_W = Vec3::Zero();  ///< N mm, haptic moment about the reference point, world axes
  Vec3 F_A = Vec3::Zero();  ///< N, in A's axes
  Vec3 M_A = Vec3::Zero();  ///< N mm, in A's axes (paper eq. (9))
  /// Per-PC diagnostics (type, task frame, distance, s_pj, regime, force), the freedoms and
  /// the contact/gravity split. Points into the renderer; valid until the next step().
  const ForceResult* force = nullptr;
};

/// The haptic renderer of one model pair. Not thread-safe: one per servo thread.
class HapticRenderer {
 public:
  /// @param graph  must outlive the renderer.
  explicit HapticRenderer(const CfGraph& graph, const Params& params = Params());
  ~HapticRenderer();
  HapticRenderer(HapticRenderer&&) noexcept;
  HapticRenderer& operator=(HapticRenderer&&) noexcept;

  /// One servo tick at time t_s (s, increasing) and pose of A. No heap allocation.
  const HapticResult& step(const Pose& pose, double t_s);

  /// The same after identification: renders a CfIdentifier's result (what step() does
  /// after identifying), or one an application filled itself. It reads `cf` (invalid when
  /// none fits), `cf_pcs`/`num_cf_pcs` (the CF's PCs), `contacts` (every candidate, for the
  /// conservative rendering when no CF fits), `approaching`/`num_approaching` (contacts
  /// within epsilon in planes the CF leaves apart; eq. (1) only) and `status`.
  const HapticResult& step_identified(const Pose& pose, double t_s, const Identification& id);

  /// Forgets the history (previous CF, anchors, filters).
  void reset();

  const HapticResult& result() const;
  const CfGraph& graph() const;
  const Params& params() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf

#pragma once
/// @file
/// The run-time servo loop of section 6 of docs/spec.md as one object: a CfModel (its own, or one
/// shared with other threads) and this thread's CfState, stepped by cf::step (cf/servo.hpp).
/// step() allocates nothing.

#include <cf/graph.hpp>
#include <cf/model.hpp>
#include <cf/params.hpp>
#include <cf/servo.hpp>
#include <cf/state.hpp>

#include <cstdint>
#include <memory>

namespace cf {

/// The haptic renderer of one model pair. Not thread-safe: one per servo thread.
class HapticRenderer {
 public:
  /// Builds its own CfModel of the graph.
  /// @param graph  must outlive the renderer.
  /// @throws cf::Error when a parameter is out of range (validate(), cf/params.hpp).
  explicit HapticRenderer(const CfGraph& graph, const Params& params = Params());
  /// Steps a model shared with other renderers (one per thread).
  /// @param model  must outlive the renderer.
  explicit HapticRenderer(const CfModel& model);
  ~HapticRenderer();
  HapticRenderer(HapticRenderer&&) noexcept;
  HapticRenderer& operator=(HapticRenderer&&) noexcept;

  /// One servo tick at time t_s (s, increasing) and pose of A: cf::step. No heap
  /// allocation.
  const HapticResult& step(const Pose& pose, double t_s);

  /// The same after identification (cf::classify_motion and cf::compute_force): renders a
  /// CfIdentifier's result (what step() does after identifying), or one an application
  /// filled itself. It reads `cf` (invalid when
  /// none fits), `cf_pcs`/`num_cf_pcs` (the CF's PCs), `contacts` (every candidate, for the
  /// conservative rendering when no CF fits), `approaching`/`num_approaching` (contacts
  /// within epsilon in planes the CF leaves apart; eq. (1) only) and `status`.
  const HapticResult& step_identified(const Pose& pose, double t_s, const Identification& id);

  /// Forgets the history (previous CF, anchors, filters).
  void reset();

  const HapticResult& result() const;
  const CfGraph& graph() const;
  const Params& params() const;
  const CfModel& model() const;
  const CfState& state() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf

#pragma once
/// @file
/// The per-thread half of the run time (after MuJoCo's `mjData`): everything one servo
/// thread writes while it steps a CfModel. Its capacity is fixed when it is made, so the
/// stages of cf/servo.hpp allocate nothing.

#include <cf/contact.hpp>
#include <cf/identifier.hpp>
#include <cf/model.hpp>
#include <cf/types.hpp>

#include <memory>

namespace cf {

struct HapticResult;  // cf/servo.hpp

/// One servo thread's state for one CfModel: detection's posing caches and the pairs kept
/// for the next tick with their certificates, identification's scratch, the CF of the
/// previous tick, the force model's stick anchors, held loads and filters, and the last
/// results. Not thread-safe: one per thread.
class CfState {
 public:
  /// A state sized for `model`, to be used with it only (the stages check this). The model
  /// must outlive the state.
  explicit CfState(const CfModel& model);
  ~CfState();
  CfState(CfState&&) noexcept;
  CfState& operator=(CfState&&) noexcept;
  CfState(const CfState&) = delete;
  CfState& operator=(const CfState&) = delete;

  /// Forgets the history: the previous CF, stick anchors, held loads, filters, kept pairs
  /// stay valid (they are certified per pose).
  void reset();

  /// The CF the next identification prefers (the last identified CF; kept across ticks
  /// whose contacts fit no CF; none after a tick without contact).
  CfId previous() const;
  /// The candidate PCs of the last detect().
  const ContactSet& contacts() const;
  /// The last identify() (its `contacts` are the ones it read).
  const Identification& identification() const;
  /// The last compute_force() or step().
  const HapticResult& result() const;
  /// Element pairs tested by the last detect() (ContactDetector::last_pairs_tested).
  std::size_t last_pairs_tested() const;
  /// Whether the last detect() served the pairs kept at an earlier pose.
  bool last_reused_pairs() const;

  struct Impl;

 private:
  friend struct internal::Access;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf

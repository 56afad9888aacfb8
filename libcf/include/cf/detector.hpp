#pragma once
/// @file
/// Candidate principal contacts at a pose (docs/spec.md, section 6; paper section 4.1): every pair
/// of an element of A and an element of B that is within the contact threshold and whose
/// type is consistent within tolerances. Built once per model pair; `detect` allocates
/// nothing. docs/runtime.md describes every test and tolerance.

#include <cf/contact.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <memory>

namespace cf {

/// Finds the candidate PCs between A (moving) and B (fixed) at a pose. Immutable after
/// construction except for per-call scratch space and the pairs kept for the next call
/// (DetectionParams::reuse_margin_mm), so use one instance per thread.
class ContactDetector {
 public:
  /// Builds the bounding volume hierarchies of both models (copied). Uses
  /// `params.epsilon_mm` and `params.detection`.
  /// @throws cf::Error when a parameter is out of range (validate(), cf/params.hpp).
  ContactDetector(const Polyhedron& a, const Polyhedron& b, const Params& params = {});
  ~ContactDetector();
  ContactDetector(ContactDetector&&) noexcept;
  ContactDetector& operator=(ContactDetector&&) noexcept;

  /// Fills `out` with the candidate PCs at `pose`, sorted in canonical PC order, with
  /// `dominated` and `plane` set. No heap allocation.
  void detect(const Pose& pose, ContactSet& out);

  const Params& params() const;
  const Polyhedron& model_a() const;
  const Polyhedron& model_b() const;
  /// Element pairs of kinds that can touch whose bounding boxes overlapped in the last
  /// `detect` (before the cheap rejections and the exact tests); on a pose served from kept
  /// pairs (last_reused_pairs), the kept pairs whose certificates did not hold; all pairs
  /// with use_bvh off.
  std::size_t last_pairs_tested() const;
  /// Whether the last `detect` tested only the pairs kept at an earlier pose
  /// (DetectionParams::reuse_margin_mm) instead of descending the hierarchies.
  bool last_reused_pairs() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf

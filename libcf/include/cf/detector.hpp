#pragma once
/// @file
/// Candidate principal contacts at a pose (SPEC section 6, paper section 4.1): every pair
/// of an element of A and an element of B that is within the contact threshold and whose
/// type is consistent within tolerances. Built once per model pair; `detect` allocates
/// nothing. docs/runtime.md describes every test and tolerance.

#include <cf/contact.hpp>
#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <memory>

namespace cf {

/// Tolerances of contact detection. Lengths in mm, angles in rad.
struct DetectionParams {
  /// Contact threshold: element pairs further apart than this are not in contact
  /// (paper eq. (1)).
  double epsilon = 1.0;
  /// Deepest interpenetration still reported as a contact (distance down to -max_penetration).
  /// Deeper pairs are taken as the far side of the other solid, not a contact.
  double max_penetration = 1.0;
  /// How far outside a face (in its plane) or beyond an edge's end a contact may fall and
  /// still count, so that degenerate touches (v-v, v-e, e-v, collinear e-e) yield their
  /// neighbouring non-degenerate interpretations. <= 0 means `epsilon`.
  double in_plane_tolerance = 0;
  /// Fixed angular tolerance for "near-parallel" (f-f, e-f, f-e) and "not near-parallel"
  /// (e-e). <= 0 (the default) derives it per pair from the extent L of the contact
  /// region: atan(epsilon / L), i.e. the tilt at which the whole region stays within the
  /// threshold, clamped to [min_angular_tolerance, max_angular_tolerance].
  double angular_tolerance = 0;
  double min_angular_tolerance = 1e-3;  ///< rad (about 0.06 degrees)
  double max_angular_tolerance = 0.1;   ///< rad (about 5.7 degrees)
  /// Added to the misfit of a contact that another detected contact dominates.
  double dominance_penalty = 1.0;
  /// A detected contact dominates another (ContactPc::dominated) only when its shape fits
  /// within this share of its tolerances: its misfit without the distance term (angle /
  /// angular tolerance + in-plane gap / epsilon) is at most this. Between this and the
  /// tolerance both readings stand (e.g. an edge touching exactly under a face tilted by
  /// 0.7 of the face's tolerance: e-f and f-f), and the previous CF, else the fit, decides:
  /// a hysteresis band rather than a flip at one angle.
  double dominance_fit = 0.25;
  /// Cull element pairs with bounding volume hierarchies and cheap necessary conditions
  /// (the default). false runs the exact tests on all pairs: for checking the culling and
  /// for comparison only.
  bool use_bvh = true;
  /// mm. Temporal coherence for models of 256 features or more in a servo loop: when A
  /// has moved less than half this since the previous call, `detect` keeps the element
  /// pairs that come within this margin of each other, and at the following poses, while no
  /// point of A is further than the margin from where it was then (bounded from the
  /// translation and the change of rotation), it tests only those, skipping the hierarchy.
  /// The results are the same for any value; 0 turns it off. A larger margin keeps more
  /// pairs for more ticks.
  double reuse_margin = 0.3;
};

/// Finds the candidate PCs between A (moving) and B (fixed) at a pose. Immutable after
/// construction except for per-call scratch space and the pairs kept for the next call
/// (DetectionParams::reuse_margin), so use one instance per thread.
class ContactDetector {
 public:
  /// Builds the bounding volume hierarchies of both models (copied).
  /// @throws cf::Error when a parameter is not finite or negative where it must not be.
  ContactDetector(const Polyhedron& a, const Polyhedron& b, const DetectionParams& params = {});
  ~ContactDetector();
  ContactDetector(ContactDetector&&) noexcept;
  ContactDetector& operator=(ContactDetector&&) noexcept;

  /// Fills `out` with the candidate PCs at `pose`, sorted in canonical PC order, with
  /// `dominated` and `plane` set. No heap allocation.
  void detect(const Pose& pose, ContactSet& out);

  const DetectionParams& params() const;
  const Polyhedron& model_a() const;
  const Polyhedron& model_b() const;
  /// Element pairs of kinds that can touch whose bounding boxes overlapped in the last
  /// `detect` (before the cheap rejections and the exact tests); on a pose served from kept
  /// pairs (last_reused_pairs), the kept pairs whose certificates did not hold; all pairs
  /// with use_bvh off.
  std::size_t last_pairs_tested() const;
  /// Whether the last `detect` tested only the pairs kept at an earlier pose
  /// (DetectionParams::reuse_margin) instead of descending the hierarchies.
  bool last_reused_pairs() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf

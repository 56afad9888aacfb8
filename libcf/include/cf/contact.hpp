#pragma once
/// @file
/// Contacts detected at a pose: the candidate principal contacts of section 6 of docs/spec.md, each
/// with its distance, point of action and task frame, and a fixed-capacity set of them.

#include <cf/pc.hpp>
#include <cf/types.hpp>

#include <array>
#include <cstdint>
#include <limits>

namespace cf {

/// One contact between an element of A and an element of B at the current pose.
struct ContactPc {
  Pc pc;
  /// mm, signed distance along the task frame's y axis: > 0 apart, < 0 interpenetrating.
  /// Paper eq. (1) uses it as d_j. For line and plane PCs it is the smallest such distance
  /// over the contact region (its deepest point).
  double distance = 0;
  /// mm, world frame: the contact point (point PC) or the centroid of the contact region
  /// (line and plane PCs), taken on A.
  Vec3 p_W = Vec3::Zero();
  /// Task frame in the world: columns are its x, y, z axes; y is the contact-plane normal
  /// pointing into A; origin on the contact plane at the contact point or region centroid.
  Mat3 R_WT = Mat3::Identity();
  Vec3 origin_W = Vec3::Zero();  ///< mm, world frame
  /// Non-negative residual of the type's geometric conditions: smaller fits better. Used to
  /// rank interpretations. It is the sum of
  ///   angle / angular tolerance (parallel types: f-f, e-f, f-e),
  ///   |distance| / epsilon,
  ///   in-plane gap / epsilon (how far the contact falls outside the face or edge ends),
  ///   a dominance penalty when another detected contact dominates this one
  /// (docs/runtime.md gives the tolerances).
  double misfit = 0;
  /// True when another detected contact dominates this one (docs/spec.md, section 4: its elements
  /// are those of the other or lie on their boundaries), e.g. a v-f beside the e-f of an
  /// edge ending at that vertex, and that contact's shape fits within
  /// DetectionParams::dominance_fit of its tolerances (a face tilted by most of its
  /// tolerance does not dominate the edge touching under it). Dominated contacts remain
  /// candidates (paper Fig. 3).
  bool dominated = false;
  /// How far inside its type's detection conditions the contact lies: 1 well inside, falling
  /// continuously to 0 at the edge of any of them (the angular tolerance of f-f, e-f and
  /// f-e, the in-plane gap, the wedges' and a vertex's edges' tolerances, e-e's crossing
  /// angle). It weighs p_W in the centre of its plane (centre_W).
  double fit = 1;
  /// mm, world frame: where the force of this contact's plane acts, the depth-weighted centre
  /// of the plane's contact region: the mean of the p_W of the detected contacts weighted by
  /// fit (epsilon - distance) and by how nearly each lies in this contact's plane (parallel
  /// within the largest angular tolerance, its origin within epsilon of the plane); p_W when
  /// all weigh 0 (docs/runtime.md, "Where a plane's force acts"). It moves continuously while
  /// A does, whichever contact of the region a reading takes. Set by ContactDetector::detect;
  /// a contact made by other code may leave it unset (NaN), and its force then acts at p_W.
  Vec3 centre_W = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Index of the contact plane group at this pose (contacts whose planes coincide within
  /// tolerance share it; a CF takes at most one contact per group); -1 before grouping.
  std::int16_t plane = -1;
};

/// The contacts detected at one pose: fixed capacity, no heap, created once.
class ContactSet {
 public:
  static constexpr int kCapacity = 256;
  int size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// True when more contacts were found than fit; the extra ones were dropped.
  bool overflow() const { return overflow_; }
  /// Number of contact plane groups (ContactPc::plane is in [0, num_planes)).
  int num_planes() const { return num_planes_; }
  const ContactPc& operator[](int i) const { return items_[static_cast<std::size_t>(i)]; }
  ContactPc& operator[](int i) { return items_[static_cast<std::size_t>(i)]; }
  const ContactPc* begin() const { return items_.data(); }
  const ContactPc* end() const { return items_.data() + size_; }
  ContactPc* begin() { return items_.data(); }
  ContactPc* end() { return items_.data() + size_; }
  void clear() {
    size_ = 0;
    overflow_ = false;
    num_planes_ = 0;
  }
  /// Appends; returns false (and sets overflow) when full.
  bool push(const ContactPc& c) {
    if (size_ == kCapacity) {
      overflow_ = true;
      return false;
    }
    items_[static_cast<std::size_t>(size_++)] = c;
    return true;
  }
  void set_num_planes(int n) { num_planes_ = n; }

 private:
  std::array<ContactPc, kCapacity> items_{};
  int size_ = 0;
  bool overflow_ = false;
  int num_planes_ = 0;
};

}  // namespace cf

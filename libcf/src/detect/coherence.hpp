#pragma once
// Temporal coherence of detection for big models in a servo loop
// (DetectionParams::reuse_margin_mm). At a pose where A moves slowly, the element pairs
// whose boxes overlap with A's boxes grown by the margin are kept, each with the
// certificate of the test that turned it away (exact.hpp, Cert). Every pair that can touch
// at a later pose where no point of A is further than the margin from the kept pose is
// among them, so such a pose tests only those, and of those only the ones whose
// certificates no longer hold.

#include "bvh.hpp"
#include "exact.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <vector>

namespace cf::internal {

/// Bounds how far any point of A moves from pose p0 to p1 (mm): the move of t.origin_A plus
/// |R1 - R0| times A's reach from it (Frobenius norm, a bound of the spectral norm).
inline double motion_bound(const PairTables& t, const Pose& p0, const Pose& p1) {
  return (p1.apply(t.origin_A) - p0.apply(t.origin_A)).norm() + (p1.R_BA - p0.R_BA).norm() * t.r_a;
}

class KeptPairs {
 public:
  static constexpr std::size_t kMaxKept = 1 << 14;
  enum class Mode { kOff, kServe, kRecord };

  /// Sizes the arrays: coherence is on from here.
  void enable() {
    pairs_.resize(kMaxKept);
    lin_.resize(kMaxKept + 3);
    rot_.resize(kMaxKept + 3);
  }
  bool enabled() const { return !pairs_.empty(); }

  /// At the start of a detection at `pose`: serve it from the kept pairs (A within the
  /// margin of the kept pose), or keep new pairs at it (A moved less than half the margin
  /// since the previous call), or neither. Poses whose R_BA is off orthonormal by more than
  /// t.orth_allow at A's origin are neither: the certificates of B's points seen from A
  /// hold for rotations only.
  Mode start(const PairTables& t, const Pose& pose, double margin_mm) {
    const double moved =
        have_last_ ? motion_bound(t, last_pose_, pose) : std::numeric_limits<double>::infinity();
    last_pose_ = pose;
    have_last_ = true;
    const bool rotation =
        ((pose.R_BA.transpose() * pose.R_BA - Mat3::Identity()) * t.origin_A).norm() <=
        t.orth_allow;
    moved_ = valid_ ? motion_bound(t, kept_pose_, pose) : std::numeric_limits<double>::infinity();
    if (rotation && moved_ <= margin_mm) {
      turned_ = (pose.R_BA - kept_pose_.R_BA).norm();
      return Mode::kServe;
    }
    // Keep pairs for the next poses only while A moves slowly enough for them to serve a
    // few; otherwise (poses far apart) the grown boxes would only cost.
    valid_ = false;
    if (!(rotation && moved <= 0.5 * margin_mm)) return Mode::kOff;
    num_ = 0;
    overflow_ = false;
    moved_ = turned_ = 0;  // this pose is the new kept pose
    return Mode::kRecord;
  }

  /// Serving: `test(ia, ib)` on each kept pair (positions in the trees' element lists)
  /// whose certificate does not hold at this pose (four checked at once); it returns the
  /// pair's new certificate.
  template <class Test>
  void serve(Test&& test) {
    // Rounded up, so that a skip is never wrong by rounding.
    const float moved = static_cast<float>(moved_) * 1.000001f;
    const float turned = static_cast<float>(turned_) * 1.000001f;
    const Eigen::Array4f moved4 = Eigen::Array4f::Constant(moved),
                         turned4 = Eigen::Array4f::Constant(turned);
    for (std::size_t k = 0; k < num_; k += 4) {
      const Eigen::Map<const Eigen::Array4f> lin(lin_.data() + k), rot(rot_.data() + k);
      unsigned todo = ~(greater_mask4(lin, moved4) | greater_mask4(rot, turned4)) & 0xFu;
      while (todo != 0) {
        const std::size_t i = k + static_cast<std::size_t>(__builtin_ctz(todo));
        todo &= todo - 1;
        store(i, test(pairs_[i].a, pairs_[i].b));
      }
    }
  }

  /// Recording: one more pair, and its certificate at this pose.
  void record(int ia, int ib, const Cert& c) {
    if (num_ < pairs_.size()) {
      pairs_[num_] = {ia, ib};
      store(num_++, c);
    } else {
      overflow_ = true;
    }
  }
  /// The end of a recording detection at `pose`: the pairs serve from now on, unless they
  /// overflowed.
  void finish_recording(const Pose& pose) {
    if (overflow_) return;
    valid_ = true;
    kept_pose_ = pose;
    // Padding that is always skipped.
    for (std::size_t k = num_; k % 4 != 0; ++k) lin_[k] = std::numeric_limits<float>::infinity();
  }

 private:
  // Pair i's certificate, from this pose, counted from the kept pose (rounded down): both
  // measures are metrics, so a pair certified at a pose `lin` from the kept pose holds at
  // any pose less than `lin` minus that from the kept pose. Tight while A moves on (the
  // usual servo loop), and the check is two comparisons with this call's distances.
  void store(std::size_t i, const Cert& c) {
    const double lin = c.lin - moved_, rot = c.rot - turned_;
    lin_[i] = lin > 0 ? static_cast<float>(lin) * 0.999999f : 0.0f;
    rot_[i] = rot > 0 ? static_cast<float>(rot) * 0.999999f : 0.0f;
  }

  std::vector<NodePair> pairs_;   // (A position, B position) in the trees' element lists
  std::vector<float> lin_, rot_;  // side by side, padded to a multiple of 4
  std::size_t num_ = 0;
  bool valid_ = false, overflow_ = false, have_last_ = false;
  Pose kept_pose_, last_pose_;
  double moved_ = 0, turned_ = 0;  // this call's pose from the kept pose
};

}  // namespace cf::internal

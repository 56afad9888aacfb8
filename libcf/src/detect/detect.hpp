#pragma once
// Detection's immutable model (the two polyhedra, their trees, the exact tests' tables) and
// its per-thread state (the posing caches, scratch, the kept pairs), apart as in MuJoCo's
// mjModel/mjData: one DetectModel serves any number of threads, each with its own state.
// Both are opaque here so that the trees and tables stay inside detector.cpp.

#include <cf/contact.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>

#include <cstddef>
#include <memory>

namespace cf::internal {

struct DetectModel;
struct DetectState;
struct DetectModelDelete {
  void operator()(const DetectModel* m) const;
};
struct DetectStateDelete {
  void operator()(DetectState* s) const;
};
using DetectModelPtr = std::unique_ptr<const DetectModel, DetectModelDelete>;
using DetectStatePtr = std::unique_ptr<DetectState, DetectStateDelete>;

/// Builds the trees and tables of the pair (copies of a and b).
/// @throws cf::Error when a detection parameter is out of range (named).
DetectModelPtr make_detect_model(const Polyhedron& a, const Polyhedron& b, const Params& params);
/// A state sized for `m`; used only with `m`.
DetectStatePtr make_detect_state(const DetectModel& m);

/// The candidate PCs at `pose` into `out` (canonical order, dominance and planes set). No
/// heap allocation.
void detect(const DetectModel& m, DetectState& s, const Pose& pose, ContactSet& out);

/// The contacts of the last detection and the pose they are of, so that a pose detected
/// twice in a row (the proxy's last pose, then the stages at it) is detected once.
struct DetectedAt {
  ContactSet* out = nullptr;  // where detections go
  Pose pose;
  bool valid = false;
};
/// `at.out` holds the contacts at `pose`: detected unless they already are.
inline const ContactSet& detect_at(const DetectModel& m, DetectState& s, const Pose& pose,
                                   DetectedAt& at) {
  if (!(at.valid && at.pose.t_BA == pose.t_BA && at.pose.R_BA == pose.R_BA)) {
    detect(m, s, pose, *at.out);
    at.pose = pose;
    at.valid = true;
  }
  return *at.out;
}

const Params& params_of(const DetectModel& m);
const Polyhedron& model_a_of(const DetectModel& m);
const Polyhedron& model_b_of(const DetectModel& m);
std::size_t pairs_tested(const DetectState& s);  ///< in the last detect (ContactDetector)
bool reused_pairs(const DetectState& s);         ///< the last detect served kept pairs

}  // namespace cf::internal

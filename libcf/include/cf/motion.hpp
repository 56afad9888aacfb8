#pragma once
/// @file
/// Freedoms of a contact formation at the current pose and the prior motion MT1..MT5 of
/// paper section 4.2 (with the MT2 cases of section 4.4).
///
/// Twists of A are written xi = (v, L w): v (mm) is the displacement of A's origin, w (rad)
/// the rotation vector, L (mm) the size of A (Polyhedron::size), so that both halves are
/// lengths and one tolerance serves both.

#include <cf/contact.hpp>
#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/types.hpp>

#include <Eigen/Core>

#include <cstdint>

namespace cf {

/// Prior motion of A (paper section 4.2), with the MT2 case of section 4.4.
enum class MotionType : std::uint8_t {
  kNone,  ///< no contact, or no CF of the graph fits (conservative rendering)
  kMT1,   ///< guarded motion from no contact to a PC
  kMT2a,  ///< CF kept, no actual physical motion
  kMT2b,  ///< CF kept, the motion must involve translation
  kMT2c,  ///< CF kept, the motion can be a pure rotation
  kMT3,   ///< some PCs changed to neighbouring PCs
  kMT4,   ///< one PC gained
  kMT5,   ///< PCs broken
};
/// "none", "MT1", "MT2.a", "MT2.b", "MT2.c", "MT3", "MT4", "MT5" (cfreplay's `motion`).
const char* to_string(MotionType type);

/// The instantaneous freedoms of A that keep every PC of a CF (bilateral contact
/// constraints: each contact point keeps zero normal velocity).
struct Freedoms {
  static constexpr int kMaxRows = 9;  ///< 3 PCs x 3 constraint points
  int num_constraints = 0;            ///< rows of the constraint matrix
  int dof = 6;                        ///< dimension of the space of twists keeping the CF
  int translation_dof = 3;            ///< dimension of its pure translations
  /// Whether some twist with w != 0 and v . w = 0 (a screw of zero pitch: a pure rotation
  /// about some axis) keeps the CF.
  bool pure_rotation = true;
  Vec3 rotation_axis_W = Vec3::UnitZ();  ///< unit; one such axis when pure_rotation
  Vec3 rotation_point_W = Vec3::Zero();  ///< mm; a point on that axis
  /// Orthonormal basis of the free twists (v, L w) in its first `dof` columns, with v the
  /// velocity of A's origin in world axes.
  Eigen::Matrix<double, 6, 6> basis = Eigen::Matrix<double, 6, 6>::Identity();
  double length_scale = 1;          ///< L, mm
  Vec3 reference_W = Vec3::Zero();  ///< A's origin at this pose: the twists' reference point
};

/// A point of A whose velocity along a contact normal must stay zero while a CF holds.
struct ConstraintPoint {
  Vec3 p_W = Vec3::Zero();   ///< mm, world frame
  Vec3 n_W = Vec3::UnitY();  ///< unit contact normal, world frame
};

/// The freedoms left by constraint points: the null space of the rows
/// n . v + ((p - reference_W) x n) . w, with rank decided at Params::freedom_rank_tolerance
/// on rows scaled by length_scale. The one place where a CF's freedoms are computed: the run
/// time (compute_freedoms) and the generator (the `dof` written into a graph) both call it.
/// @param pts  at most Freedoms::kMaxRows points.
/// @param reference_W  mm, the twists' reference point (A's origin).
/// @param length_scale  mm, > 0, balances rotations against translations (A's size).
/// @throws cf::Error when n is out of [0, Freedoms::kMaxRows] or length_scale <= 0.
Freedoms freedoms_from_points(const ConstraintPoint* pts, int n, const Vec3& reference_W,
                              double length_scale, const Params& params);

/// Constraint points of one PC: the contact point (point PCs), two points on the contact
/// line (line PCs), three non-collinear points of the contact plane (plane PCs), each with
/// the contact normal (task frame y, into A). Line directions come from the models.
/// @param pose  current pose of A.
Freedoms compute_freedoms(const ContactPc* pcs, int n, const Polyhedron& A, const Polyhedron& B,
                          const Pose& pose, const Params& params);

/// Result of comparing a pose change with the freedoms (paper Fig. 10).
struct MotionCheck {
  bool moved = false;                 ///< some point of A moved more than Params::motion_noise_mm
  bool along = true;                  ///< the change is approximately along a possible motion
  double twist_angle_rad = 0;         ///< angle between the twist and the space of freedoms
  double rotation_angle_rad = 0;      ///< angle between the rotation axis and possible axes
  double rotation_rad = 0;            ///< size of the rotation
  Vec3 translation_W = Vec3::Zero();  ///< mm, displacement of A's origin
};

/// Compares the pose change prev -> cur with `f` (computed at cur): "along" when both the
/// whole twist and the rotation axis alone are within Params::motion_angle_tolerance_rad of
/// the free space (rotation axes: the rotation parts of the free twists).
MotionCheck check_motion(const Freedoms& f, const Pose& prev, const Pose& cur,
                         const Params& params);

/// The base prior motion from the previous and the current PC sets and the graph.
struct PriorMotion {
  MotionType type = MotionType::kNone;  ///< MT1, MT2a (to be refined), MT3, MT4, MT5, none
  bool transition_in_graph = true;      ///< false when the CF pair is not a graph transition
  /// Index in the current PC set of the PC that MT4 gained, -1 otherwise.
  int gained = -1;
};

/// Classifies the prior motion (paper section 4.2).
/// @param prev   PCs of the CF at the previous tick (empty: no contact).
/// @param cur    PCs of the current CF (empty: no contact: kNone).
/// @param graph  when given with valid ids, the transition kind is looked up in it; when the
///   pair is not a transition there, the set relation decides and transition_in_graph is
///   false. Without a graph the set relation decides.
PriorMotion classify_prior_motion(const PcSet& prev, const PcSet& cur,
                                  const CfGraph* graph = nullptr, CfId prev_id = CfId(),
                                  CfId cur_id = CfId());

}  // namespace cf

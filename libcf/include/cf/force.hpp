#pragma once
/// @file
/// Contact force and moment of paper sections 4.3-5 from the PCs at the current pose and the
/// prior motion: normal force eq. (1), friction eqs. (2)-(6) with the per-MT rules of
/// section 4.4, totals eqs. (7)-(9), gravity and smoothing (section 4.5). Independent of
/// detection: the input is an array of ContactPc. See docs/force-model.md.

#include <cf/contact.hpp>
#include <cf/motion.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>

#include <array>
#include <cstdint>
#include <string>

namespace cf {

/// Which friction law a PC got this tick.
enum class Regime : std::uint8_t {
  kNone,          ///< not rendered
  kImpactStatic,  ///< eq. (2): guarded impact inside the static friction cone
  kStick,         ///< eq. (4): static friction -K_p s_pj, with eq. (3) holding
  kMaxStatic,     ///< eq. (6): largest static friction mu F_cy
  kKinetic,       ///< eq. (5): kinetic friction mu_D F_cy
  /// Not a PC of the CF: a contact approaching within epsilon in a plane the CF leaves
  /// apart, rendered with eq. (1) alone (no friction) so that its gain does not step.
  kApproaching,
};
/// "none", "impact_static", "stick", "max_static", "kinetic", "approaching".
const char* to_string(Regime regime);

/// The force model's discontinuities by design (docs/force-model.md, "Continuity"): bit
/// flags of ForceResult::discontinuities. Between flagged ticks the wrench moves
/// continuously with the pose.
enum Discontinuity : std::uint32_t {
  kSlipOnset = 1u << 0,     ///< a PC static last tick slides now (eq. (3) fails: mu to mu_D)
  kImpactEnd = 1u << 1,     ///< eq. (2)'s impact friction ends
  kRegimeSwitch = 1u << 2,  ///< another friction regime set by the motion type (eq. (5) or
                            ///< (6), MT3's all-kinetic rule, case (c)'s choice), or the
                            ///< conservative laws start or end
  kHoldRelease = 1u << 3,   ///< section 4.5's hold of F_cy lets go
  kPcLost = 1u << 4,        ///< a PC that pushed last tick is gone and no PC of its plane follows
                            ///< (MT5 with the device pressed in: the proxy drops towards it)
  kPcGained = 1u << 5,      ///< a PC gained in a plane no PC held: its friction (eq. (2) or (5))
                            ///< starts where eq. (1) alone pushed while it approached
};
/// "slip_onset|impact_end|..." for the flags set, "" for none.
std::string discontinuities_string(std::uint32_t flags);

/// Per-PC diagnostics and force.
struct PcForce {
  Pc pc;
  PcExtent extent = PcExtent::kPoint;
  Mat3 R_WT = Mat3::Identity();  ///< task frame axes in the world (y: normal into A)
  Vec3 origin_W = Vec3::Zero();  ///< task frame origin, mm
  Vec3 p_W = Vec3::Zero();       ///< the contact's point p_j, mm: its motion gives s_pj
  Vec3 centre_W = Vec3::Zero();  ///< mm, where the force acts: ContactPc::centre_W, else p_W
  double distance = 0;           ///< d_j, mm
  double F_cy = 0;               ///< N, eq. (1) (after the hold of section 4.5)
  double s_mm = 0;               ///< s_pj as used in eq. (3)
  double s_bound_mm = 0;         ///< mu F_cy / K_p, the eq. (3) bound
  Vec3 u_T = Vec3::Zero();       ///< [a b c]: unit direction of p_j's motion this tick
  Regime regime = Regime::kNone;
  Vec3 F_T = Vec3::Zero();  ///< N, contact force in the task frame [F_cx F_cy F_cz]
  Vec3 F_W = Vec3::Zero();  ///< N, the same in the world
  bool gained = false;      ///< the PC MT4 gained
};

/// Result of one force evaluation. Fixed capacity: no heap.
struct ForceResult {
  static constexpr int kMaxPcs = 16;
  /// The rendered PCs (num_pcs), then the approaching contacts (regime kApproaching).
  std::array<PcForce, kMaxPcs> pcs{};
  int num_pcs = 0;
  int num_approaching = 0;  ///< entries after the PCs; num_pcs + num_approaching <= kMaxPcs
  bool truncated = false;   ///< more contacts than kMaxPcs were given; the rest are ignored
  MotionType motion = MotionType::kNone;
  /// Discontinuity flags: why the wrench may jump at this tick; 0 when it moves continuously.
  std::uint32_t discontinuities = 0;
  /// Rendered with the conservative laws (normal force eq. (1) + kinetic friction eq. (5)
  /// on the non-dominated contacts) because no CF or transition of the graph fits.
  bool conservative = false;
  /// Of the current PCs; computed for MT3, and for MT2 when some PC fails eq. (3) (with all
  /// PCs static the case is MT2.a whatever the freedoms). Default (6 dof) otherwise.
  Freedoms freedoms;
  MotionCheck check;                ///< pose change against the freedoms (MT2, when computed)
  Vec3 reference_W = Vec3::Zero();  ///< moment reference point, mm
  Vec3 centroid_W = Vec3::Zero();   ///< p_g, mm
  Vec3 F_contact_W = Vec3::Zero();  ///< eq. (7) in the world (after interpolation)
  Vec3 M_contact_W = Vec3::Zero();  ///< N mm, eq. (8) about reference_W (after interpolation)
  Vec3 F_gravity_W = Vec3::Zero();  ///< m g along -y
  Vec3 F_W = Vec3::Zero();          ///< haptic force F_h = F_c + F_g, world axes
  Vec3 M_W = Vec3::Zero();          ///< N mm, haptic moment about reference_W, world axes
  Vec3 F_A = Vec3::Zero();          ///< F_h in A's axes
  Vec3 M_A = Vec3::Zero();          ///< eq. (9) in A's axes
};

/// The force model's per-tick state (after MuJoCo's `mjData`, as CfState is the servo's): all
/// that ForceModel::step() writes, and all that one tick hands the next. Plain values of fixed
/// capacity; a default-constructed ForceState is the state before the first tick.
struct ForceState {
  /// One PC's friction memory while it (or another reading of its contact plane) is rendered.
  struct Slot {
    Pc pc;
    bool used = false;             ///< holds a PC of the last tick (or of this one)
    bool seen = false;             ///< this tick renders it (set during step())
    Vec3 anchor_A = Vec3::Zero();  ///< the stick anchor: material point of A it holds, A frame
    Vec3 anchor_W = Vec3::Zero();  ///< where that point is tied, world
    double held_fcy = 0;           ///< N, F_cy as section 4.5's hold holds it
    bool held = false;             ///< the hold set the last tick's F_cy
    /// The last tick's reading of the PC: its plane (unit normal into A, a point on it; mm),
    /// its regime and its F_cy (N).
    Vec3 n_W = Vec3::Zero();
    Vec3 origin_W = Vec3::Zero();
    Regime regime = Regime::kNone;
    double F_cy = 0;
  };
  std::array<Slot, ForceResult::kMaxPcs> slots{};
  bool has_prev = false;           ///< a tick was rendered since construction or reset()
  Pose prev_pose;                  ///< pose of A at the last tick: p_j's motion, MT2's check
  double prev_t_s = 0;             ///< s, time of the last tick: the filter's time step
  bool prev_conservative = false;  ///< the last tick rendered with the conservative laws
  /// Section 4.5's low-pass filter of the total contact force (N) and moment (N mm).
  Vec3 filtered_F_W = Vec3::Zero();
  Vec3 filtered_M_W = Vec3::Zero();
  bool filter_valid = false;
  ForceResult result;  ///< the last tick's result (step() returns a reference to it)
};

/// The force model: a fixed part, set at construction and never written (the models, the
/// parameters and what is derived from them once), and one ForceState, all that step()
/// writes. Create once; step() allocates nothing.
class ForceModel {
 public:
  /// What step() reads and never writes (after MuJoCo's `mjModel`, as CfModel is the servo's).
  struct Fixed {
    /// The models must outlive this (they are the graph's models at run time).
    Fixed(const Polyhedron& A, const Polyhedron& B, const Params& params);
    const Polyhedron* A;
    const Polyhedron* B;
    Params params;
    Vec3 centroid_A = Vec3::Zero();  ///< p_g, mm in A's frame (Params::centroid)
    /// cos of detection's largest angular tolerance: two readings of one contact plane have
    /// normals at least this close.
    double cos_plane = 1;
  };

  /// The models must outlive the ForceModel (they are the graph's models at run time).
  /// @throws cf::Error when a parameter is out of range (validate(), cf/params.hpp).
  ForceModel(const Polyhedron& A, const Polyhedron& B, const Params& params = Params());

  /// Forgets the previous tick: the state becomes a default ForceState (anchors, held
  /// forces, filter, previous pose).
  void reset() { state_ = ForceState(); }

  /// One servo tick.
  /// @param pose          pose of A now.
  /// @param t_s           time now, s (strictly increasing across calls).
  /// @param pcs, n        the PCs to render: the identified CF's PCs, or all detected
  ///                      contacts when `conservative`.
  /// @param prior         prior motion from classify_prior_motion (the MT2 case is decided
  ///                      here); ignored when conservative.
  /// @param conservative  no CF or transition of the graph fits: normal force + kinetic
  ///                      friction on the contacts that no other contact dominates.
  /// @param approaching, n_approaching  contacts within epsilon that the CF leaves apart
  ///                      (Identification::approaching): eq. (1) normal force only, when
  ///                      Params::render_approaching; ignored when conservative.
  const ForceResult& step(const Pose& pose, double t_s, const ContactPc* pcs, int n,
                          const PriorMotion& prior, bool conservative = false,
                          const ContactPc* approaching = nullptr, int n_approaching = 0);

  const ForceResult& result() const { return state_.result; }
  const Params& params() const { return fixed_.params; }
  const Fixed& fixed() const { return fixed_; }
  /// The per-tick state (stick anchors, held F_cy, last regimes, previous pose, filter).
  const ForceState& state() const { return state_; }

 private:
  Fixed fixed_;
  ForceState state_;
};

}  // namespace cf

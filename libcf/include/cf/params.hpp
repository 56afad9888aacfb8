#pragma once
/// @file
/// The run time's parameters, one tree (`cf::Params`): the contact threshold, the force
/// model (docs/spec.md, sections 2 and 6; paper section 4), and under it detection
/// (`Params::detection`) and identification (`Params::identification`). Defaults are the
/// paper's values; every choice the paper leaves open is a named option here, described in
/// docs/force-model.md and docs/runtime.md. Every field's name or comment gives its unit.

#include <cf/types.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace cf {

/// How s_pj of eqs. (3)-(4) is measured (docs/spec.md, section 6).
enum class FrictionDisplacement : std::uint8_t {
  /// Tangential displacement of p_j since the PC last entered sticking (a stick anchor).
  /// Independent of the servo rate. When eq. (3) fails the anchor is dragged along so that
  /// it trails p_j at the eq. (3) bound.
  kStickAnchor,
  /// The paper's literal reading: the tangential displacement of p_j over one servo tick.
  kPerTick,
};

/// Where the mass centre of A is taken (paper section 3.1 uses the vertex mean).
enum class CentroidChoice : std::uint8_t { kVertexMean, kVolume };

/// About which point the haptic moment is reported (paper section 5 uses A's frame origin).
enum class MomentReference : std::uint8_t {
  kAOrigin,    ///< A's frame origin (paper eq. (9))
  kACentroid,  ///< A's mass centre (Params::centroid)
  kAPoint,     ///< Params::moment_point_A, a point fixed in A (e.g. where the device holds it)
};

/// The choices' names: the values cfreplay's options and the Python keywords take, one
/// spelling for both ("stick_anchor", "per_tick"; "vertex_mean", "volume"; "a_origin",
/// "a_centroid", "a_point").
const char* to_string(FrictionDisplacement choice);
const char* to_string(CentroidChoice choice);
const char* to_string(MomentReference choice);
/// Every choice of each, in the enum's order.
inline constexpr FrictionDisplacement kFrictionDisplacements[] = {
    FrictionDisplacement::kStickAnchor, FrictionDisplacement::kPerTick};
inline constexpr CentroidChoice kCentroidChoices[] = {CentroidChoice::kVertexMean,
                                                      CentroidChoice::kVolume};
inline constexpr MomentReference kMomentReferences[] = {
    MomentReference::kAOrigin, MomentReference::kACentroid, MomentReference::kAPoint};

/// Tolerances of contact detection (ContactDetector; docs/runtime.md). The contact threshold
/// itself is Params::epsilon_mm.
struct DetectionParams {
  /// mm. Deepest interpenetration still reported as a contact (distance down to
  /// -deepest_contact_mm). Deeper pairs are taken as the far side of the other solid.
  double deepest_contact_mm = 1.0;
  /// mm. How far outside a face (in its plane) or beyond an edge's end a contact may fall
  /// and still count, so that degenerate touches (v-v, v-e, e-v, collinear e-e) yield their
  /// neighbouring non-degenerate interpretations. <= 0 means epsilon_mm.
  double in_plane_tolerance_mm = 0;
  /// rad. Fixed angular tolerance for "near-parallel" (f-f, e-f, f-e) and "not
  /// near-parallel" (e-e). <= 0 (the default) derives it per pair from the extent L of the
  /// contact region: atan(epsilon / L), i.e. the tilt at which the whole region stays within
  /// the threshold, clamped to [min_angular_tolerance_rad, max_angular_tolerance_rad].
  double angular_tolerance_rad = 0;
  double min_angular_tolerance_rad = 1e-3;  ///< rad (about 0.06 degrees)
  double max_angular_tolerance_rad = 0.1;   ///< rad (about 5.7 degrees)
  /// Misfit units (1 = a contact at the edge of its tolerances), added to the misfit of a
  /// contact that another detected contact dominates.
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
  double reuse_margin_mm = 0.3;

  /// rad: the largest angular tolerance any contact gets (angular_tolerance_rad when set,
  /// else max_angular_tolerance_rad); two contacts whose normals differ by more are in
  /// different planes.
  double largest_angular_tolerance_rad() const {
    return angular_tolerance_rad > 0 ? angular_tolerance_rad : max_angular_tolerance_rad;
  }
};

/// Parameters of identification (CfIdentifier; docs/runtime.md).
struct IdentificationParams {
  /// Most interpretations (one candidate or none per contact plane) examined per step;
  /// enumeration goes from the best-fitting candidates down, so a cap drops the worst.
  int max_combinations = 4096;
  /// mm. Which detected contacts a CF must hold: those within touch_distance_mm of touching
  /// (distance <= touch_distance_mm) or of the CF's farthest PC (<= its distance +
  /// touch_distance_mm), unless they are another reading of one of its touches. Farther ones
  /// (up to epsilon) may be left out as apart. So at a witness the exact CF wins over one
  /// that also holds a pair 0.05 mm away (best fit), and a CF is kept while a new contact
  /// approaches, which is gained once it touches. The default is far above rounding (1e-9 mm
  /// at the generator's witnesses) and far below their clearance of non-contacts (0.01 mm).
  double touch_distance_mm = 0.001;
};

/// The proxy (docs/spec.md, section 6b; docs/force-model.md "The proxy"): a 6-DOF god-object pose
/// of A that follows the device pose but never penetrates B by more than penetration_tolerance_mm,
/// and a spring (and damper) coupling the device to it.
struct ProxyParams {
  /// false: no proxy; A's pose is the device pose (the paper's literal model).
  bool enabled = true;
  /// N/mm. The coupling's translational stiffness, which is also the proxy's metric:
  /// rotations are weighted by coupling_stiffness_N_per_mm times A's inertia per unit mass about
  /// the grip point (mm^2; that of A's bounding box), so the rotational stiffness is
  /// coupling_stiffness_N_per_mm * J (N mm/rad). The default is eq. (1)'s K, so that past the
  /// surface the normal force keeps eq. (1)'s slope, and the device's passivity needs are
  /// those of the paper's own band: physical damping above k T / 2 (1.15 N s/m at 1 kHz).
  double coupling_stiffness_N_per_mm = 2.3;
  /// N s/mm. Coupling damping on the device-proxy velocity difference (rotations weighted
  /// as the stiffness is). 0 by default: virtual damping adds to the physical damping a
  /// sampled spring needs to stay passive (b_device > k T / 2 + damping).
  double coupling_damping_N_s_per_mm = 0.0;
  /// mm. Deepest penetration of B the proxy is left with (linearisation and solver
  /// residue); a deeper result is corrected before the tick ends.
  double penetration_tolerance_mm = 0.01;
  /// mm, A's frame: where the device holds A; the coupling acts there.
  Vec3 grip_point_A = Vec3::Zero();
  /// Most sub-steps of one tick's swept motion: each moves every point of A by at most
  /// 0.75 epsilon, or a translation as far as the lookahead shows it free, so that no wall
  /// is crossed between two detections.
  int max_substeps = 256;
  /// Multiple of epsilon_mm (>= 1). A translation longer than one sub-step (a pressed face
  /// breaking away, a fast hand) is first looked along with the detection band widened to
  /// lookahead_epsilons * epsilon_mm, and goes up to 0.75 of that band at once, stopping
  /// half an epsilon short of the first contact in it: one detection instead of one per
  /// 0.75 epsilon. Turns advance one sub-step at a time. 1 turns it off; where the proxy
  /// ends is the same either way (the solve at every sub-step uses the stages' own detection).
  double lookahead_epsilons = 4.0;
  /// Projected Gauss-Seidel sweeps of the constraint solve per (sub-)step (at most).
  int solver_iterations = 60;
  /// Friction acts inside the proxy step: a contact that sticks does not slide.
  bool friction = true;
};

/// All parameters of the run time: the contact threshold, detection, identification,
/// friction, gravity and smoothing. ContactDetector, CfIdentifier, ForceModel and
/// HapticRenderer each read the parts they need from one Params.
struct Params {
  // --- Paper's experimental values (paper section 6; docs/spec.md, section 2) ---
  double mass_kg = 0.5;                     ///< m, mass of A
  double gravity_N_per_kg = 9.8;            ///< g, acting along -y of the world
  double contact_stiffness_N_per_mm = 2.3;  ///< K of eq. (1)
  double kp_N_per_mm = 1.6;                 ///< K_p of eqs. (3)-(4)
  double mu_static = 0.7;                   ///< mu of eqs. (2), (3), (6)
  double mu_kinetic = 0.08;                 ///< mu_D of eq. (5) (docs/spec.md, section 6)
  /// The contact threshold: of eq. (1), of detection (element pairs farther apart are not in
  /// contact) and of identification. The only epsilon of the run time.
  double epsilon_mm = 1.0;

  // --- Friction ---
  FrictionDisplacement friction_displacement = FrictionDisplacement::kStickAnchor;

  // --- Mass centre and moment ---
  CentroidChoice centroid = CentroidChoice::kVertexMean;
  MomentReference moment_reference = MomentReference::kAOrigin;
  Vec3 moment_point_A = Vec3::Zero();  ///< mm, A's frame; the reference with kAPoint

  // --- Freedoms and the "approximately along" test of paper Fig. 10 ---
  /// Relative singular-value tolerance for the null space of the contact constraints: a
  /// direction is free when its constraint singular value is below this fraction of the
  /// largest (constraint rows are unit normals and moment arms divided by the model size).
  double freedom_rank_tolerance = 1e-6;
  /// rad. A pose change is "approximately along" the freedoms when the angle between its
  /// twist (translation of A's origin, rotation vector times the model size) and the space
  /// of freedoms is at most this; the same angle bounds the rotation axis alone.
  double motion_angle_tolerance_rad = 0.35;  // 20 degrees
  /// mm. Pose changes whose largest point displacement over A is below this count as no
  /// motion at all (they pass the "along" test trivially).
  double motion_noise_mm = 1e-9;

  // --- Contacts approaching in a plane the CF leaves apart ---
  /// Identification gains a contact of a new plane when it touches (within
  /// IdentificationParams::touch_distance_mm), not when it comes within epsilon; true renders
  /// such approaching contacts with eq. (1) meanwhile (normal force only), so that the force
  /// rises from 0 at epsilon as eq. (1) intends instead of stepping by up to K epsilon at the
  /// gain. false: only the CF's PCs push (docs/force-model.md).
  bool render_approaching = true;

  // --- Smoothing (paper section 4.5). Both off by default so that eq. (1) holds exactly. ---
  /// N. When > 0 and the prior motion is compliant (MT2..MT5), a PC keeps its previous F_cy
  /// while the new eq. (1) value differs from the held one by less than this (a deadband
  /// against the held value, so slow drifts still update: rate independent).
  double hold_fcy_threshold_N = 0.0;
  /// s. When > 0 the total contact force and moment are low-pass filtered across ticks with
  /// this time constant: factor = 1 - exp(-dt / tau), so the filter is rate independent.
  double interpolation_time_constant_s = 0.0;

  // --- Detection and identification ---
  DetectionParams detection;
  IdentificationParams identification;
  ProxyParams proxy;
};

}  // namespace cf

namespace cf {

/// One real-valued parameter of Params: where it is in the tree, its names, unit and the
/// values accepted. param_specs() lists every one: the one table from which validate(), the
/// options of cfreplay and the keywords of the Python package take their ranges and help.
struct ParamSpec {
  const char* path;    ///< its path in Params ("mu_static", "proxy.coupling_stiffness_N_per_mm")
  const char* python;  ///< the Python keyword
  /// cfreplay's option, the Python keyword in kebab case ("--mu-static"), or nullptr when
  /// it has none.
  const char* option;
  const char* unit;  ///< "N/mm", "rad", ...; "" for a plain number
  double lo, hi;     ///< accepted: finite and in [lo, hi] (in (lo, hi] with lo_open)
  bool lo_open;
  const char* doc;            ///< one line, for --help and Python's docs
  double& (*field)(Params&);  ///< the value in a tree
  /// The Python keyword before a rename, accepted with a DeprecationWarning for one
  /// release; nullptr when there was none.
  const char* deprecated_python = nullptr;
  /// cfreplay's option before the names were made one ("--mu"), accepted with a warning for
  /// one release; nullptr when there was none.
  const char* deprecated_option = nullptr;
  double get(const Params& p) const { return field(const_cast<Params&>(p)); }
  /// Empty when `v` is accepted, else why not: "mu_static = -1 is outside [0, 100]".
  std::string problem(double v) const;
};

/// Every real-valued parameter of Params, in the tree's order.
const std::vector<ParamSpec>& param_specs();

/// Checks a parameter tree: every real value against param_specs(), the integers (at least
/// 1), the points (finite), and the constraints between parameters (kinetic friction at most
/// static friction, the derived angular tolerances' floor at most their ceiling).
/// ContactDetector, CfIdentifier, ForceModel, HapticRenderer and CfModel call it.
/// @throws cf::Error "cf::Params: parameter <path> = <value> is outside <range> <unit>", or
/// naming both parameters of a constraint.
void validate(const Params& p);

}  // namespace cf

// Contact force and moment (paper sections 4.3-5). See docs/force-model.md for every
// equation, the readings of docs/spec.md, section 6, and the per-MT rules.

#include <cf/force.hpp>

#include "force_step.hpp"

#include "../check.hpp"
#include "tolerances.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf {

const char* to_string(Regime regime) {
  switch (regime) {
    case Regime::kNone:
      return "none";
    case Regime::kImpactStatic:
      return "impact_static";
    case Regime::kStick:
      return "stick";
    case Regime::kMaxStatic:
      return "max_static";
    case Regime::kKinetic:
      return "kinetic";
    case Regime::kApproaching:
      return "approaching";
  }
  return "none";
}

std::string discontinuities_string(std::uint32_t flags) {
  static const std::pair<Discontinuity, const char*> kNames[] = {
      {kSlipOnset, "slip_onset"},     {kImpactEnd, "impact_end"}, {kRegimeSwitch, "regime_switch"},
      {kHoldRelease, "hold_release"}, {kPcLost, "pc_lost"},       {kPcGained, "pc_gained"}};
  std::string out;
  for (const auto& [flag, name] : kNames)
    if (flags & flag) out += (out.empty() ? "" : "|") + std::string(name);
  return out;
}

namespace {

using Slot = ForceState::Slot;
constexpr int kMaxPcs = ForceResult::kMaxPcs;

// mm: a tangential motion or stretch shorter than this has no direction: round-off of the
// poses, relative to epsilon (the length scale of what the force model measures).
double round_off_mm(const Params& P) { return internal::kRelativeRounding * P.epsilon_mm; }

constexpr std::size_t pc_index(int k) { return static_cast<std::size_t>(k); }

Vec3 tangential(const Vec3& v, const Vec3& n) { return v - n * n.dot(v); }

Vec3 unit_or_zero(const Vec3& v, double tiny_mm) {
  const double l = v.norm();
  return l > tiny_mm ? Vec3(v / l) : Vec3::Zero();
}

// The stick anchor's stretch after the anchored material point moves by d (tangential, mm)
// from stretch w0, the anchor trailing at most L (mm) behind it: w0 + d while that is within
// L. Past L the anchor is dragged along the string and the stretch turns towards d as a
// tractrix does, tan(phi/2) shrinking by e^(-s/L) over a straight travel s (phi: the angle
// between the stretch and d). Exact for a straight tick, so the anchor, and the friction
// along it, do not depend on how a path is cut into ticks (docs/force-model.md, "s_pj").
Vec3 trail(const Vec3& w0, const Vec3& d, double L, double tiny_mm) {
  const Vec3 chord = w0 + d;
  if (chord.norm() <= L) return chord;
  if (!(L > 0)) return Vec3::Zero();
  // Where along d the stretch reaches L: |w0 + t d| = L, the root in (0, 1]; or the start,
  // pulled in to L, when a bound smaller than last tick's already holds the anchor there.
  double t0 = 0;
  Vec3 w = w0 * (L / std::max(w0.norm(), L));
  if (w0.norm() < L) {
    const double a = d.squaredNorm(), b = w0.dot(d), c = w0.squaredNorm() - L * L;
    t0 = (-b + std::sqrt(b * b - a * c)) / a;
    w = w0 + t0 * d;
  }
  const double travel = (1 - t0) * d.norm();
  const Vec3 u = unit_or_zero(d, tiny_mm);
  const Vec3 w_across = w - u * u.dot(w);  // the stretch's part across the motion
  const Vec3 across = unit_or_zero(w_across, tiny_mm);
  const double phi0 = std::atan2(w_across.norm(), u.dot(w));
  const double phi1 = 2 * std::atan(std::tan(0.5 * phi0) * std::exp(-travel / L));
  return L * (std::cos(phi1) * u + std::sin(phi1) * across);
}

bool compliant(MotionType m) {
  return m == MotionType::kMT2a || m == MotionType::kMT2b || m == MotionType::kMT2c ||
         m == MotionType::kMT3 || m == MotionType::kMT4 || m == MotionType::kMT5;
}

// One tick's working values per rendered PC, beside ForceResult::pcs (on the stack: not state).
struct PcWork {
  int m = 0;                  // rendered PCs
  int input[kMaxPcs];         // each one's index among the given contacts
  Slot* slot[kMaxPcs];        // its friction memory
  bool gained[kMaxPcs];       // a fresh slot that no PC of last tick handed its state
  Vec3 dir_static[kMaxPcs];   // unit, world: eqs. (4) and (6)'s direction
  Vec3 dir_kinetic[kMaxPcs];  // unit, world: eq. (5)'s
  Vec3 trail[kMaxPcs];        // mm, world: the anchor's stretch after its drag (trail())
};

// ---- The tick's start and the contacts rendered ----

void begin_force_tick(ForceState& s, const PriorMotion& prior, bool conservative) {
  ForceResult& r = s.result;
  r.num_pcs = 0;
  r.truncated = false;
  r.conservative = conservative;
  r.motion = conservative ? MotionType::kNone : prior.type;
  r.check = MotionCheck();
  // Entering or leaving the conservative laws changes every PC's law.
  r.discontinuities =
      s.has_prev && conservative != s.prev_conservative ? std::uint32_t{kRegimeSwitch} : 0u;
  r.freedoms = Freedoms();
  for (Slot& slot : s.slots) slot.seen = false;
}

bool dominated(const ForceModel::Fixed& fm, const ContactPc* pcs, int n, int i) {
  bool dom = false;
  for (int j = 0; j < n && !dom; ++j) dom = j != i && dominates(*fm.A, *fm.B, pcs[j].pc, pcs[i].pc);
  return dom;
}

// The contacts rendered, into w: the given ones up to kMaxPcs. With the conservative laws,
// only those no other given contact dominates (the PC rule of docs/spec.md, section 4):
// several interpretations of one physical contact (paper Fig. 3) must not add up.
void select_contacts(const ForceModel::Fixed& fm, const ContactPc* pcs, int n, bool conservative,
                     PcWork& w, ForceResult& r) {
  w.m = 0;
  for (int i = 0; i < n; ++i) {
    if (conservative && dominated(fm, pcs, n, i)) continue;
    if (w.m == kMaxPcs) {
      r.truncated = true;
      break;
    }
    w.input[w.m++] = i;
  }
}

// ---- Slots: each PC's friction memory across ticks ----

Slot* find_slot(ForceState& s, const Pc& pc) {
  for (Slot& slot : s.slots)
    if (slot.used && slot.pc == pc) return &slot;
  return nullptr;
}

// This tick's PCs that have slots keep them (new_slot may take any other).
void keep_slots(ForceState& s, const ContactPc* pcs, const PcWork& w) {
  for (int k = 0; k < w.m; ++k)
    if (Slot* slot = find_slot(s, pcs[w.input[k]].pc)) slot->seen = true;
}

Slot& new_slot(ForceState& s, const Pc& pc) {
  // A free slot, else one whose PC is not rendered this tick (keep_slots marks this tick's
  // PCs first, so such a slot is stale): with at most kMaxPcs PCs per tick one always exists.
  Slot* stale = nullptr;
  for (Slot& slot : s.slots) {
    if (!slot.used) {
      stale = &slot;
      break;
    }
    if (!slot.seen && stale == nullptr) stale = &slot;
  }
  CF_DEMAND(stale != nullptr);
  if (stale->used && stale->F_cy > 0) s.result.discontinuities |= kPcLost;  // pushed last tick
  *stale = Slot();
  stale->used = true;
  stale->pc = pc;
  return *stale;
}

// A slot of last tick's PCs that no PC of this tick holds (yet) and whose plane is c's: the
// same contact region read as another PC (an f-f read as the e-f of its edge).
Slot* same_plane_unseen(const ForceModel::Fixed& fm, ForceState& s, const ContactPc& c) {
  const Vec3 n = c.R_WT.col(1);
  for (Slot& slot : s.slots)
    if (slot.used && !slot.seen && slot.n_W.dot(n) >= fm.cos_plane &&
        std::abs(n.dot(c.origin_W - slot.origin_W)) <= fm.params.epsilon_mm)
      return &slot;
  return nullptr;
}

// c's slot: its own (fresh = false), else a new one with its anchor at p_j, or with the
// friction memory of another reading of the same region, which carries over so that a change
// of reading does not drop the anchor.
Slot& slot_of(const ForceModel::Fixed& fm, ForceState& s, const ContactPc& c, const Vec3& p_A,
              bool& fresh) {
  fresh = false;
  if (Slot* own = find_slot(s, c.pc)) return *own;
  fresh = true;
  Slot* before = same_plane_unseen(fm, s, c);
  const Slot carried = before != nullptr ? *before : Slot();
  if (before != nullptr) before->used = false;
  Slot& slot = new_slot(s, c.pc);  // one exists: at most kMaxPcs PCs, stale slots are reused
  slot.anchor_A = p_A;
  slot.anchor_W = c.p_W;
  if (carried.used) {
    slot.anchor_A = carried.anchor_A, slot.anchor_W = carried.anchor_W;
    slot.held_fcy = carried.held_fcy, slot.held = carried.held;
    slot.regime = carried.regime, slot.F_cy = carried.F_cy;
  }
  return slot;
}

// Slots of last tick's PCs that this tick does not render are freed; one that pushed had
// its force drop with no PC of its plane taking over.
void drop_unseen(ForceState& s) {
  for (Slot& slot : s.slots)
    if (slot.used && !slot.seen) {
      if (slot.F_cy > 0) s.result.discontinuities |= kPcLost;
      slot = Slot();
    }
}

// ---- Per PC: geometry, eq. (1) with the hold, s_pj ----

// A PcForce carrying the contact's geometry (type, task frame, point, distance), no force yet.
PcForce with_geometry(const ContactPc& c) {
  PcForce f;
  f.pc = c.pc;
  f.extent = extent(c.pc.type);
  f.R_WT = c.R_WT;
  f.origin_W = c.origin_W;
  f.p_W = c.p_W;
  f.centre_W = c.centre_W.allFinite() ? c.centre_W : c.p_W;  // unset: at the contact
  f.distance = c.distance;
  return f;
}

// Eq. (1), N; the clamp only guards round-off (a PC is reported within epsilon).
double eq1(const Params& P, double distance) {
  return std::max(0.0, P.contact_stiffness_N_per_mm * (P.epsilon_mm - distance));
}

// F_cy: eq. (1), or with section 4.5's hold (`hold`: a compliant motion and a PC of last
// tick) the held value while eq. (1) stays within the threshold of it. A deadband about the
// held value, not last tick's: slow drifts still update, at any servo rate.
double normal_force(const Params& P, Slot& slot, double distance, bool hold, std::uint32_t& flags) {
  const double raw = eq1(P, distance);
  const bool held = hold && std::abs(raw - slot.held_fcy) < P.hold_fcy_threshold_N;
  double F_cy = slot.held_fcy;
  if (!held) {
    if (slot.held && raw != slot.held_fcy) flags |= kHoldRelease;
    F_cy = raw;
    slot.held_fcy = raw;
  }
  slot.held = held;
  return F_cy;
}

// s_pj and friction's directions. With the stick anchor, s_pj is the stretch of its material
// point from the tie point, and every friction law acts along the stretch as the anchor's drag
// leaves it (`trail`): p_j's motion over its last eq. (3) bound of travel, which a proxy's
// sub-micron settling cannot turn as it turns a 1 um tick's own motion at 10 kHz. Per tick
// (and with no stretch), the tick's tangential motion t_tick.
void displacement(bool anchor_mode, double tiny_mm, const Pose& pose, const Pose* prev_pose,
                  const Slot& slot, const Vec3& nrm, const Vec3& t_tick, PcForce& f,
                  Vec3& dir_static, Vec3& dir_kinetic, Vec3& stretch_after) {
  stretch_after = Vec3::Zero();
  if (anchor_mode) {
    const Vec3 now = pose.apply(slot.anchor_A);
    const Vec3 before = prev_pose != nullptr ? prev_pose->apply(slot.anchor_A) : now;
    const Vec3 w0 = tangential(before - slot.anchor_W, nrm), d = tangential(now - before, nrm);
    f.s_mm = (w0 + d).norm();
    stretch_after = trail(w0, d, f.s_bound_mm, tiny_mm);
    dir_static = unit_or_zero(stretch_after, tiny_mm);
  } else {
    f.s_mm = t_tick.norm();
    dir_static = unit_or_zero(t_tick, tiny_mm);
  }
  if (anchor_mode && stretch_after.norm() > tiny_mm)
    dir_kinetic = dir_static;
  else
    dir_kinetic = t_tick.norm() > tiny_mm ? unit_or_zero(t_tick, tiny_mm) : dir_static;
}

// Each rendered PC's geometry, the motion [a b c] of A's material point at p_j over the
// tick, its slot, F_cy, the eq. (3) bound and s_pj.
void read_pcs(const ForceModel::Fixed& fm, ForceState& s, const Pose& pose, const ContactPc* pcs,
              PcWork& w) {
  const Params& P = fm.params;
  ForceResult& r = s.result;
  const bool anchor_mode = P.friction_displacement == FrictionDisplacement::kStickAnchor;
  const bool hold = P.hold_fcy_threshold_N > 0 && compliant(r.motion);
  for (int k = 0; k < w.m; ++k) {
    const ContactPc& c = pcs[w.input[k]];
    PcForce& f = r.pcs[pc_index(k)];
    f = with_geometry(c);
    const Vec3 nrm = c.R_WT.col(1);
    const Vec3 p_A = pose.inverse_apply(c.p_W);
    const Vec3 d_tick = s.has_prev ? Vec3(c.p_W - s.prev_pose.apply(p_A)) : Vec3::Zero();
    f.u_T = unit_or_zero(c.R_WT.transpose() * d_tick, round_off_mm(P));
    const Vec3 t_tick = tangential(d_tick, nrm);

    bool fresh = false;
    Slot& slot = slot_of(fm, s, c, p_A, fresh);
    w.gained[k] = fresh && slot.regime == Regime::kNone;
    slot.seen = true;
    slot.n_W = nrm;
    slot.origin_W = c.origin_W;
    w.slot[k] = &slot;

    f.F_cy = normal_force(P, slot, c.distance, hold && !fresh, r.discontinuities);
    f.s_bound_mm = P.mu_static * f.F_cy / P.kp_N_per_mm;
    displacement(anchor_mode, round_off_mm(P), pose, s.has_prev ? &s.prev_pose : nullptr, slot, nrm,
                 t_tick, f, w.dir_static[k], w.dir_kinetic[k], w.trail[k]);
  }
}

// ---- The friction regime per motion type (section 4.4) ----

// Eq. (3). The slack absorbs the round-off of an anchor placed exactly at the bound.
bool sticks(const PcForce& f, double tiny_mm) {
  constexpr double kBoundRounding = 1e-9;  // relative: the anchor's own round-off, and more
  return f.s_mm <= f.s_bound_mm * (1 + kBoundRounding) + tiny_mm;
}

Regime stick_or_max(const PcForce& f, double tiny_mm) {
  return sticks(f, tiny_mm) ? Regime::kStick : Regime::kMaxStatic;
}

// Eq. (2)'s cone test on [a b c]: moving towards B (b < 0) within the cone.
bool inside_cone(const PcForce& f, double mu) {
  const Vec3& u = f.u_T;
  return u.y() < 0 && std::hypot(u.x(), u.z()) <= mu * std::abs(u.y());
}

void set_all(ForceResult& r, int m, Regime g) {
  for (int k = 0; k < m; ++k) r.pcs[pc_index(k)].regime = g;
}

// Case (c) of MT2, also used by MT3 and MT5: the PC with the least s_pj stays static when
// eq. (3) holds there (a pure compliant rotation about it), the others slide.
void rotation_rule(ForceResult& r, int m, double tiny_mm) {
  int i_min = 0;
  for (int k = 1; k < m; ++k)
    if (r.pcs[pc_index(k)].s_mm < r.pcs[pc_index(i_min)].s_mm) i_min = k;
  set_all(r, m, Regime::kKinetic);
  if (m > 0 && sticks(r.pcs[pc_index(i_min)], tiny_mm))
    r.pcs[pc_index(i_min)].regime = Regime::kStick;
}

// The freedoms of the current PCs: an SVD-sized eigenproblem, so only when a rule needs
// them. The rendered PCs are the first m given (select_contacts drops none when not
// conservative).
Freedoms freedoms_of(const ForceModel::Fixed& fm, const ContactPc* pcs, int m, const Pose& pose) {
  return compute_freedoms(pcs, m, *fm.A, *fm.B, pose, fm.params);
}

// MT2: the first situation (every PC satisfies eq. (3)) needs no freedoms; otherwise the
// pose change against them decides between the second situation, (b) and (c).
void regimes_mt2(const ForceModel::Fixed& fm, const Pose* prev, const Pose& pose,
                 const ContactPc* pcs, int m, ForceResult& r) {
  const double tiny_mm = round_off_mm(fm.params);
  bool all_stick = true;
  for (int k = 0; k < m; ++k) all_stick = all_stick && sticks(r.pcs[pc_index(k)], tiny_mm);
  if (all_stick) {
    r.motion = MotionType::kMT2a;  // first situation: every PC static, eq. (4)
    set_all(r, m, Regime::kStick);
    return;
  }
  r.freedoms = freedoms_of(fm, pcs, m, pose);
  if (prev != nullptr) r.check = check_motion(r.freedoms, *prev, pose, fm.params);
  if (!r.check.along) {
    r.motion = MotionType::kMT2a;  // second situation: not a possible motion
    for (int k = 0; k < m; ++k)
      r.pcs[pc_index(k)].regime = stick_or_max(r.pcs[pc_index(k)], tiny_mm);
  } else if (!r.freedoms.pure_rotation) {
    r.motion = MotionType::kMT2b;
    set_all(r, m, Regime::kKinetic);
  } else {
    r.motion = MotionType::kMT2c;
    rotation_rule(r, m, tiny_mm);
  }
}

// MT4: the gained PC g inside its cone takes eq. (2) and the others hold where eq. (3) does
// (else eq. (6)); outside the cone all slide.
void regimes_mt4(const Params& P, int g, int m, ForceResult& r) {
  if (g >= 0 && g < m && inside_cone(r.pcs[pc_index(g)], P.mu_static)) {
    for (int k = 0; k < m; ++k)
      r.pcs[pc_index(k)].regime =
          k == g ? Regime::kImpactStatic : stick_or_max(r.pcs[pc_index(k)], round_off_mm(P));
  } else {
    set_all(r, m, Regime::kKinetic);
  }
  if (g >= 0 && g < m) r.pcs[pc_index(g)].gained = true;
}

// Each PC's friction law by the rules of section 4.4 for the prior motion (the MT2 case is
// decided here); the conservative laws are kinetic friction throughout. `prev`: last tick's
// pose, null on the first tick.
void choose_regimes(const ForceModel::Fixed& fm, const Pose* prev, const Pose& pose,
                    const ContactPc* pcs, int m, const PriorMotion& prior, bool conservative,
                    ForceResult& r) {
  if (m == 0) return;
  if (conservative) {
    set_all(r, m, Regime::kKinetic);
    return;
  }
  switch (r.motion) {
    case MotionType::kMT1:
      for (int k = 0; k < m; ++k)
        r.pcs[pc_index(k)].regime = inside_cone(r.pcs[pc_index(k)], fm.params.mu_static)
                                        ? Regime::kImpactStatic
                                        : Regime::kKinetic;
      break;
    case MotionType::kMT2a:
    case MotionType::kMT2b:
    case MotionType::kMT2c:
      regimes_mt2(fm, prev, pose, pcs, m, r);
      break;
    case MotionType::kMT3:
      r.freedoms = freedoms_of(fm, pcs, m, pose);
      if (!r.freedoms.pure_rotation)
        set_all(r, m, Regime::kKinetic);
      else
        rotation_rule(r, m, round_off_mm(fm.params));
      break;
    case MotionType::kMT4:
      regimes_mt4(fm.params, prior.gained, m, r);
      break;
    case MotionType::kMT5:
      rotation_rule(r, m, round_off_mm(fm.params));
      break;
    case MotionType::kNone:
      set_all(r, m, Regime::kKinetic);
      break;
  }
}

// ---- The friction force per regime, the anchors, the flags ----

// PC f's friction in its task frame (y = 0) by its regime.
Vec3 friction_T(const Params& P, const PcForce& f, const Vec3& dir_static,
                const Vec3& dir_kinetic) {
  const Vec3 x = f.R_WT.col(0);
  const Vec3 z = f.R_WT.col(2);
  auto task_dir = [&](const Vec3& d_W) { return Vec3(x.dot(d_W), 0.0, z.dot(d_W)); };
  switch (f.regime) {
    case Regime::kImpactStatic:  // eq. (2)
      return Vec3(f.F_cy * f.u_T.x() / f.u_T.y(), 0.0, f.F_cy * f.u_T.z() / f.u_T.y());
    case Regime::kStick:  // eq. (4); min() only trims the round-off slack of eq. (3)
      return -P.kp_N_per_mm * std::min(f.s_mm, f.s_bound_mm) * task_dir(dir_static);
    case Regime::kMaxStatic:  // eq. (6)
      return -P.mu_static * f.F_cy * task_dir(dir_static);
    case Regime::kKinetic:  // eq. (5)
      return -P.mu_kinetic * f.F_cy * task_dir(dir_kinetic);
    case Regime::kNone:
    case Regime::kApproaching:
      break;
  }
  return Vec3::Zero();
}

// The flag of a PC's regime changing from `was` to `now` (both rendered regimes).
std::uint32_t regime_change(Regime was, Regime now) {
  if (was == now) return 0;
  const bool was_static = was == Regime::kStick || was == Regime::kImpactStatic;
  if (was_static && (now == Regime::kKinetic || now == Regime::kMaxStatic)) return kSlipOnset;
  if (was == Regime::kImpactStatic) return kImpactEnd;
  return kRegimeSwitch;
}

// The flags of a PC's friction Ff this tick: its law changed since last tick, or friction
// starts on a PC gained in a plane no PC held (where eq. (1) alone pushed while it approached).
std::uint32_t friction_flags(const Slot& slot, const PcForce& f, bool gained, const Vec3& Ff) {
  if (slot.regime != Regime::kNone) return regime_change(slot.regime, f.regime);
  return gained && Ff.squaredNorm() > 0 ? std::uint32_t{kPcGained} : 0u;
}

// The stick anchor after the tick's friction Ff (docs/force-model.md, "s_pj").
void move_anchor(const Params& P, const Pose& pose, const PcForce& f, const Vec3& Ff,
                 const Vec3& stretch_after, Slot& slot) {
  if (f.regime == Regime::kImpactStatic) {
    // Pre-stretch the new anchor so that eq. (4) continues the impact friction on the
    // next ticks instead of dropping it: the result does not depend on the servo rate.
    slot.anchor_A = pose.inverse_apply(f.p_W);
    slot.anchor_W = f.p_W + f.R_WT * Ff / P.kp_N_per_mm;
  } else if (f.regime != Regime::kStick && f.s_mm > f.s_bound_mm) {
    // Eq. (3) fails: the PC slips and the anchor is dragged to trail at the bound.
    slot.anchor_W = pose.apply(slot.anchor_A) - stretch_after;
  }
}

// Each rendered PC's force F_T = [F_cx F_cy F_cz] and F_W; its slot records the tick.
void render_pcs(const Params& P, ForceState& s, const Pose& pose, const PcWork& w) {
  ForceResult& r = s.result;
  const bool anchor_mode = P.friction_displacement == FrictionDisplacement::kStickAnchor;
  for (int k = 0; k < w.m; ++k) {
    PcForce& f = r.pcs[pc_index(k)];
    Slot& slot = *w.slot[k];
    const Vec3 Ff = friction_T(P, f, w.dir_static[k], w.dir_kinetic[k]);
    f.F_T = Vec3(Ff.x(), f.F_cy, Ff.z());
    f.F_W = f.R_WT * f.F_T;
    r.discontinuities |= friction_flags(slot, f, w.gained[k], Ff);
    slot.regime = f.regime;
    slot.F_cy = f.F_cy;
    if (anchor_mode) move_anchor(P, pose, f, Ff, w.trail[k], slot);
  }
  r.num_pcs = w.m;
}

// ---- Approaching contacts ----

// Contacts the CF leaves apart push with eq. (1) along their normals and nothing else (a
// decision of ours, docs/force-model.md); no slot: when gained, a PC starts with a fresh
// anchor, as any new PC does. Listed after the PCs.
void render_approaching(const Params& P, const ContactPc* approaching, int n, ForceResult& r) {
  r.num_approaching = 0;
  if (!P.render_approaching || approaching == nullptr) return;
  for (int i = 0; i < n; ++i) {
    if (r.num_pcs + r.num_approaching == kMaxPcs) {
      r.truncated = true;
      break;
    }
    const ContactPc& c = approaching[i];
    PcForce& f = r.pcs[pc_index(r.num_pcs + r.num_approaching++)];
    f = with_geometry(c);
    f.F_cy = eq1(P, c.distance);
    f.regime = Regime::kApproaching;
    f.F_T = Vec3(0.0, f.F_cy, 0.0);
    f.F_W = f.R_WT * f.F_T;
  }
}

// ---- Totals, gravity, moment; smoothing ----

void reference_points(const ForceModel::Fixed& fm, const Pose& pose, ForceResult& r) {
  r.centroid_W = pose.apply(fm.centroid_A);
  switch (fm.params.moment_reference) {
    case MomentReference::kAOrigin:
      r.reference_W = pose.t_BA;
      break;
    case MomentReference::kACentroid:
      r.reference_W = r.centroid_W;
      break;
    case MomentReference::kAPoint:
      r.reference_W = pose.apply(fm.params.moment_point_A);
      break;
  }
}

// Section 4.5's interpolation: x += (1 - exp(-dt / tau)) (x_new - x), the same response at
// any servo rate; off (x = x_new) with tau = 0 and on a first tick.
void smooth(const Params& P, double dt, const Vec3& F_c, const Vec3& M_c, ForceState& s) {
  if (P.interpolation_time_constant_s > 0 && s.filter_valid && dt > 0) {
    const double a = 1.0 - std::exp(-dt / P.interpolation_time_constant_s);
    s.filtered_F_W += a * (F_c - s.filtered_F_W);
    s.filtered_M_W += a * (M_c - s.filtered_M_W);
  } else {
    s.filtered_F_W = F_c;
    s.filtered_M_W = M_c;
  }
  s.filter_valid = true;
}

// Eqs. (7)-(9) and section 4.5: the contact force and its moment about the reference point
// (each PC's force at its centre, then the approaching contacts', in that order), smoothed;
// F_h = F_c + F_g and the moment with gravity's, in world and A's axes.
void totals(const ForceModel::Fixed& fm, const Pose& pose, double t_s, ForceState& s) {
  const Params& P = fm.params;
  ForceResult& r = s.result;
  reference_points(fm, pose, r);
  Vec3 F_c = Vec3::Zero();
  Vec3 M_c = Vec3::Zero();
  for (int k = 0; k < r.num_pcs + r.num_approaching; ++k) {
    const PcForce& f = r.pcs[pc_index(k)];
    F_c += f.F_W;
    M_c += (f.centre_W - r.reference_W).cross(f.F_W);
  }
  smooth(P, s.has_prev ? t_s - s.prev_t_s : 0.0, F_c, M_c, s);
  r.F_contact_W = s.filtered_F_W;
  r.M_contact_W = s.filtered_M_W;
  r.F_gravity_W = Vec3(0.0, -P.mass_kg * P.gravity_N_per_kg, 0.0);
  r.F_W = r.F_contact_W + r.F_gravity_W;
  r.M_W = s.filtered_M_W + (r.centroid_W - r.reference_W).cross(r.F_gravity_W);
  r.F_A = pose.R_BA.transpose() * r.F_W;
  r.M_A = pose.R_BA.transpose() * r.M_W;
}

}  // namespace

ForceModel::Fixed::Fixed(const Polyhedron& a, const Polyhedron& b, const Params& p)
    : A(&a),
      B(&b),
      params(p),
      centroid_A(p.centroid == CentroidChoice::kVolume ? a.volume_centroid() : a.vertex_centroid()),
      cos_plane(std::cos(p.detection.largest_angular_tolerance_rad())) {
  validate(p);
}

ForceModel::ForceModel(const Polyhedron& A, const Polyhedron& B, const Params& params)
    : fixed_(A, B, params) {}

const ForceResult& ForceModel::step(const Pose& pose, double t_s, const ContactPc* pcs, int n,
                                    const PriorMotion& prior, bool conservative,
                                    const ContactPc* approaching, int n_approaching) {
  return internal::step_force(fixed_, state_, pose, t_s, pcs, n, prior, conservative, approaching,
                              n_approaching);
}

const ForceResult& internal::step_force(const ForceModel::Fixed& fm, ForceState& s,
                                        const Pose& pose, double t_s, const ContactPc* pcs, int n,
                                        const PriorMotion& prior, bool conservative,
                                        const ContactPc* approaching, int n_approaching) {
  ForceResult& r = s.result;
  begin_force_tick(s, prior, conservative);
  PcWork w;
  select_contacts(fm, pcs, n, conservative, w, r);
  if (w.m == 0) r.motion = MotionType::kNone;
  keep_slots(s, pcs, w);
  read_pcs(fm, s, pose, pcs, w);
  choose_regimes(fm, s.has_prev ? &s.prev_pose : nullptr, pose, pcs, w.m, prior, conservative, r);
  render_pcs(fm.params, s, pose, w);
  render_approaching(fm.params, conservative ? nullptr : approaching, n_approaching, r);
  drop_unseen(s);
  s.prev_conservative = conservative;
  totals(fm, pose, t_s, s);
  s.has_prev = true;
  s.prev_pose = pose;
  s.prev_t_s = t_s;
  return r;
}

}  // namespace cf

// Contact force and moment (paper sections 4.3-5). See docs/force-model.md for every
// equation, the readings of docs/spec.md, section 6, and the per-MT rules.

#include <cf/force.hpp>

#include "../check.hpp"

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

// mm: tangential motions below this have no direction (round-off of poses in mm).
constexpr double kTinyMm = 1e-12;

Vec3 tangential(const Vec3& v, const Vec3& n) { return v - n * n.dot(v); }

Vec3 unit_or_zero(const Vec3& v) {
  const double l = v.norm();
  return l > kTinyMm ? Vec3(v / l) : Vec3::Zero();
}

bool compliant(MotionType m) {
  return m == MotionType::kMT2a || m == MotionType::kMT2b || m == MotionType::kMT2c ||
         m == MotionType::kMT3 || m == MotionType::kMT4 || m == MotionType::kMT5;
}

}  // namespace

ForceModel::ForceModel(const Polyhedron& A, const Polyhedron& B, const Params& params)
    : A_(&A),
      B_(&B),
      params_(params),
      cos_plane_(std::cos(params.detection.largest_angular_tolerance_rad())) {
  centroid_A_ =
      params_.centroid == CentroidChoice::kVolume ? A.volume_centroid() : A.vertex_centroid();
}

void ForceModel::reset() {
  for (Slot& s : slots_) s = Slot();
  has_prev_ = false;
  conservative_prev_ = false;
  filt_valid_ = false;
  filt_F_.setZero();
  filt_M_.setZero();
  result_ = ForceResult();
}

ForceModel::Slot* ForceModel::find_slot(const Pc& pc) {
  for (Slot& s : slots_)
    if (s.used && s.pc == pc) return &s;
  return nullptr;
}

ForceModel::Slot* ForceModel::new_slot(const Pc& pc) {
  // A free slot, else one whose PC is not rendered this tick (step() marks this tick's PCs
  // first, so such a slot is stale): with at most kMaxPcs PCs per tick one always exists.
  Slot* stale = nullptr;
  for (Slot& s : slots_) {
    if (!s.used) {
      stale = &s;
      break;
    }
    if (!s.seen && stale == nullptr) stale = &s;
  }
  CF_DEMAND(stale != nullptr);
  if (stale->used && stale->F_cy > 0) result_.discontinuities |= kPcLost;  // pushed last tick
  *stale = Slot();
  stale->used = true;
  stale->pc = pc;
  return stale;
}

// A slot of last tick's PCs that no PC of this tick holds (yet) and whose plane is c's: the
// same contact region read as another PC (an f-f read as the e-f of its edge). Its friction
// state carries over, so that a change of reading does not drop the anchor.
ForceModel::Slot* ForceModel::same_plane_unseen(const ContactPc& c) {
  const Vec3 n = c.R_WT.col(1);
  for (Slot& s : slots_)
    if (s.used && !s.seen && s.n_W.dot(n) >= cos_plane_ &&
        std::abs(n.dot(c.origin_W - s.origin_W)) <= params_.epsilon_mm)
      return &s;
  return nullptr;
}

namespace {
// The flag of a PC's regime changing from `was` to `now` (both rendered regimes).
std::uint32_t regime_change(Regime was, Regime now) {
  if (was == now) return 0;
  const bool was_static = was == Regime::kStick || was == Regime::kImpactStatic;
  if (was_static && (now == Regime::kKinetic || now == Regime::kMaxStatic)) return kSlipOnset;
  if (was == Regime::kImpactStatic) return kImpactEnd;
  return kRegimeSwitch;
}
}  // namespace

namespace {
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
}  // namespace

const ForceResult& ForceModel::step(const Pose& pose, double t_s, const ContactPc* pcs, int n,
                                    const PriorMotion& prior, bool conservative,
                                    const ContactPc* approaching, int n_approaching) {
  const Params& P = params_;
  ForceResult& r = result_;
  r.num_pcs = 0;
  r.truncated = false;
  r.conservative = conservative;
  r.motion = conservative ? MotionType::kNone : prior.type;
  r.check = MotionCheck();
  r.discontinuities = has_prev_ && conservative != conservative_prev_ ? kRegimeSwitch : 0;
  r.freedoms = Freedoms();
  const double dt = has_prev_ ? t_s - prev_t_ : 0.0;

  for (Slot& s : slots_) s.seen = false;

  // --- Which contacts are rendered ---
  int idx[ForceResult::kMaxPcs];
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (conservative) {
      // Several interpretations of one physical contact (paper Fig. 3) must not add up:
      // keep the contacts no other detected contact dominates (the PC rule of docs/spec.md,
      // section 4).
      bool dom = false;
      for (int j = 0; j < n && !dom; ++j) dom = j != i && dominates(*A_, *B_, pcs[j].pc, pcs[i].pc);
      if (dom) continue;
    }
    if (m == ForceResult::kMaxPcs) {
      r.truncated = true;
      break;
    }
    idx[m++] = i;
  }
  if (m == 0) r.motion = MotionType::kNone;

  // This tick's PCs that have slots keep them (new_slot may take any other).
  for (int k = 0; k < m; ++k)
    if (Slot* s = find_slot(pcs[idx[k]].pc)) s->seen = true;

  // --- Per-PC geometry, normal force, s_pj ---
  Vec3 dir_static[ForceResult::kMaxPcs];
  Vec3 dir_kinetic[ForceResult::kMaxPcs];
  Slot* slot[ForceResult::kMaxPcs];
  bool gained[ForceResult::kMaxPcs];  // a fresh slot no PC of last tick handed its state
  const bool anchor_mode = P.friction_displacement == FrictionDisplacement::kStickAnchor;
  const bool hold = P.hold_fcy_threshold_N > 0 && compliant(r.motion);
  for (int k = 0; k < m; ++k) {
    const ContactPc& c = pcs[idx[k]];
    PcForce& f = r.pcs[static_cast<std::size_t>(k)];
    f = with_geometry(c);
    const Vec3 nrm = c.R_WT.col(1);

    // Motion of the material point of A at p_j over the tick.
    const Vec3 p_A = pose.inverse_apply(c.p_W);
    const Vec3 d_tick = has_prev_ ? Vec3(c.p_W - prev_pose_.apply(p_A)) : Vec3::Zero();
    f.u_T = unit_or_zero(c.R_WT.transpose() * d_tick);
    const Vec3 t_tick = tangential(d_tick, nrm);

    Slot* s = find_slot(c.pc);
    const bool fresh = s == nullptr;
    if (fresh) {
      // Another reading of a region last tick's PCs held keeps that PC's friction state.
      Slot* before = same_plane_unseen(c);
      const Slot carried = before != nullptr ? *before : Slot();
      if (before != nullptr) before->used = false;
      s = new_slot(c.pc);  // one exists: at most kMaxPcs PCs, stale slots are reused
      s->anchor_A = p_A;
      s->anchor_W = c.p_W;
      if (carried.used) {
        s->anchor_A = carried.anchor_A, s->anchor_W = carried.anchor_W;
        s->held_fcy = carried.held_fcy, s->held = carried.held;
        s->regime = carried.regime, s->F_cy = carried.F_cy;
      }
    }
    gained[k] = fresh && s->regime == Regime::kNone;
    s->seen = true;
    s->n_W = nrm;
    s->origin_W = c.origin_W;
    slot[k] = s;

    const double raw = std::max(0.0, P.stiffness_N_per_mm * (P.epsilon_mm - c.distance));
    const bool held = hold && !fresh && std::abs(raw - s->held_fcy) < P.hold_fcy_threshold_N;
    if (held) {
      f.F_cy = s->held_fcy;
    } else {
      if (s->held && raw != s->held_fcy) r.discontinuities |= kHoldRelease;
      f.F_cy = raw;
      s->held_fcy = raw;
    }
    s->held = held;
    f.s_bound_mm = P.mu_static * f.F_cy / P.kp_N_per_mm;

    if (anchor_mode) {
      const Vec3 stretch = tangential(pose.apply(s->anchor_A) - s->anchor_W, nrm);
      f.s_mm = stretch.norm();
      dir_static[k] = unit_or_zero(stretch);
    } else {
      f.s_mm = t_tick.norm();
      dir_static[k] = unit_or_zero(t_tick);
    }
    dir_kinetic[k] = t_tick.norm() > kTinyMm ? unit_or_zero(t_tick) : dir_static[k];
  }

  // Eq. (3). The slack absorbs the round-off of an anchor placed exactly at the bound.
  auto sticks = [&](int k) {
    const PcForce& f = r.pcs[static_cast<std::size_t>(k)];
    return f.s_mm <= f.s_bound_mm * (1 + 1e-9) + kTinyMm;
  };
  auto set_all = [&](Regime g) {
    for (int k = 0; k < m; ++k) r.pcs[static_cast<std::size_t>(k)].regime = g;
  };
  auto static_or_max = [&](int k) { return sticks(k) ? Regime::kStick : Regime::kMaxStatic; };
  // Eq. (2)'s cone test on [a b c]: moving towards B (b < 0) within the cone.
  auto inside_cone = [&](int k) {
    const Vec3& u = r.pcs[static_cast<std::size_t>(k)].u_T;
    return u.y() < 0 && std::hypot(u.x(), u.z()) <= P.mu_static * std::abs(u.y());
  };
  // Case (c) of MT2, also used by MT3 and MT5: the PC with the least s_pj stays static
  // when eq. (3) holds there (a pure compliant rotation about it), the others slide.
  auto rotation_rule = [&]() {
    int i_min = 0;
    for (int k = 1; k < m; ++k)
      if (r.pcs[static_cast<std::size_t>(k)].s_mm < r.pcs[static_cast<std::size_t>(i_min)].s_mm)
        i_min = k;
    set_all(Regime::kKinetic);
    if (m > 0 && sticks(i_min)) r.pcs[static_cast<std::size_t>(i_min)].regime = Regime::kStick;
  };

  // --- Friction regime per the rules of section 4.4 ---
  if (m > 0) {
    // The freedoms (an SVD-sized eigenproblem) only when a rule needs them. The PCs are
    // contiguous here: idx is the identity when not conservative.
    auto freedoms = [&]() { r.freedoms = compute_freedoms(pcs, m, *A_, *B_, pose, P); };
    if (conservative) {
      set_all(Regime::kKinetic);
    } else {
      switch (r.motion) {
        case MotionType::kMT1:
          for (int k = 0; k < m; ++k)
            r.pcs[static_cast<std::size_t>(k)].regime =
                inside_cone(k) ? Regime::kImpactStatic : Regime::kKinetic;
          break;
        case MotionType::kMT2a:
        case MotionType::kMT2b:
        case MotionType::kMT2c: {
          bool all_stick = true;
          for (int k = 0; k < m; ++k) all_stick = all_stick && sticks(k);
          if (!all_stick) {
            freedoms();
            if (has_prev_) r.check = check_motion(r.freedoms, prev_pose_, pose, P);
          }
          if (all_stick) {
            r.motion = MotionType::kMT2a;  // first situation: every PC static, eq. (4)
            set_all(Regime::kStick);
          } else if (!r.check.along) {
            r.motion = MotionType::kMT2a;  // second situation: not a possible motion
            for (int k = 0; k < m; ++k)
              r.pcs[static_cast<std::size_t>(k)].regime = static_or_max(k);
          } else if (!r.freedoms.pure_rotation) {
            r.motion = MotionType::kMT2b;
            set_all(Regime::kKinetic);
          } else {
            r.motion = MotionType::kMT2c;
            rotation_rule();
          }
          break;
        }
        case MotionType::kMT3:
          freedoms();
          if (!r.freedoms.pure_rotation)
            set_all(Regime::kKinetic);
          else
            rotation_rule();
          break;
        case MotionType::kMT4: {
          const int g = prior.gained;
          if (g >= 0 && g < m && inside_cone(g)) {
            for (int k = 0; k < m; ++k)
              r.pcs[static_cast<std::size_t>(k)].regime =
                  k == g ? Regime::kImpactStatic : static_or_max(k);
          } else {
            set_all(Regime::kKinetic);
          }
          if (g >= 0 && g < m) r.pcs[static_cast<std::size_t>(g)].gained = true;
          break;
        }
        case MotionType::kMT5:
          rotation_rule();
          break;
        case MotionType::kNone:
          set_all(Regime::kKinetic);
          break;
      }
    }
  }

  // --- Friction force per regime, anchors, totals ---
  Vec3 F_c = Vec3::Zero();
  Vec3 M_c = Vec3::Zero();
  r.centroid_W = pose.apply(centroid_A_);
  switch (P.moment_reference) {
    case MomentReference::kAOrigin:
      r.reference_W = pose.t_BA;
      break;
    case MomentReference::kACentroid:
      r.reference_W = r.centroid_W;
      break;
    case MomentReference::kAPoint:
      r.reference_W = pose.apply(P.moment_point_A);
      break;
  }
  for (int k = 0; k < m; ++k) {
    PcForce& f = r.pcs[static_cast<std::size_t>(k)];
    const Vec3 x = f.R_WT.col(0);
    const Vec3 z = f.R_WT.col(2);
    auto task_dir = [&](const Vec3& d_W) { return Vec3(x.dot(d_W), 0.0, z.dot(d_W)); };
    Vec3 Ff = Vec3::Zero();  // task frame, y = 0
    switch (f.regime) {
      case Regime::kImpactStatic:
        Ff = Vec3(f.F_cy * f.u_T.x() / f.u_T.y(), 0.0, f.F_cy * f.u_T.z() / f.u_T.y());  // eq. (2)
        break;
      case Regime::kStick:  // eq. (4); min() only trims the round-off slack of eq. (3)
        Ff = -P.kp_N_per_mm * std::min(f.s_mm, f.s_bound_mm) * task_dir(dir_static[k]);
        break;
      case Regime::kMaxStatic:
        Ff = -P.mu_static * f.F_cy * task_dir(dir_static[k]);
        break;  // eq. (6)
      case Regime::kKinetic:
        Ff = -P.mu_kinetic * f.F_cy * task_dir(dir_kinetic[k]);
        break;  // eq. (5)
      case Regime::kNone:
      case Regime::kApproaching:
        break;
    }
    f.F_T = Vec3(Ff.x(), f.F_cy, Ff.z());
    f.F_W = f.R_WT * f.F_T;
    F_c += f.F_W;
    M_c += (f.centre_W - r.reference_W).cross(f.F_W);
    if (slot[k]->regime != Regime::kNone)
      r.discontinuities |= regime_change(slot[k]->regime, f.regime);
    else if (gained[k] && Ff.squaredNorm() > 0)
      r.discontinuities |= kPcGained;
    slot[k]->regime = f.regime;
    slot[k]->F_cy = f.F_cy;

    if (anchor_mode) {
      Slot* s = slot[k];
      const Vec3 nrm = f.R_WT.col(1);
      if (f.regime == Regime::kImpactStatic) {
        // Pre-stretch the new anchor so that eq. (4) continues the impact friction on the
        // next ticks instead of dropping it: the result does not depend on the servo rate.
        s->anchor_A = pose.inverse_apply(f.p_W);
        s->anchor_W = f.p_W + f.R_WT * Ff / P.kp_N_per_mm;
      } else if (f.regime != Regime::kStick && f.s_mm > f.s_bound_mm) {
        // Eq. (3) fails: the PC slips and the anchor is dragged to trail at the bound.
        const Vec3 now = pose.apply(s->anchor_A);
        s->anchor_W = now - tangential(now - s->anchor_W, nrm).normalized() * f.s_bound_mm;
      }
    }
  }
  r.num_pcs = m;
  // Approaching contacts: eq. (1) along their normals, nothing else (no slot: when gained a
  // PC starts with a fresh anchor, as any new PC does).
  r.num_approaching = 0;
  if (!conservative && P.render_approaching && approaching != nullptr) {
    for (int i = 0; i < n_approaching; ++i) {
      if (m + r.num_approaching == ForceResult::kMaxPcs) {
        r.truncated = true;
        break;
      }
      const ContactPc& c = approaching[i];
      PcForce& f = r.pcs[static_cast<std::size_t>(m + r.num_approaching++)];
      f = with_geometry(c);
      f.F_cy = std::max(0.0, P.stiffness_N_per_mm * (P.epsilon_mm - c.distance));
      f.regime = Regime::kApproaching;
      f.F_T = Vec3(0.0, f.F_cy, 0.0);
      f.F_W = f.R_WT * f.F_T;
      F_c += f.F_W;
      M_c += (f.centre_W - r.reference_W).cross(f.F_W);
    }
  }
  for (Slot& s : slots_)
    if (s.used && !s.seen) {
      if (s.F_cy > 0) r.discontinuities |= kPcLost;
      s = Slot();
    }
  conservative_prev_ = conservative;

  // --- Smoothing (section 4.5): low-pass across ticks, rate independent ---
  if (P.interpolation_time_constant_s > 0 && filt_valid_ && dt > 0) {
    const double a = 1.0 - std::exp(-dt / P.interpolation_time_constant_s);
    filt_F_ += a * (F_c - filt_F_);
    filt_M_ += a * (M_c - filt_M_);
  } else {
    filt_F_ = F_c;
    filt_M_ = M_c;
  }
  filt_valid_ = true;

  r.F_contact_W = filt_F_;
  r.M_contact_W = filt_M_;
  r.F_gravity_W = Vec3(0.0, -P.mass_kg * P.gravity_N_per_kg, 0.0);
  r.F_W = r.F_contact_W + r.F_gravity_W;
  r.M_W = filt_M_ + (r.centroid_W - r.reference_W).cross(r.F_gravity_W);
  r.F_A = pose.R_BA.transpose() * r.F_W;
  r.M_A = pose.R_BA.transpose() * r.M_W;

  has_prev_ = true;
  prev_pose_ = pose;
  prev_t_ = t_s;
  return r;
}

}  // namespace cf

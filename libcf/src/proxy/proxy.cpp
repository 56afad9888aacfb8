// The 6-DOF god-object proxy (docs/spec.md, section 6b; docs/force-model.md "The proxy"): each tick
// the proxy moves towards the device pose along the swept path, in sub-steps short enough that
// detection sees every wall, and at each sub-step takes the motion closest to its target in the
// coupling's metric under the linearised non-penetration constraints of its point contacts (v-f,
// f-v, e-e: the corners of every contact region) and Coulomb friction, by projected Gauss-Seidel on
// the constraint forces.

#include "proxy.hpp"

#include "../check.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace cf::internal {

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

// mm. Gauss-Seidel stops when no row's update moves the proxy by more than this: it only
// has to find the active set, the projection after it is exact (polish).
constexpr double kSolveTolerance_mm = 1e-5;

// Share of epsilon a point of A may move between two detections. A feature of B it could
// reach was within epsilon, so detected and constrained; below 1 to leave room for the
// in-plane tolerances at the boundary of a face.
constexpr double kSweepShare = 0.75;

// Sweeps a contact group must hold all its loaded corners at the static friction bound before
// it breaks away (a few: a sticking region can touch the bound while its load settles).
constexpr int kBreakawaySweeps = 4;
// Relative change of a group's total normal load over one sweep below which it counts as
// settled for the breakaway (friction at mu_s times a load within 0.1% of its final value).
constexpr double kSettledLoad = 1e-3;

Vec3 rotation_vector(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}
Mat3 rotation_matrix(const Vec3& w) {
  const double a = w.norm();
  if (a == 0) return Mat3::Identity();
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

bool is_point_type(PcType t) { return extent(t) == PcExtent::kPoint; }

// A corner's friction (l1, l2) at its Coulomb bound mu ln (to rounding): where Gauss-Seidel
// left it, the corner would slip.
bool at_friction_bound(double l1, double l2, double mu, double ln) {
  constexpr double kAtBound = 1e-6;  // relative: Gauss-Seidel's round-off at the bound
  const double cap = mu * ln * (1 - kAtBound);
  return mu > 0 && l1 * l1 + l2 * l2 >= cap * cap;
}

// One constraint row: a . xi >= lo (normal) or = 0 (tangent), xi = (v, w) about the grip.
struct Row {
  Vec6 a, Wa;    // the row and the inverse metric times it
  double G = 1;  // a . W a
  // 1 / G: Gauss-Seidel multiplies (a division is on each update's critical path).
  double inv_G = 1;
};

// Grip point of a pose, world frame.
Vec3 grip(const Pose& X, const Vec3& g_A) { return X.apply(g_A); }

Pose moved(const Pose& X, const Vec3& g_A, const Vec3& v, const Vec3& w) {
  Pose Y;
  Y.R_BA = rotation_matrix(w) * X.R_BA;
  const Vec3 g = grip(X, g_A) + v;
  Y.t_BA = g - Y.R_BA * g_A;
  return Y;
}

constexpr int kMaxContacts = ProxyResult::kMaxContacts;
constexpr int kMaxRows = 3 * kMaxContacts;

// One pass's constraints: the point contacts used, three rows each (the normal, then the task
// frame's x and z), their multipliers (constraint forces, N), friction bounds and contact
// planes (groups). On the stack, rebuilt each pass; the last pass's is the tick's report.
struct Constraints {
  std::array<Row, kMaxRows> rows;
  std::array<double, kMaxRows> lambda{};
  std::array<double, kMaxContacts> dist{}, mu{};
  std::array<int, kMaxContacts> group{};          // contact plane, numbered per pass
  std::array<bool, kMaxContacts> slides{};        // by group, from the last polish
  std::array<ContactPc, kMaxContacts> used{};     // copies: detection reuses its set
  std::array<int, ContactSet::kCapacity> pick{};  // the point contacts used
  std::array<std::int16_t, ContactSet::kCapacity> plane_group{};  // detection's plane -> group
  int m = 0;                         // point contacts used as constraints in the last solve
  int num_groups = 0;                // groups of this pass
  Mat3 Winv_rot = Mat3::Identity();  // the inverse metric's rotational block, world axes
};

// The groups that slide: loaded, with every loaded corner's friction at its bound.
void find_sliding_groups(Constraints& c) {
  std::array<double, kMaxContacts> load{};
  std::array<bool, kMaxContacts> saturated{};
  for (int g = 0; g < kMaxContacts; ++g) {
    saturated[static_cast<std::size_t>(g)] = true;
    c.slides[static_cast<std::size_t>(g)] = false;
  }
  for (int j = 0; j < c.m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    const auto g = static_cast<std::size_t>(c.group[J]);
    const double ln = c.lambda[3 * J], l1 = c.lambda[3 * J + 1], l2 = c.lambda[3 * J + 2];
    if (ln <= 0) continue;
    load[g] += ln;
    if (!at_friction_bound(l1, l2, c.mu[J], ln)) saturated[g] = false;
  }
  for (std::size_t g = 0; g < kMaxContacts; ++g) c.slides[g] = load[g] > 0 && saturated[g];
}

// The target xi_d moved by the sliding groups' kinetic friction: each corner's friction (all
// at their bounds) to mu_D times its load, in its own direction (so a region turning about
// its normal keeps its torsional friction).
Vec6 kinetic_target(const Vec6& xi_d, Constraints& c, double mu_kinetic) {
  Vec6 xe = xi_d;
  for (int j = 0; j < c.m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    if (!c.slides[static_cast<std::size_t>(c.group[J])]) continue;
    const double len = std::hypot(c.lambda[3 * J + 1], c.lambda[3 * J + 2]);
    const double sc = len > 0 ? mu_kinetic * c.lambda[3 * J] / len : 0.0;
    c.lambda[3 * J + 1] *= sc;
    c.lambda[3 * J + 2] *= sc;
    xe += c.rows[3 * J + 1].Wa * c.lambda[3 * J + 1] + c.rows[3 * J + 2].Wa * c.lambda[3 * J + 2];
  }
  return xe;
}

// The active rows, orthonormal in the coupling's metric (Gram-Schmidt; dependent rows are
// dropped): at most 6, the twist's dimension. Projecting a twist onto {a_i . xi = b_i}.
class ActiveRows {
 public:
  ActiveRows(double k, const Mat3& Winv_rot) : k_(k), Winv_rot_(Winv_rot) {}
  int size() const { return nq_; }

  // Row a . xi = b, unless it depends on the rows before.
  void add(const Row& row, double b) {
    if (nq_ == 6) return;
    Vec6 u = row.a;
    double c = b;
    for (std::size_t l = 0; l < static_cast<std::size_t>(nq_); ++l) {
      const double p = WQ_[l].dot(row.a);
      u -= p * Q_[l];
      c -= p * C_[l];
    }
    const Vec6 Wu = W(u);
    const double n2 = u.dot(Wu);
    constexpr double kDependent = 1e-10;     // relative: what is left of the row is round-off
    if (!(n2 > kDependent * row.G)) return;  // dependent on the rows before
    const double sc = 1 / std::sqrt(n2);
    const auto q = static_cast<std::size_t>(nq_++);
    Q_[q] = sc * u;
    WQ_[q] = sc * Wu;
    C_[q] = sc * c;
  }

  // Contact j's rows: its normal row at its distance, its friction rows when its group sticks.
  void add_contact(const Constraints& c, int j) {
    const auto J = static_cast<std::size_t>(j);
    add(c.rows[3 * J], -c.dist[J]);
    if (c.mu[J] > 0 && !c.slides[static_cast<std::size_t>(c.group[J])]) {
      add(c.rows[3 * J + 1], 0);
      add(c.rows[3 * J + 2], 0);
    }
  }

  // The twist nearest to xe in the metric that satisfies every row.
  Vec6 project(const Vec6& xe) const {
    Vec6 xi = xe;
    for (std::size_t l = 0; l < static_cast<std::size_t>(nq_); ++l)
      xi += WQ_[l] * (C_[l] - Q_[l].dot(xe));
    return xi;
  }

 private:
  Vec6 W(const Vec6& u) const {  // the inverse metric
    Vec6 w;
    w << u.head<3>() / k_, Winv_rot_ * u.tail<3>();
    return w;
  }
  double k_;
  Mat3 Winv_rot_;
  std::array<Vec6, 6> Q_, WQ_;
  std::array<double, 6> C_{};
  int nq_ = 0;
};

// Projected Gauss-Seidel converges slowly on the redundant rows of contact regions (four
// corners of a face on a plane, with friction on each), and what it leaves unconverged
// drifts the proxy from tick to tick; how it shares a region's load among the corners is
// arbitrary. So its result only chooses the active set: the normal rows it loads, and per
// contact plane (group) whether friction holds. A group slides when every loaded corner's
// friction is at its bound; its friction is then kinetic, mu_D times the group's normal
// load, each corner along its solve's direction, applied as given. Otherwise every loaded
// corner of the group sticks (the region holds as a whole, however the corners share the
// load). The motion is the exact projection of the target onto that set in the coupling's
// metric, kept when it satisfies every normal row. `c.lambda` leaves with the sliding groups'
// kinetic friction; `c.slides` tells them.
Vec6 polish(const Vec6& xi_pgs, const Vec6& xi_d, Constraints& c, double k, double mu_kinetic) {
  find_sliding_groups(c);
  const Vec6 xe = kinetic_target(xi_d, c, mu_kinetic);
  ActiveRows active(k, c.Winv_rot);
  for (int j = 0; j < c.m; ++j) {
    if (c.lambda[static_cast<std::size_t>(3 * j)] <= 0) continue;
    active.add_contact(c, j);
  }
  // A normal row the projection violates (a corner Gauss-Seidel left unloaded, which the
  // motion would push into B) joins the active set, with its friction rows when its group
  // sticks, and the projection is redone: one row per round, while the rows stay independent.
  for (int round = 0; round <= 6; ++round) {
    const Vec6 xi = active.project(xe);
    int worst = -1;
    constexpr double kGapRoundingMm = 1e-9;  // a row violated by less is held, to round-off
    double worst_gap = -kGapRoundingMm;
    for (int j = 0; j < c.m; ++j) {
      const auto J = static_cast<std::size_t>(j);
      const double gap = c.dist[J] + c.rows[3 * J].a.dot(xi);
      if (gap < worst_gap) worst_gap = gap, worst = j;
    }
    if (worst < 0) return xi;
    const int before = active.size();
    active.add_contact(c, worst);
    if (active.size() == before) break;  // dependent on the active rows: they cannot all hold
  }
  return xi_pgs;
}

}  // namespace

namespace {
Params lookahead_params(const Params& p) {
  Params w = p;
  w.epsilon_mm = p.epsilon_mm * p.proxy.lookahead_epsilons;
  DetectionParams& d = w.detection;
  // The in-plane tolerance grows with the band as it does by default, so that a feature
  // within the band but off the end of an edge or face is read through a neighbouring
  // contact. The derived angular tolerance would grow with the band too and read crossing
  // edges as parallel ones: pinned at its floor, e-e is read wherever the stages read it.
  if (!(d.angular_tolerance_rad > 0)) d.max_angular_tolerance_rad = d.min_angular_tolerance_rad;
  return w;
}
}  // namespace

ProxyModel::ProxyModel(const Polyhedron& a, const Polyhedron& b, const Params& p)
    : prm(p.proxy), epsilon_mm(p.epsilon_mm), mu_static(p.mu_static), mu_kinetic(p.mu_kinetic) {
  const ProxyParams& q = p.proxy;
  validate(p);
  // A's bounding box as a solid: its inertia per unit mass about its centre, moved to the
  // grip point. The metric only has to weigh radians against millimetres as A's mass does.
  const Vec3 lo = a.bbox_min(), hi = a.bbox_max(), size = hi - lo, c = 0.5 * (lo + hi);
  const double x2 = size.x() * size.x(), y2 = size.y() * size.y(), z2 = size.z() * size.z();
  Mat3 Jc = Mat3::Zero();
  Jc.diagonal() << (y2 + z2) / 12, (x2 + z2) / 12, (x2 + y2) / 12;
  const Vec3 r = c - q.grip_point_A;
  J_A = Jc + (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  // A flat or needle-like A: keep every axis weighted (1e-6 of the largest).
  constexpr double kAxisFloor = 1e-6, kLeastTrace = 1e-12;  // relative; mm^2 per mm^3
  const double floor = kAxisFloor * std::max(J_A.trace(), kLeastTrace);
  for (int k = 0; k < 3; ++k) J_A(k, k) = std::max(J_A(k, k), floor);
  Jinv_A = J_A.inverse();
  for (const Vertex& v : a.vertices()) reach_mm = std::max(reach_mm, (v.p - q.grip_point_A).norm());
  if (q.enabled && q.lookahead_epsilons > 1) look = make_detect_model(a, b, lookahead_params(p));
}

void init_proxy_state(const ProxyModel& pm, ProxyState& s) {
  s.look = pm.look ? make_detect_state(*pm.look) : nullptr;
}

namespace {

// ---- The tick's start ----

void begin_proxy_tick(ProxyState& s, const Pose& X_WD, double t_s) {
  ProxyResult& r = s.result;
  r.X_WD = X_WD;
  r.constrained = false;
  r.substeps = 0;
  r.iterations = 0;
  r.num_contacts = 0;
  r.dropped_contacts = 0;
  if (!s.has_prev) {
    // The first tick: the proxy starts at the device.
    s.X_WP = X_WD;
    s.X_WP_prev = X_WD;
    s.X_WD_prev = X_WD;
    s.t_prev_s = t_s;
  }
}

// ---- Look-ahead ----

// A translation v from X0 longer than step_len looks through the lookahead band (a wide
// detection) and goes along the same motion until half an epsilon short of the first contact
// that band holds, or look_len: one wide detection instead of one per step_len. The solve at
// every pass, and so where the proxy ends, is the stages' own detection's. Returns the share
// of v to go.
double look_ahead(const ProxyModel& pm, ProxyState& s, const Pose& X0, const Vec3& v,
                  double step_len) {
  const double look_len = step_len * pm.prm.lookahead_epsilons;
  const double len = v.norm();
  const double floor = step_len / len;
  const double stop = 1 - 0.5 * step_len / len;  // the last half step: a pass of its own
  detect(*pm.look, *s.look, X0, s.look_contacts);
  if (s.look_contacts.overflow()) return floor;
  double f = std::min(look_len / len, stop);
  for (const ContactPc& c : s.look_contacts) {
    if (!is_point_type(c.pc.type)) continue;
    // Its distance after the whole step (linear in a translation). The solve keeps the
    // contacts it had at least that far; one it did not have, crossed before the step
    // ends, stops the step half an epsilon short of it.
    const double rate = c.R_WT.col(1).dot(v);
    if (c.distance + rate < -kSolveTolerance_mm)
      f = std::min(f, (c.distance - 0.5 * pm.epsilon_mm) / -rate);
  }
  return std::max(f, floor);
}

// ---- Constraints ----

// Whether the motion xi_d about the grip point g runs into point contact c.
bool blocks(const ContactPc& c, const Vec6& xi_d, const Vec3& g) {
  return c.distance + c.R_WT.col(1).dot(xi_d.head<3>() + xi_d.tail<3>().cross(c.p_W - g)) < 0;
}

// The point contacts to constrain (the corners of every contact region) into c.pick, in
// detection's order; returns how many. With more than kMaxContacts, the nearest: a pass moves
// no point of A by more than kSweepShare epsilon, so the farthest are the last it could
// reach. `blocking`: a contact left out blocks the motion (then the pass must not jump to
// the device).
int pick_point_contacts(const ContactSet& contacts, const Vec6& xi_d, const Vec3& g, Constraints& c,
                        bool& blocking, ProxyResult& r) {
  int n_point = 0;
  for (int i = 0; i < contacts.size(); ++i)
    if (is_point_type(contacts[i].pc.type)) c.pick[static_cast<std::size_t>(n_point++)] = i;
  r.dropped_contacts = std::max(0, n_point - kMaxContacts);
  blocking = false;
  if (r.dropped_contacts == 0) return n_point;
  // Equally near contacts (the corners of a flat region) by index, so the choice is the same
  // from pass to pass.
  const auto nearer = [&](int x, int y) {
    return contacts[x].distance < contacts[y].distance ||
           (contacts[x].distance == contacts[y].distance && x < y);
  };
  std::nth_element(c.pick.begin(), c.pick.begin() + kMaxContacts, c.pick.begin() + n_point, nearer);
  for (int i = kMaxContacts; i < n_point; ++i)
    blocking = blocking || blocks(contacts[c.pick[static_cast<std::size_t>(i)]], xi_d, g);
  std::sort(c.pick.begin(), c.pick.begin() + kMaxContacts);  // detection's order
  return kMaxContacts;
}

// Contact j's group: its contact plane, numbered afresh for the contacts used (detection's
// numbers run over all its contacts, up to its capacity), so at most kMaxContacts groups.
int group_of(const ContactPc& cp, Constraints& c) {
  if (cp.plane < 0) return c.num_groups++;  // ungrouped: a plane of its own
  std::int16_t& pg = c.plane_group[static_cast<std::size_t>(cp.plane)];
  if (pg < 0) pg = static_cast<std::int16_t>(c.num_groups++);
  return pg;
}

// Point contact cp as constraint j about the grip point g: its three rows, its forces from
// the last solve that had it (warm start), and its friction bound (kinetic once it slid).
void add_constraint(const ProxyModel& pm, const ProxyState& s, const ContactPc& cp, const Vec3& g,
                    int j, Constraints& c) {
  const auto J = static_cast<std::size_t>(j);
  const double k = pm.prm.coupling_stiffness_N_per_mm;
  const Vec3 rr = cp.p_W - g;
  c.used[J] = cp;
  c.dist[J] = cp.distance;
  c.group[J] = group_of(cp, c);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const Vec3 dir = cp.R_WT.col(axis == 0 ? 1 : axis == 1 ? 0 : 2);
    Row& row = c.rows[3 * J + axis];
    row.a << dir, rr.cross(dir);
    row.Wa << dir / k, c.Winv_rot * rr.cross(dir);
    row.G = row.a.dot(row.Wa);
    row.inv_G = 1 / row.G;
    c.lambda[3 * J + axis] = 0;
  }
  for (int i = 0; i < s.num_warm; ++i)
    if (s.warm_pc[static_cast<std::size_t>(i)] == cp.pc)
      for (std::size_t axis = 0; axis < 3; ++axis)
        c.lambda[3 * J + axis] = s.warm_lambda[static_cast<std::size_t>(i)][axis];
  bool slid = false;
  for (int i = 0; i < s.num_sliding && !slid; ++i)
    slid = s.sliding[static_cast<std::size_t>(i)] == cp.pc;
  c.mu[J] = pm.prm.friction ? (slid ? pm.mu_kinetic : pm.mu_static) : 0.0;
}

// The pass's constraints at pose X (grip point g, target xi_d) from its detected contacts.
// Returns whether the motion to the device runs into any point contact.
bool build_constraints(const ProxyModel& pm, const ProxyState& s, const ContactSet& contacts,
                       const Pose& X, const Vec3& g, const Vec6& xi_d, Constraints& c,
                       ProxyResult& r) {
  bool blocking = false;
  const int n_point = pick_point_contacts(contacts, xi_d, g, c, blocking, r);
  for (int i = 0; i < n_point; ++i) {
    const int pl = contacts[c.pick[static_cast<std::size_t>(i)]].plane;
    if (pl >= 0) c.plane_group[static_cast<std::size_t>(pl)] = -1;
  }
  c.num_groups = 0;
  c.m = 0;
  c.Winv_rot = X.R_BA * pm.Jinv_A * X.R_BA.transpose() / pm.prm.coupling_stiffness_N_per_mm;
  for (int i = 0; i < n_point; ++i) {
    const ContactPc& cp = contacts[c.pick[static_cast<std::size_t>(i)]];
    add_constraint(pm, s, cp, g, c.m++, c);
    if (blocks(cp, xi_d, g)) blocking = true;
  }
  return blocking;
}

// ---- Solve ----

// One projected Gauss-Seidel sweep over the rows, xi = xi_d + W sum a_i lambda_i kept up to
// date; returns the largest displacement (mm) a row's update made.
double gauss_seidel_sweep(Constraints& c, Vec6& xi) {
  double change = 0;
  for (int j = 0; j < c.m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    const Row& rn = c.rows[3 * J];
    double& ln = c.lambda[3 * J];
    const double ln_new = std::max(0.0, ln - (c.dist[J] + rn.a.dot(xi)) * rn.inv_G);
    xi += rn.Wa * (ln_new - ln);
    change = std::max(change, std::abs(ln_new - ln) * rn.G);
    ln = ln_new;
    if (c.mu[J] == 0) continue;
    const Row& r1 = c.rows[3 * J + 1];
    const Row& r2 = c.rows[3 * J + 2];
    double& l1 = c.lambda[3 * J + 1];
    double& l2 = c.lambda[3 * J + 2];
    double n1 = l1 - r1.a.dot(xi) * r1.inv_G, n2 = l2 - r2.a.dot(xi) * r2.inv_G;
    // sqrt, not hypot: the forces are far from overflow, and hypot is several times slower.
    const double cap = c.mu[J] * ln, len2 = n1 * n1 + n2 * n2;
    if (len2 > cap * cap) {
      const double sc = len2 > 0 ? cap / std::sqrt(len2) : 0.0;
      n1 *= sc;
      n2 *= sc;
    }
    xi += r1.Wa * (n1 - l1) + r2.Wa * (n2 - l2);
    change = std::max({change, std::abs(n1 - l1) * r1.G, std::abs(n2 - l2) * r2.G});
    l1 = n1;
    l2 = n2;
  }
  return change;
}

// A contact group (plane) whose loaded corners have all held their friction at the static
// bound for kBreakawaySweeps sweeps, its load settled, breaks away: from then on its bounds
// are kinetic, as they would be on the next pass. Gauss-Seidel converges very slowly on a
// region held at the edge of static cones (the corners trade a torsional pair of forces), and
// polish would only scale those forces down to kinetic ones anyway.
class Breakaway {
 public:
  // After a sweep: counts the streaks, and moves the groups that break to kinetic bounds.
  void after_sweep(const ProxyModel& pm, Constraints& c, Vec6& xi) {
    if (!(pm.mu_kinetic < pm.mu_static)) return;
    std::array<bool, kMaxContacts> loaded, held, breaks;
    std::array<double, kMaxContacts> load;
    for (int g = 0; g < c.num_groups; ++g) loaded[g] = false, held[g] = true, load[g] = 0;
    for (int j = 0; j < c.m; ++j) {
      const auto J = static_cast<std::size_t>(j);
      const auto g = static_cast<std::size_t>(c.group[J]);
      const double ln = c.lambda[3 * J];
      if (ln <= 0) continue;
      loaded[g] = true;
      load[g] += ln;
      if (!(c.mu[J] == pm.mu_static &&
            at_friction_bound(c.lambda[3 * J + 1], c.lambda[3 * J + 2], c.mu[J], ln)))
        held[g] = false;
    }
    // And its load settled (the group's total within kSettledLoad of a sweep ago): while
    // loads still grow (a fresh contact, a harder press) friction can sit at mu_s times a
    // partial load of a region that sticks. (The corners' shares may still move: they
    // trade load as they trade the torsional pair.)
    bool any = false;
    for (int g = 0; g < c.num_groups; ++g) {
      const bool settled = std::abs(load[g] - load_before_[g]) <= kSettledLoad * load[g];
      load_before_[g] = load[g];
      streak_[g] = loaded[g] && held[g] && settled ? streak_[g] + 1 : 0;
      breaks[g] = streak_[g] >= kBreakawaySweeps;
      any = any || breaks[g];
    }
    if (any) to_kinetic(pm, breaks, c, xi);
  }

 private:
  static void to_kinetic(const ProxyModel& pm, const std::array<bool, kMaxContacts>& breaks,
                         Constraints& c, Vec6& xi) {
    const double sc = pm.mu_kinetic / pm.mu_static;
    for (int j = 0; j < c.m; ++j) {
      const auto J = static_cast<std::size_t>(j);
      if (!breaks[static_cast<std::size_t>(c.group[J])]) continue;
      c.mu[J] = pm.mu_kinetic;
      xi += c.rows[3 * J + 1].Wa * (c.lambda[3 * J + 1] * (sc - 1)) +
            c.rows[3 * J + 2].Wa * (c.lambda[3 * J + 2] * (sc - 1));
      c.lambda[3 * J + 1] *= sc;
      c.lambda[3 * J + 2] *= sc;
    }
  }
  std::array<int, kMaxContacts> streak_{};          // by group
  std::array<double, kMaxContacts> load_before_{};  // N, by group, a sweep ago
};

// The loaded contacts' constraint forces, by PC: a later solve starts from them.
void remember_forces(const Constraints& c, ProxyState& s) {
  s.num_warm = 0;
  for (int j = 0; j < c.m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    if (c.lambda[3 * J] <= 0) continue;
    s.warm_pc[static_cast<std::size_t>(s.num_warm)] = c.used[J].pc;
    s.warm_lambda[static_cast<std::size_t>(s.num_warm++)] = {c.lambda[3 * J], c.lambda[3 * J + 1],
                                                             c.lambda[3 * J + 2]};
  }
}

// A group that broke away slides for the rest of the tick (kinetic bounds in the passes
// after this one), not only from the next tick on.
void remember_sliding(const Constraints& c, ProxyState& s) {
  for (int j = 0; j < c.m; ++j) {
    const Pc& pc = c.used[static_cast<std::size_t>(j)].pc;
    if (!c.slides[static_cast<std::size_t>(c.group[static_cast<std::size_t>(j)])]) continue;
    bool known = false;
    for (int i = 0; i < s.num_sliding && !known; ++i)
      known = s.sliding[static_cast<std::size_t>(i)] == pc;
    if (!known && s.num_sliding < kMaxContacts)
      s.sliding[static_cast<std::size_t>(s.num_sliding++)] = pc;
  }
}

// The motion nearest to xi_d under the constraints: projected Gauss-Seidel on the constraint
// forces (N), warm-started, with breakaway, then polished to the exact projection.
Vec6 solve(const ProxyModel& pm, ProxyState& s, Constraints& c, const Vec6& xi_d) {
  ProxyResult& r = s.result;
  Vec6 xi = xi_d;
  for (int i = 0; i < 3 * c.m; ++i)
    xi += c.rows[static_cast<std::size_t>(i)].Wa * c.lambda[static_cast<std::size_t>(i)];
  Breakaway breakaway;
  for (int it = 0; it < pm.prm.solver_iterations; ++it) {
    ++r.iterations;
    if (gauss_seidel_sweep(c, xi) < kSolveTolerance_mm) break;
    breakaway.after_sweep(pm, c, xi);
  }
  xi = polish(xi, xi_d, c, pm.prm.coupling_stiffness_N_per_mm, pm.mu_kinetic);
  remember_sliding(c, s);
  remember_forces(c, s);  // the next pass of this tick starts from them
  return xi;
}

// ---- Depth check ----

// Whether X keeps every point contact within the allowed depth; if not (a rotation's
// second-order error, a contact the linearisation misjudged) another pass pushes it out. The
// detection is the one the stages then use at this pose (cached).
bool within_depth(const ProxyModel& pm, const DetectModel& dm, DetectState& ds, DetectedAt& at,
                  const Pose& X) {
  double deepest = 0;
  for (const ContactPc& c : detect_at(dm, ds, X, at))
    if (is_point_type(c.pc.type)) deepest = std::min(deepest, c.distance);
  return deepest >= -pm.prm.penetration_tolerance_mm;
}

// ---- The tick's end: constraint forces and coupling ----

// The last solve's constraint forces at the proxy pose X: reported (about the grip point),
// and the contacts that slid remembered for the next tick.
void report_constraints(const ProxyModel& pm, ProxyState& s, const Constraints& c, const Pose& X) {
  ProxyResult& r = s.result;
  const Vec3 g_P = grip(X, pm.prm.grip_point_A);
  r.F_constraint_W.setZero();
  r.M_constraint_W.setZero();
  s.num_sliding = 0;
  remember_forces(c, s);  // the next tick starts from them
  for (int j = 0; j < c.m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    const ContactPc& cp = c.used[J];
    const double ln = c.lambda[3 * J];
    ProxyContact& pc = r.contacts[static_cast<std::size_t>(r.num_contacts++)];
    pc.pc = cp.pc;
    pc.p_W = cp.p_W;
    pc.n_W = cp.R_WT.col(1);
    pc.distance_mm = cp.distance;
    pc.normal_load_N = ln;
    pc.friction_W = c.lambda[3 * J + 1] * cp.R_WT.col(0) + c.lambda[3 * J + 2] * cp.R_WT.col(2);
    pc.sliding = ln > 0 && c.mu[J] > 0 && c.slides[static_cast<std::size_t>(c.group[J])];
    if (pc.sliding) s.sliding[static_cast<std::size_t>(s.num_sliding++)] = cp.pc;
    const Vec3 f = ln * pc.n_W + pc.friction_W;
    r.F_constraint_W += f;
    r.M_constraint_W += (cp.p_W - g_P).cross(f);
  }
}

// The coupling on the hand, about the grip point at the device X_WD: a spring (and damper)
// to the proxy X.
void couple(const ProxyModel& pm, ProxyState& s, const Pose& X, const Pose& X_WD, double t_s) {
  const ProxyParams& q = pm.prm;
  const double k = q.coupling_stiffness_N_per_mm;
  const Vec3& g_A = q.grip_point_A;
  ProxyResult& r = s.result;
  const Vec3 g_P = grip(X, g_A);
  const Vec3 g_D = grip(X_WD, g_A);
  const Mat3 J_W = X_WD.R_BA * pm.J_A * X_WD.R_BA.transpose();
  const Vec3 theta = rotation_vector(X.R_BA * X_WD.R_BA.transpose());  // device to proxy
  r.F_coupling_W = k * (g_P - g_D);
  r.M_coupling_W = k * (J_W * theta);
  const double dt = t_s - s.t_prev_s;
  if (s.has_prev && dt > 0 && q.coupling_damping_N_s_per_mm > 0) {
    const Vec3 dv = (g_P - grip(s.X_WP_prev, g_A)) - (g_D - grip(s.X_WD_prev, g_A));
    const Vec3 dw = rotation_vector(X.R_BA * s.X_WP_prev.R_BA.transpose()) -
                    rotation_vector(X_WD.R_BA * s.X_WD_prev.R_BA.transpose());
    r.F_coupling_W += q.coupling_damping_N_s_per_mm * dv / dt;
    r.M_coupling_W += q.coupling_damping_N_s_per_mm * (J_W * dw) / dt;
  }
  s.has_prev = true;
  s.X_WP_prev = X;
  s.X_WD_prev = X_WD;
  s.t_prev_s = t_s;
}

}  // namespace

void advance_proxy(const ProxyModel& pm, const DetectModel& dm, DetectState& ds, DetectedAt& at,
                   ProxyState& s, const Pose& X_WD, double t_s) {
  ProxyResult& r = s.result;
  begin_proxy_tick(s, X_WD, t_s);
  const Vec3& g_A = pm.prm.grip_point_A;
  // Conservative advancement: each pass takes the motion towards the device that the
  // constraints at the current pose allow; a motion that would move some point of A by more
  // than kSweepShare of epsilon is cut to that length, so that no wall is crossed between two
  // detections (the passes follow the proxy's own motion, not the device's: a proxy held at
  // the surface by a device 20 mm inside takes one pass).
  const double step_len = kSweepShare * pm.epsilon_mm;
  Constraints c;
  Pose X = s.X_WP;
  for (int pass = 0; pass < pm.prm.max_substeps; ++pass) {
    ++r.substeps;
    const ContactSet& contacts = detect_at(dm, ds, X, at);
    const Vec3 g = grip(X, g_A);
    Vec6 xi_d;
    xi_d << grip(X_WD, g_A) - g, rotation_vector(X_WD.R_BA * X.R_BA.transpose());
    const bool blocking = build_constraints(pm, s, contacts, X, g, xi_d, c, r);
    Vec6 xi = xi_d;
    if (blocking) {
      r.constrained = true;
      xi = solve(pm, s, c, xi_d);
    }
    const double sweep = xi.head<3>().norm() + xi.tail<3>().norm() * pm.reach_mm;
    if (sweep > step_len) {
      // Too long to be sure of: advance by step_len and look again; a translation as far as
      // the lookahead band shows it free. (A turn's contacts in the band would be linearised
      // about points up to the band's width from where they touch: turns advance by step_len.)
      constexpr double kTurnShare = 1e-6;  // a turn that moves A this share of a step is none
      const bool translation = xi.tail<3>().norm() * pm.reach_mm <= kTurnShare * step_len;
      const double f =
          pm.look && translation ? look_ahead(pm, s, X, xi.head<3>(), step_len) : step_len / sweep;
      X = moved(X, g_A, f * xi.head<3>(), f * xi.tail<3>());
      continue;
    }
    if (!blocking) {
      X = X_WD;  // nothing in the way: the proxy is the device, exactly
      c.slides.fill(false);
      for (int i = 0; i < 3 * c.m; ++i) c.lambda[static_cast<std::size_t>(i)] = 0;
      break;
    }
    X = moved(X, g_A, xi.head<3>(), xi.tail<3>());
    if (within_depth(pm, dm, ds, at, X)) break;
  }
  s.X_WP = X;
  r.X_WP = X;
  report_constraints(pm, s, c, X);
  couple(pm, s, X, X_WD, t_s);
}

}  // namespace cf::internal

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

namespace cf::detail {

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

void require(bool ok, const std::string& what) {
  if (!ok) throw Error("cf::Params: parameter proxy." + what);
}

// A corner's friction (l1, l2) at its Coulomb bound mu ln (to rounding): where Gauss-Seidel
// left it, the corner would slip.
bool at_friction_bound(double l1, double l2, double mu, double ln) {
  const double cap = mu * ln * (1 - 1e-6);
  return mu > 0 && l1 * l1 + l2 * l2 >= cap * cap;
}

// One constraint row: a . xi >= lo (normal) or = 0 (tangent), xi = (v, w) about the grip.
struct Row {
  Vec6 a, Wa;    // the row and the inverse metric times it
  double G = 1;  // a . W a
  double inv_G =
      1;  // 1 / G: Gauss-Seidel multiplies (a division is on each update's critical path)
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

// Projected Gauss-Seidel converges slowly on the redundant rows of contact regions (four
// corners of a face on a plane, with friction on each), and what it leaves unconverged
// drifts the proxy from tick to tick; how it shares a region's load among the corners is
// arbitrary. So its result only chooses the active set: the normal rows it loads, and per
// contact plane (group) whether friction holds. A group slides when every loaded corner's
// friction is at its bound; its friction is then kinetic, mu_D times the group's normal
// load, each corner along its solve's direction, applied as given. Otherwise every loaded corner of
// the group sticks (the region holds as a whole, however the corners share the load). The motion is
// the exact projection of the target onto that set in the coupling's metric (Gram-Schmidt over the
// rows, dependent rows dropped), kept when it satisfies every normal row. `lambda` leaves with the
// sliding groups' kinetic friction; `slides[g]` tells them.
Vec6 polish(const Vec6& xi_pgs, const Vec6& xi_d, const Row* rows, double* lambda,
            const double* dist, const double* mu, const int* group, int m, double k,
            const Mat3& Winv_rot, double mu_kinetic, bool* slides) {
  auto W = [&](const Vec6& u) {
    Vec6 w;
    w << u.head<3>() / k, Winv_rot * u.tail<3>();
    return w;
  };
  constexpr int kGroups = ProxyResult::kMaxContacts;
  std::array<double, kGroups> load{};
  std::array<bool, kGroups> saturated{};
  for (int g = 0; g < kGroups; ++g) {
    saturated[static_cast<std::size_t>(g)] = true;
    slides[g] = false;
  }
  for (int j = 0; j < m; ++j) {
    const auto g = static_cast<std::size_t>(group[j]);
    const double ln = lambda[3 * j], l1 = lambda[3 * j + 1], l2 = lambda[3 * j + 2];
    if (ln <= 0) continue;
    load[g] += ln;
    if (!at_friction_bound(l1, l2, mu[j], ln)) saturated[g] = false;
  }
  for (int g = 0; g < kGroups; ++g)
    slides[g] = load[static_cast<std::size_t>(g)] > 0 && saturated[static_cast<std::size_t>(g)];
  // Sliding groups: each corner's friction (all at their bounds) to mu_D times its load, in
  // its own direction (so a region turning about its normal keeps its torsional friction).
  Vec6 xe = xi_d;  // the target moved by the kinetic friction of sliding groups
  for (int j = 0; j < m; ++j) {
    if (!slides[group[j]]) continue;
    const double len = std::hypot(lambda[3 * j + 1], lambda[3 * j + 2]);
    const double sc = len > 0 ? mu_kinetic * lambda[3 * j] / len : 0.0;
    lambda[3 * j + 1] *= sc;
    lambda[3 * j + 2] *= sc;
    xe += rows[3 * j + 1].Wa * lambda[3 * j + 1] + rows[3 * j + 2].Wa * lambda[3 * j + 2];
  }
  std::array<Vec6, 6> Q, WQ;
  std::array<double, 6> C{};
  int nq = 0;
  auto add = [&](const Row& row, double b) {
    if (nq == 6) return;
    Vec6 u = row.a;
    double c = b;
    for (int l = 0; l < nq; ++l) {
      const double p = WQ[static_cast<std::size_t>(l)].dot(row.a);
      u -= p * Q[static_cast<std::size_t>(l)];
      c -= p * C[static_cast<std::size_t>(l)];
    }
    const Vec6 Wu = W(u);
    const double n2 = u.dot(Wu);
    if (!(n2 > 1e-10 * row.G)) return;  // dependent on the rows before
    const double sc = 1 / std::sqrt(n2);
    Q[static_cast<std::size_t>(nq)] = sc * u;
    WQ[static_cast<std::size_t>(nq)] = sc * Wu;
    C[static_cast<std::size_t>(nq++)] = sc * c;
  };
  for (int j = 0; j < m; ++j) {
    if (lambda[3 * j] <= 0) continue;
    add(rows[3 * j], -dist[j]);
    if (mu[j] > 0 && !slides[group[j]]) {
      add(rows[3 * j + 1], 0);
      add(rows[3 * j + 2], 0);
    }
  }
  // The projection; a normal row it violates (a corner Gauss-Seidel left unloaded, which the
  // motion would push into B) joins the active set, with its friction rows when its group
  // sticks, and the projection is redone: one row per round, while the rows stay independent.
  for (int round = 0; round <= 6; ++round) {
    Vec6 xi = xe;
    for (int l = 0; l < nq; ++l)
      xi += WQ[static_cast<std::size_t>(l)] *
            (C[static_cast<std::size_t>(l)] - Q[static_cast<std::size_t>(l)].dot(xe));
    int worst = -1;
    double worst_gap = -1e-9;
    for (int j = 0; j < m; ++j) {
      const double gap = dist[j] + rows[3 * j].a.dot(xi);
      if (gap < worst_gap) worst_gap = gap, worst = j;
    }
    if (worst < 0) return xi;
    const int before = nq;
    add(rows[3 * worst], -dist[worst]);
    if (mu[worst] > 0 && !slides[group[worst]]) {
      add(rows[3 * worst + 1], 0);
      add(rows[3 * worst + 2], 0);
    }
    if (nq == before) break;  // dependent on the active rows: they cannot all hold
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
  require(std::isfinite(q.stiffness_N_per_mm) && q.stiffness_N_per_mm > 0,
          "stiffness_N_per_mm must be finite and positive, got " +
              std::to_string(q.stiffness_N_per_mm));
  require(std::isfinite(q.damping_N_s_per_mm) && q.damping_N_s_per_mm >= 0,
          "damping_N_s_per_mm must be finite and non-negative, got " +
              std::to_string(q.damping_N_s_per_mm));
  require(std::isfinite(q.max_penetration_mm) && q.max_penetration_mm > 0,
          "max_penetration_mm must be finite and positive, got " +
              std::to_string(q.max_penetration_mm));
  require(q.grip_point_A.allFinite(), "grip_point_A must be finite");
  require(q.max_substeps >= 1,
          "max_substeps must be at least 1, got " + std::to_string(q.max_substeps));
  require(q.solver_iterations >= 1,
          "solver_iterations must be at least 1, got " + std::to_string(q.solver_iterations));
  require(std::isfinite(q.lookahead_epsilons) && q.lookahead_epsilons >= 1,
          "lookahead_epsilons must be finite and at least 1, got " +
              std::to_string(q.lookahead_epsilons));
  // A's bounding box as a solid: its inertia per unit mass about its centre, moved to the
  // grip point. The metric only has to weigh radians against millimetres as A's mass does.
  const Vec3 lo = a.bbox_min(), hi = a.bbox_max(), size = hi - lo, c = 0.5 * (lo + hi);
  const double x2 = size.x() * size.x(), y2 = size.y() * size.y(), z2 = size.z() * size.z();
  Mat3 Jc = Mat3::Zero();
  Jc.diagonal() << (y2 + z2) / 12, (x2 + z2) / 12, (x2 + y2) / 12;
  const Vec3 r = c - q.grip_point_A;
  J_A = Jc + (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  // A flat or needle-like A: keep every axis weighted (1e-6 of the largest).
  const double floor = 1e-6 * std::max(J_A.trace(), 1e-12);
  for (int k = 0; k < 3; ++k) J_A(k, k) = std::max(J_A(k, k), floor);
  Jinv_A = J_A.inverse();
  for (const Vertex& v : a.vertices()) reach_mm = std::max(reach_mm, (v.p - q.grip_point_A).norm());
  if (q.enabled && q.lookahead_epsilons > 1) look = make_detect_model(a, b, lookahead_params(p));
}

void init_proxy_state(const ProxyModel& pm, ProxyState& s) {
  s.look = pm.look ? make_detect_state(*pm.look) : nullptr;
}

void move_proxy(const ProxyModel& pm, const DetectModel& dm, DetectState& ds, DetectedAt& at,
                ProxyState& s, const Pose& X_WD, double t_s) {
  const ProxyParams& q = pm.prm;
  const double k = q.stiffness_N_per_mm;
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
  const Vec3& g_A = q.grip_point_A;
  // Conservative advancement: each pass takes the motion towards the device that the
  // constraints at the current pose allow; a motion that would move some point of A by
  // more than kSweepShare of epsilon is cut to that length, so that no wall is crossed between two
  // detections (the passes follow the proxy's own motion, not the device's: a proxy held at
  // the surface by a device 20 mm inside takes one pass).
  const double step_len = kSweepShare * pm.epsilon_mm;
  const double look_len = step_len * q.lookahead_epsilons;
  // A translation longer than step_len looks through the lookahead band (a wide detection)
  // and goes along the same motion until half an epsilon short of the first contact that
  // band holds, or look_len: one wide detection instead of one per step_len. The solve at
  // every pass, and so where the proxy ends, is the stages' own detection's.
  const auto look_ahead = [&](const Pose& X0, const Vec3& v) {
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
  };
  Pose X = s.X_WP;
  static constexpr int kMaxRows = 3 * ProxyResult::kMaxContacts;
  std::array<Row, kMaxRows> rows;
  std::array<double, kMaxRows> lambda{};
  std::array<double, ProxyResult::kMaxContacts> dist{}, mu{};
  std::array<int, ProxyResult::kMaxContacts> group{};       // contact plane, numbered per pass
  std::array<bool, ProxyResult::kMaxContacts> slides{};     // by group, from the last polish
  std::array<ContactPc, ProxyResult::kMaxContacts> used{};  // copies: detection reuses its set
  std::array<int, ContactSet::kCapacity> pick{};            // the point contacts used, by index
  std::array<std::int16_t, ContactSet::kCapacity> plane_group{};  // detection's plane -> group
  int m = 0;  // point contacts used as constraints in the last solve
  // The loaded contacts' constraint forces, by PC: a later solve starts from them.
  const auto remember_forces = [&] {
    s.num_warm = 0;
    for (int j = 0; j < m; ++j) {
      const auto J = static_cast<std::size_t>(j);
      if (lambda[3 * J] <= 0) continue;
      s.warm_pc[static_cast<std::size_t>(s.num_warm)] = used[J].pc;
      s.warm_lambda[static_cast<std::size_t>(s.num_warm++)] = {lambda[3 * J], lambda[3 * J + 1],
                                                               lambda[3 * J + 2]};
    }
  };
  for (int pass = 0; pass < q.max_substeps; ++pass) {
    ++r.substeps;
    const ContactSet& contacts = detect_at(dm, ds, X, at);
    const Vec3 g = grip(X, g_A);
    Vec6 xi_d;
    xi_d << grip(X_WD, g_A) - g, rotation_vector(X_WD.R_BA * X.R_BA.transpose());
    // The constraints: the point contacts (the corners of every contact region).
    // With more than kMaxContacts of them, the nearest: a pass moves no point of A by more
    // than kSweepShare epsilon, so the farthest are the last it could reach.
    int n_point = 0;
    for (int i = 0; i < contacts.size(); ++i)
      if (is_point_type(contacts[i].pc.type)) pick[static_cast<std::size_t>(n_point++)] = i;
    r.dropped_contacts = std::max(0, n_point - ProxyResult::kMaxContacts);
    // Whether the motion to the device runs into a point contact (one that is left out too:
    // then the pass must not jump to the device).
    const auto blocks = [&](const ContactPc& c) {
      return c.distance + c.R_WT.col(1).dot(xi_d.head<3>() + xi_d.tail<3>().cross(c.p_W - g)) < 0;
    };
    bool blocking = false;
    if (r.dropped_contacts > 0) {
      // Equally near contacts (the corners of a flat region) by index, so the choice is
      // the same from pass to pass.
      const auto nearer = [&](int x, int y) {
        return contacts[x].distance < contacts[y].distance ||
               (contacts[x].distance == contacts[y].distance && x < y);
      };
      std::nth_element(pick.begin(), pick.begin() + ProxyResult::kMaxContacts,
                       pick.begin() + n_point, nearer);
      for (int i = ProxyResult::kMaxContacts; i < n_point; ++i)
        blocking = blocking || blocks(contacts[pick[static_cast<std::size_t>(i)]]);
      std::sort(pick.begin(), pick.begin() + ProxyResult::kMaxContacts);  // detection's order
      n_point = ProxyResult::kMaxContacts;
    }
    // Contact planes numbered afresh for the contacts used (detection's numbers run over all
    // its contacts, up to its capacity): at most kMaxContacts groups.
    for (int i = 0; i < n_point; ++i) {
      const int pl = contacts[pick[static_cast<std::size_t>(i)]].plane;
      if (pl >= 0) plane_group[static_cast<std::size_t>(pl)] = -1;
    }
    int num_groups = 0;
    m = 0;
    const Mat3 Winv_rot = X.R_BA * pm.Jinv_A * X.R_BA.transpose() / k;
    for (int i = 0; i < n_point; ++i) {
      const ContactPc& c = contacts[pick[static_cast<std::size_t>(i)]];
      const Vec3 rr = c.p_W - g;
      const int j = m++;
      used[static_cast<std::size_t>(j)] = c;
      dist[static_cast<std::size_t>(j)] = c.distance;
      if (c.plane < 0) {
        group[static_cast<std::size_t>(j)] = num_groups++;  // ungrouped: a plane of its own
      } else {
        std::int16_t& pg = plane_group[static_cast<std::size_t>(c.plane)];
        if (pg < 0) pg = static_cast<std::int16_t>(num_groups++);
        group[static_cast<std::size_t>(j)] = pg;
      }
      for (int axis = 0; axis < 3; ++axis) {
        const Vec3 dir = c.R_WT.col(axis == 0 ? 1 : axis == 1 ? 0 : 2);
        Row& row = rows[static_cast<std::size_t>(3 * j + axis)];
        row.a << dir, rr.cross(dir);
        row.Wa << dir / k, Winv_rot * rr.cross(dir);
        row.G = row.a.dot(row.Wa);
        row.inv_G = 1 / row.G;
        lambda[static_cast<std::size_t>(3 * j + axis)] = 0;
      }
      if (blocks(c)) blocking = true;
      for (int i = 0; i < s.num_warm; ++i)
        if (s.warm_pc[static_cast<std::size_t>(i)] == c.pc)
          for (int axis = 0; axis < 3; ++axis)
            lambda[static_cast<std::size_t>(3 * j + axis)] =
                s.warm_lambda[static_cast<std::size_t>(i)][static_cast<std::size_t>(axis)];
      bool slid = false;
      for (int i = 0; i < s.num_sliding && !slid; ++i)
        slid = s.sliding[static_cast<std::size_t>(i)] == c.pc;
      mu[static_cast<std::size_t>(j)] = q.friction ? (slid ? pm.mu_kinetic : pm.mu_static) : 0.0;
    }
    Vec6 xi = xi_d;
    if (blocking) {
      r.constrained = true;
      for (int i = 0; i < 3 * m; ++i)
        xi += rows[static_cast<std::size_t>(i)].Wa * lambda[static_cast<std::size_t>(i)];
      // A contact group (plane) whose loaded corners have all held their friction at the static
      // bound for kBreakawaySweeps sweeps breaks away: from then on its bounds are kinetic, as
      // they would be on the next pass. Gauss-Seidel converges very slowly on a region held at
      // the edge of static cones (the corners trade a torsional pair of forces), and polish would
      // only scale those forces down to kinetic ones anyway.
      std::array<int, ProxyResult::kMaxContacts> streak{};          // by group
      std::array<double, ProxyResult::kMaxContacts> load_before{};  // N, by group, a sweep ago
      const auto break_away = [&](Vec6& x) {
        if (!(pm.mu_kinetic < pm.mu_static)) return;
        std::array<bool, ProxyResult::kMaxContacts> loaded, held, breaks;
        std::array<double, ProxyResult::kMaxContacts> load;
        for (int g = 0; g < num_groups; ++g) loaded[g] = false, held[g] = true, load[g] = 0;
        for (int j = 0; j < m; ++j) {
          const auto J = static_cast<std::size_t>(j);
          const auto g = static_cast<std::size_t>(group[J]);
          const double ln = lambda[3 * J];
          if (ln <= 0) continue;
          loaded[g] = true;
          load[g] += ln;
          if (!(mu[J] == pm.mu_static &&
                at_friction_bound(lambda[3 * J + 1], lambda[3 * J + 2], mu[J], ln)))
            held[g] = false;
        }
        // And its load settled (the group's total within kSettledLoad of a sweep ago): while
        // loads still grow (a fresh contact, a harder press) friction can sit at mu_s times a
        // partial load of a region that sticks. (The corners' shares may still move: they
        // trade load as they trade the torsional pair.)
        bool any = false;
        for (int g = 0; g < num_groups; ++g) {
          const bool settled = std::abs(load[g] - load_before[g]) <= kSettledLoad * load[g];
          load_before[g] = load[g];
          streak[g] = loaded[g] && held[g] && settled ? streak[g] + 1 : 0;
          breaks[g] = streak[g] >= kBreakawaySweeps;
          any = any || breaks[g];
        }
        if (!any) return;
        const double sc = pm.mu_kinetic / pm.mu_static;
        for (int j = 0; j < m; ++j) {
          const auto J = static_cast<std::size_t>(j);
          if (!breaks[static_cast<std::size_t>(group[J])]) continue;
          mu[J] = pm.mu_kinetic;
          x += rows[3 * J + 1].Wa * (lambda[3 * J + 1] * (sc - 1)) +
               rows[3 * J + 2].Wa * (lambda[3 * J + 2] * (sc - 1));
          lambda[3 * J + 1] *= sc;
          lambda[3 * J + 2] *= sc;
        }
      };
      // Projected Gauss-Seidel on the constraint forces (N): xi = xi_d + W sum a_i lambda_i.
      for (int it = 0; it < q.solver_iterations; ++it) {
        ++r.iterations;
        double change = 0;  // mm, largest displacement a row's update made
        for (int j = 0; j < m; ++j) {
          const auto J = static_cast<std::size_t>(j);
          Row& rn = rows[3 * J];
          double& ln = lambda[3 * J];
          const double ln_new = std::max(0.0, ln - (dist[J] + rn.a.dot(xi)) * rn.inv_G);
          xi += rn.Wa * (ln_new - ln);
          change = std::max(change, std::abs(ln_new - ln) * rn.G);
          ln = ln_new;
          if (mu[J] == 0) continue;
          Row& r1 = rows[3 * J + 1];
          Row& r2 = rows[3 * J + 2];
          double& l1 = lambda[3 * J + 1];
          double& l2 = lambda[3 * J + 2];
          double n1 = l1 - r1.a.dot(xi) * r1.inv_G, n2 = l2 - r2.a.dot(xi) * r2.inv_G;
          // sqrt, not hypot: the forces are far from overflow, and hypot is several times slower.
          const double cap = mu[J] * ln, len2 = n1 * n1 + n2 * n2;
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
        if (change < kSolveTolerance_mm) break;
        break_away(xi);
      }
      xi = polish(xi, xi_d, rows.data(), lambda.data(), dist.data(), mu.data(), group.data(), m, k,
                  Winv_rot, pm.mu_kinetic, slides.data());
      // A group that broke away slides for the rest of the tick (kinetic bounds in the
      // passes after this one), not only from the next tick on.
      for (int j = 0; j < m; ++j) {
        const Pc& pc = used[static_cast<std::size_t>(j)].pc;
        if (!slides[static_cast<std::size_t>(group[static_cast<std::size_t>(j)])]) continue;
        bool known = false;
        for (int i = 0; i < s.num_sliding && !known; ++i)
          known = s.sliding[static_cast<std::size_t>(i)] == pc;
        if (!known && s.num_sliding < ProxyResult::kMaxContacts)
          s.sliding[static_cast<std::size_t>(s.num_sliding++)] = pc;
      }
      remember_forces();  // the next pass of this tick starts from them
    }
    const double sweep = xi.head<3>().norm() + xi.tail<3>().norm() * pm.reach_mm;
    if (sweep > step_len) {
      // Too long to be sure of: advance by step_len and look again; a translation as far as
      // the lookahead band shows it free. (A turn's contacts in the band would be linearised
      // about points up to the band's width from where they touch: turns advance by step_len.)
      const bool translation = xi.tail<3>().norm() * pm.reach_mm <= 1e-6 * step_len;
      const double f = pm.look && translation ? look_ahead(X, xi.head<3>()) : step_len / sweep;
      X = moved(X, g_A, f * xi.head<3>(), f * xi.tail<3>());
      continue;
    }
    if (!blocking) {
      X = X_WD;  // nothing in the way: the proxy is the device, exactly
      slides.fill(false);
      for (int i = 0; i < 3 * m; ++i) lambda[static_cast<std::size_t>(i)] = 0;
      break;
    }
    X = moved(X, g_A, xi.head<3>(), xi.tail<3>());
    // Done when the new pose keeps every point contact within the allowed depth; otherwise
    // (a rotation's second-order error, a contact the linearisation misjudged) another pass
    // pushes it out. The detection is the one the stages then use at this pose (cached).
    double deepest = 0;
    for (const ContactPc& c : detect_at(dm, ds, X, at))
      if (is_point_type(c.pc.type)) deepest = std::min(deepest, c.distance);
    if (deepest >= -q.max_penetration_mm) break;
  }
  s.X_WP = X;
  r.X_WP = X;
  // The last solve's constraint forces: reported, and the contacts that slid remembered.
  const Vec3 g_P = grip(X, g_A);
  r.F_constraint_W.setZero();
  r.M_constraint_W.setZero();
  s.num_sliding = 0;
  remember_forces();  // the next tick starts from them
  for (int j = 0; j < m; ++j) {
    const auto J = static_cast<std::size_t>(j);
    const ContactPc& c = used[J];
    const double ln = lambda[3 * J];
    ProxyContact& pc = r.contacts[static_cast<std::size_t>(r.num_contacts++)];
    pc.pc = c.pc;
    pc.p_W = c.p_W;
    pc.n_W = c.R_WT.col(1);
    pc.distance_mm = c.distance;
    pc.normal_load_N = ln;
    pc.friction_W = lambda[3 * J + 1] * c.R_WT.col(0) + lambda[3 * J + 2] * c.R_WT.col(2);
    pc.sliding = ln > 0 && mu[J] > 0 && slides[static_cast<std::size_t>(group[J])];
    if (pc.sliding) s.sliding[static_cast<std::size_t>(s.num_sliding++)] = c.pc;
    const Vec3 f = ln * pc.n_W + pc.friction_W;
    r.F_constraint_W += f;
    r.M_constraint_W += (c.p_W - g_P).cross(f);
  }
  // The coupling on the hand, about the grip point at the device: spring and damper.
  const Vec3 g_D = grip(X_WD, g_A);
  const Mat3 J_W = X_WD.R_BA * pm.J_A * X_WD.R_BA.transpose();
  const Vec3 theta = rotation_vector(X.R_BA * X_WD.R_BA.transpose());  // device to proxy
  r.F_coupling_W = k * (g_P - g_D);
  r.M_coupling_W = k * (J_W * theta);
  const double dt = t_s - s.t_prev_s;
  if (s.has_prev && dt > 0 && q.damping_N_s_per_mm > 0) {
    const Vec3 dv = (g_P - grip(s.X_WP_prev, g_A)) - (g_D - grip(s.X_WD_prev, g_A));
    const Vec3 dw = rotation_vector(X.R_BA * s.X_WP_prev.R_BA.transpose()) -
                    rotation_vector(X_WD.R_BA * s.X_WD_prev.R_BA.transpose());
    r.F_coupling_W += q.damping_N_s_per_mm * dv / dt;
    r.M_coupling_W += q.damping_N_s_per_mm * (J_W * dw) / dt;
  }
  s.has_prev = true;
  s.X_WP_prev = X;
  s.X_WD_prev = X_WD;
  s.t_prev_s = t_s;
}

}  // namespace cf::detail

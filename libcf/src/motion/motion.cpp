// Freedoms of a CF (contact constraint null space) and the prior-motion classification of
// paper section 4.2. See docs/force-model.md.

#include <cf/motion.hpp>

#include "check.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <string>

namespace cf {

const char* to_string(MotionType type) {
  switch (type) {
    case MotionType::kNone:
      return "none";
    case MotionType::kMT1:
      return "MT1";
    case MotionType::kMT2a:
      return "MT2.a";
    case MotionType::kMT2b:
      return "MT2.b";
    case MotionType::kMT2c:
      return "MT2.c";
    case MotionType::kMT3:
      return "MT3";
    case MotionType::kMT4:
      return "MT4";
    case MotionType::kMT5:
      return "MT5";
  }
  return "none";
}

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// Unit direction of the contact line of a line PC in the world.
Vec3 line_direction(const ContactPc& c, const Polyhedron& A, const Polyhedron& B,
                    const Pose& pose) {
  if (c.pc.type == PcType::kEF) return pose.R_BA * A.edge(EdgeId(c.pc.a)).dir;
  return B.edge(EdgeId(c.pc.b)).dir;  // f-e
}

}  // namespace

Freedoms compute_freedoms(const ContactPc* pcs, int n, const Polyhedron& A, const Polyhedron& B,
                          const Pose& pose, const Params& params) {
  constexpr double kLeastSizeMm = 1e-9;  // a model of no size still gets a length scale
  const double L = std::max(A.size(), kLeastSizeMm);
  ConstraintPoint pts[Freedoms::kMaxRows];
  int rows = 0;
  auto add = [&](const Vec3& q, const Vec3& nrm) {
    if (rows < Freedoms::kMaxRows) pts[rows++] = {q, nrm};
  };
  for (int i = 0; i < n; ++i) {
    const ContactPc& c = pcs[i];
    const Vec3 nrm = c.R_WT.col(1);
    add(c.p_W, nrm);
    switch (extent(c.pc.type)) {
      case PcExtent::kPoint:
        break;
      case PcExtent::kLine:
        add(c.p_W + L * line_direction(c, A, B, pose), nrm);
        break;
      case PcExtent::kPlane:
        // Any three non-collinear points of the plane span the same constraints as the
        // corners of the contact region (the constraint is affine in the point).
        add(c.p_W + L * c.R_WT.col(0), nrm);
        add(c.p_W + L * c.R_WT.col(2), nrm);
        break;
    }
  }
  return freedoms_from_points(pts, rows, pose.t_BA, L, params);
}

Freedoms freedoms_from_points(const ConstraintPoint* pts, int n, const Vec3& reference_W,
                              double length_scale, const Params& params) {
  CF_REQUIRE(n >= 0 && n <= Freedoms::kMaxRows, "computing freedoms: at most " +
                                                    std::to_string(Freedoms::kMaxRows) +
                                                    " constraint points, got " + std::to_string(n));
  CF_REQUIRE(length_scale > 0, "computing freedoms: the length scale must be positive, got " +
                                   std::to_string(length_scale));
  Freedoms f;
  const double L = length_scale;
  f.length_scale = L;
  f.reference_W = reference_W;

  // Rows n . v + ((q - ref) x n / L) . (L w) = 0, one per constraint point q.
  Eigen::Matrix<double, Freedoms::kMaxRows, 6> J =
      Eigen::Matrix<double, Freedoms::kMaxRows, 6>::Zero();
  int rows = 0;
  for (int i = 0; i < n; ++i, ++rows) {
    J.row(rows).head<3>() = pts[i].n_W.transpose();
    J.row(rows).tail<3>() = ((pts[i].p_W - f.reference_W).cross(pts[i].n_W) / L).transpose();
  }
  f.num_constraints = rows;

  const Mat6 JtJ = J.transpose() * J;
  Eigen::SelfAdjointEigenSolver<Mat6> es(JtJ);
  const auto& lam = es.eigenvalues();  // ascending
  const double sigma_max = std::sqrt(std::max(lam(5), 0.0));
  const double tol = params.freedom_rank_tolerance * std::max(sigma_max, 1.0);
  int dof = 0;
  while (dof < 6 && std::sqrt(std::max(lam(dof), 0.0)) <= tol) ++dof;
  f.dof = dof;
  f.basis = es.eigenvectors();  // the first dof columns span the free twists

  // Pure translations: null space of the v-block of J.
  {
    const Eigen::Matrix3d JvtJv = J.leftCols<3>().transpose() * J.leftCols<3>();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ev(JvtJv);
    int t = 0;
    while (t < 3 && std::sqrt(std::max(ev.eigenvalues()(t), 0.0)) <= tol) ++t;
    f.translation_dof = t;
  }

  // Pure rotation: a free twist with w != 0 and v . w = 0. With Z the free basis and
  // Q = sym(Zv^T Zw), v . w = a^T Q a: an indefinite Q has isotropic vectors outside the
  // pure translations; a semidefinite Q has them exactly on its null space.
  f.pure_rotation = false;
  if (dof > 0) {
    using MatQ = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
    using VecQ = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
    const auto Zv = f.basis.topLeftCorner(3, dof);
    const auto Zw = f.basis.bottomLeftCorner(3, dof);
    MatQ Q(dof, dof);
    Q.noalias() = Zv.transpose() * Zw;
    const MatQ Qs = 0.5 * (Q + Q.transpose());
    Eigen::SelfAdjointEigenSolver<MatQ> eq(Qs);
    const auto& ql = eq.eigenvalues();
    const double qtol = params.freedom_rank_tolerance;
    VecQ alpha(dof);
    bool found = false;
    auto try_alpha = [&](const VecQ& a) {
      if (found) return;
      const Vec3 wl = Zw * a;
      constexpr double kNonzero = 1e-300;  // any a that is not exactly zero
      if (wl.norm() > qtol * std::max(a.norm(), kNonzero)) {
        alpha = a;
        found = true;
      }
    };
    if (ql(0) < -qtol && ql(dof - 1) > qtol) {
      const VecQ e1 = eq.eigenvectors().col(dof - 1) / std::sqrt(ql(dof - 1));
      const VecQ e2 = eq.eigenvectors().col(0) / std::sqrt(-ql(0));
      try_alpha(e1 + e2);
      try_alpha(e1 - e2);
    } else {
      // Semidefinite: the zero set is the null space of Q; pick its member with the largest
      // rotation part.
      double best = 0;
      int best_i = -1;
      for (int i = 0; i < dof; ++i) {
        if (std::abs(ql(i)) > qtol) continue;
        const double wn = (Zw * eq.eigenvectors().col(i)).norm();
        if (wn > best) {
          best = wn;
          best_i = i;
        }
      }
      if (best_i >= 0) try_alpha(eq.eigenvectors().col(best_i));
    }
    if (found) {
      f.pure_rotation = true;
      const Vec3 v = Zv * alpha;
      const Vec3 w = Zw * alpha / L;
      f.rotation_axis_W = w.normalized();
      f.rotation_point_W = f.reference_W + w.cross(v) / w.squaredNorm();
    }
  }
  return f;
}

MotionCheck check_motion(const Freedoms& f, const Pose& prev, const Pose& cur,
                         const Params& params) {
  MotionCheck m;
  const Eigen::AngleAxisd aa(Mat3(cur.R_BA * prev.R_BA.transpose()));
  const Vec3 rot = aa.axis() * aa.angle();
  m.rotation_rad = std::abs(aa.angle());
  m.translation_W = cur.t_BA - prev.t_BA;
  const double L = f.length_scale;
  Vec6 xi;
  xi.head<3>() = m.translation_W;
  xi.tail<3>() = L * rot;
  m.moved = m.translation_W.norm() + L * m.rotation_rad > params.motion_noise_mm;
  if (!m.moved) return m;

  const int k = f.dof;
  Vec6 proj = Vec6::Zero();
  if (k > 0) {
    const auto Z = f.basis.leftCols(k);
    proj.noalias() = Z * (Z.transpose() * xi);
  }
  m.twist_angle_rad = std::atan2((xi - proj).norm(), proj.norm());

  if (L * m.rotation_rad > params.motion_noise_mm) {
    // Possible rotation axes: the span of the rotation parts of the free twists.
    Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
    if (k > 0) W = f.basis.bottomLeftCorner(3, k) * f.basis.bottomLeftCorner(3, k).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ew(W);
    const Vec3 u = rot.normalized();
    Vec3 pu = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      if (ew.eigenvalues()(i) > params.freedom_rank_tolerance) {
        const Vec3 e = ew.eigenvectors().col(i);
        pu += e * e.dot(u);
      }
    }
    m.rotation_angle_rad = std::atan2((u - pu).norm(), pu.norm());
  }
  m.along = m.twist_angle_rad <= params.motion_angle_tolerance_rad &&
            m.rotation_angle_rad <= params.motion_angle_tolerance_rad;
  return m;
}

namespace {

bool subset_of(const PcSet& small, const PcSet& big) {
  for (const Pc& p : small)
    if (!big.contains(p)) return false;
  return true;
}

int first_not_in(const PcSet& cur, const PcSet& prev) {
  for (int i = 0; i < cur.size(); ++i)
    if (!prev.contains(cur[i])) return i;
  return -1;
}

}  // namespace

PriorMotion classify_prior_motion(const PcSet& prev, const PcSet& cur, const CfGraph* graph,
                                  CfId prev_id, CfId cur_id) {
  PriorMotion pm;
  if (cur.empty()) return pm;
  if (prev.empty()) {
    pm.type = MotionType::kMT1;
    return pm;
  }
  if (prev == cur) {
    pm.type = MotionType::kMT2a;  // the case is refined by the force model
    return pm;
  }
  if (graph != nullptr && prev_id.valid() && cur_id.valid() && prev_id.index() < graph->num_cfs() &&
      cur_id.index() < graph->num_cfs()) {
    for (const Transition& tr : graph->out_transitions(prev_id)) {
      if (tr.to != cur_id) continue;
      switch (tr.kind) {
        case TransitionKind::kGain:
          pm.type = MotionType::kMT4;
          pm.gained = first_not_in(cur, prev);
          break;
        case TransitionKind::kLose:
          pm.type = MotionType::kMT5;
          break;
        case TransitionKind::kChange:
          pm.type = MotionType::kMT3;
          break;
      }
      return pm;
    }
    // docs/spec.md, section 4: `lose` is any proper, non-empty subset of the CF (paper 3.1: "more
    // than one PC can be broken at the same time"); the graph lists the single losses, the run time
    // derives the rest from the PC sets of two CFs of the graph.
    if (cur.size() < prev.size() && subset_of(cur, prev)) {
      pm.type = MotionType::kMT5;
      return pm;
    }
    pm.transition_in_graph = false;
  } else if (graph != nullptr) {
    pm.transition_in_graph = false;
  }
  // Set relation (no graph, or a pair the graph does not list).
  if (cur.size() == prev.size() + 1 && subset_of(prev, cur)) {
    pm.type = MotionType::kMT4;
    pm.gained = first_not_in(cur, prev);
  } else if (cur.size() < prev.size() && subset_of(cur, prev)) {
    pm.type = MotionType::kMT5;
  } else if (cur.size() == prev.size()) {
    pm.type = MotionType::kMT3;
  } else {
    // Two PCs gained at once, or a change together with a gain or loss: none of MT3..MT5.
    pm.type = MotionType::kNone;
    pm.transition_in_graph = false;
  }
  return pm;
}

}  // namespace cf

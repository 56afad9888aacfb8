#include "cfgen/decide/explore.hpp"

#include "cfgen/verify/touch.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>

#include <cmath>
#include <limits>

namespace cf::gen {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Point p moving along unit d meets the closed segment [q0, q1] first at s; kInf when never.
// Pairs that already touch (s <= s_min) are ignored.
double point_segment_hit(const Vec3& p, const Vec3& d, const Vec3& q0, const Vec3& q1, double s_min,
                         double tol) {
  const Vec3 e = q1 - q0;
  const double len = e.norm();
  if (len == 0) return kInf;
  const Vec3 eu = e / len;
  const Vec3 c = d.cross(eu);
  if (c.norm() < 1e-9) {
    // Moving along the segment's line: a hit only when on that line.
    const Vec3 w = p - q0;
    if ((w - w.dot(eu) * eu).norm() > tol) return kInf;
    const double s0 = (q0 - p).dot(d), s1 = (q1 - p).dot(d);
    if (std::min(s0, s1) <= s_min && std::max(s0, s1) >= -s_min) return kInf;  // already on it
    const double s = std::min(s0, s1);
    return s > s_min ? s : kInf;
  }
  // p + s d = q0 + w eu, least squares in (s, w); a hit when the residual vanishes.
  Eigen::Matrix<double, 3, 2> M;
  M.col(0) = d;
  M.col(1) = -eu;
  const Eigen::Vector2d x = (M.transpose() * M).ldlt().solve(M.transpose() * (q0 - p));
  if ((p + x[0] * d - q0 - x[1] * eu).norm() > tol) return kInf;
  if (x[1] < -tol || x[1] > len + tol || x[0] <= s_min) return kInf;
  return x[0];
}

// Null space of the rows of N (unit vectors), as an orthonormal basis.
std::vector<Vec3> null_space(const std::vector<Vec3>& rows) {
  if (rows.empty()) return {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  Eigen::MatrixXd N(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i)
    N.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(N, Eigen::ComputeFullV);
  int rank = 0;
  for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > 1e-9) ++rank;
  std::vector<Vec3> out;
  for (int i = rank; i < 3; ++i) out.push_back(svd.matrixV().col(i));
  return out;
}

}  // namespace

double first_contact_translation(const Polyhedron& A, const Polyhedron& B, const Pose& pose,
                                 const Vec3& d, double s_min, double s_max, double tol,
                                 const PcSet& kept) {
  // Events between elements that the kept PCs dominate do not change the contact set.
  auto dominated = [&](ElementKind ka, int a, ElementKind kb, int b) {
    return covered_by(A, B, kept, ka, a, kb, b);
  };
  double best = s_max;
  bool hit = false;
  auto take = [&](double s) {
    if (s > s_min && s < best) {
      best = s;
      hit = true;
    }
  };
  std::vector<Vec3> pa(A.num_vertices());
  for (std::size_t i = 0; i < pa.size(); ++i) pa[i] = pose.apply(A.vertices()[i].p);
  // A translation along d keeps the coordinates across d (along e1, e2): a vertex can reach a
  // face only where its coordinates lie in the face's range of them, and two edges can meet
  // only where their ranges overlap. A face's range is tested before the point is located in
  // the face (most of the work, on parts of many faces).
  const Vec3 e1 = d.unitOrthogonal(), e2 = d.cross(e1);
  const double cross_slack = 2 * tol + 1e-9 * std::max(A.size(), B.size());  // rounding, mm
  std::vector<Eigen::Vector2d> ca(pa.size()), cb(B.num_vertices());
  for (std::size_t i = 0; i < pa.size(); ++i) ca[i] = {e1.dot(pa[i]), e2.dot(pa[i])};
  for (std::size_t i = 0; i < cb.size(); ++i)
    cb[i] = {e1.dot(B.vertices()[i].p), e2.dot(B.vertices()[i].p)};
  // A face's range across d, grown by the slack, from its vertices' coordinates.
  auto range_of = [&](const Face& F, const std::vector<Eigen::Vector2d>& c) {
    Eigen::AlignedBox2d r;
    for (VertexId v : F.vertices) r.extend(c[v.index()]);
    r.min().array() -= cross_slack;
    r.max().array() += cross_slack;
    return r;
  };
  // Vertices of A against faces of B (closed: a vertex reaching an edge or a vertex of B too).
  for (std::size_t f = 0; f < B.num_faces(); ++f) {
    const Face& F = B.faces()[f];
    const double nd = F.normal.dot(d);
    if (std::abs(nd) < 1e-9) continue;
    const Eigen::AlignedBox2d range = range_of(F, cb);
    for (std::size_t v = 0; v < pa.size(); ++v) {
      const double s = (F.offset - F.normal.dot(pa[v])) / nd;
      if (s <= s_min || s >= best || !range.contains(ca[v])) continue;
      if (dominated(ElementKind::kVertex, int(v), ElementKind::kFace, int(f))) continue;
      if (B.face_inset(FaceId(int(f)), pa[v] + s * d) >= -tol) take(s);
    }
  }
  // Vertices of B against faces of A, in A's frame (B moves by -R^T d there); the ranges
  // across d in B's frame, A's faces posed.
  const Vec3 dA = -(pose.R_BA.transpose() * d);
  for (std::size_t f = 0; f < A.num_faces(); ++f) {
    const Face& F = A.faces()[f];
    const double nd = F.normal.dot(dA);
    if (std::abs(nd) < 1e-9) continue;
    const Eigen::AlignedBox2d range = range_of(F, ca);
    for (std::size_t v = 0; v < B.num_vertices(); ++v) {
      if (!range.contains(cb[v])) continue;
      const Vec3 q = pose.inverse_apply(B.vertices()[v].p);
      const double s = (F.offset - F.normal.dot(q)) / nd;
      if (s <= s_min || s >= best) continue;
      if (dominated(ElementKind::kFace, int(f), ElementKind::kVertex, int(v))) continue;
      if (A.face_inset(FaceId(int(f)), q + s * dA) >= -tol) take(s);
    }
  }
  // Edges against edges: p0 + u ua + s d = q0 + w ub, where their ranges across d overlap
  // and B's edge lies ahead of A's by a shift in (s_min, best].
  struct Box {
    double lo[3], hi[3];  // along e1, e2, d
  };
  // An edge's box from its ends: their coordinates across d (computed above) and along d.
  auto box_of = [&](const Eigen::Vector2d& c0, const Eigen::Vector2d& c1, const Vec3& a,
                    const Vec3& b) {
    Box x;
    const double u[3] = {c0[0], c0[1], d.dot(a)}, w[3] = {c1[0], c1[1], d.dot(b)};
    for (int k = 0; k < 3; ++k) {
      x.lo[k] = std::min(u[k], w[k]);
      x.hi[k] = std::max(u[k], w[k]);
    }
    return x;
  };
  std::vector<Box> b_boxes(B.num_edges());
  for (std::size_t eb = 0; eb < B.num_edges(); ++eb) {
    const Edge& E = B.edges()[eb];
    b_boxes[eb] = box_of(cb[E.v0.index()], cb[E.v1.index()], B.vertex(E.v0).p, B.vertex(E.v1).p);
  }
  const double slack = 2 * tol;
  for (std::size_t ea = 0; ea < A.num_edges(); ++ea) {
    const Vec3& p0 = pa[A.edges()[ea].v0.index()];
    const Vec3& p1 = pa[A.edges()[ea].v1.index()];
    const Vec3 ua = p1 - p0;
    const Box ba = box_of(ca[A.edges()[ea].v0.index()], ca[A.edges()[ea].v1.index()], p0, p1);
    for (std::size_t eb = 0; eb < B.num_edges(); ++eb) {
      const Box& bb = b_boxes[eb];
      if (bb.lo[0] > ba.hi[0] + slack || ba.lo[0] > bb.hi[0] + slack ||
          bb.lo[1] > ba.hi[1] + slack || ba.lo[1] > bb.hi[1] + slack ||
          bb.hi[2] - ba.lo[2] < s_min - slack || bb.lo[2] - ba.hi[2] > best + slack)
        continue;
      if (dominated(ElementKind::kEdge, int(ea), ElementKind::kEdge, int(eb))) continue;
      const Vec3& q0 = B.edge_point(EdgeId(int(eb)), 0);
      const Vec3& q1 = B.edge_point(EdgeId(int(eb)), 1);
      const Vec3 ub = q1 - q0;
      Mat3 M;
      M.col(0) = ua;
      M.col(1) = -ub;
      M.col(2) = d;
      const double det = M.determinant();
      if (std::abs(det) > 1e-9 * ua.norm() * ub.norm()) {
        const Vec3 x = M.inverse() * (q0 - p0);
        const double eu = tol / ua.norm(), ew = tol / ub.norm();
        if (x[0] >= -eu && x[0] <= 1 + eu && x[1] >= -ew && x[1] <= 1 + ew) take(x[2]);
        continue;
      }
      // Coplanar motion or parallel edges: the first meeting involves an end point.
      take(point_segment_hit(p0, d, q0, q1, s_min, tol));
      take(point_segment_hit(p1, d, q0, q1, s_min, tol));
      take(point_segment_hit(q0, -d, p0, p1, s_min, tol));
      take(point_segment_hit(q1, -d, p0, p1, s_min, tol));
    }
  }
  return hit ? best : kInf;
}

std::vector<Pose> turned_witnesses(const WitnessSearch& search, const PcSet& pcs,
                                   const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  std::vector<Vec3> points;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF:
        points.push_back(witness.apply(A.vertices()[pc.a].p));
        break;
      case PcType::kFV:
        points.push_back(B.vertices()[pc.b].p);
        break;
      case PcType::kEE:
        points.push_back(
            element_distance(A, witness, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b)
                .p_b);
        break;
      default:
        return {};  // line and plane PCs leave no rotation about a point free
    }
  }
  // Turns that keep the contact points fixed: about any axis through a single point, about
  // the line through two.
  std::vector<std::pair<Vec3, double>> turns;
  if (points.size() == 1) {
    static const Vec3 kAxes[] = {Vec3(1, 0, 0),
                                 Vec3(0, 1, 0),
                                 Vec3(0, 0, 1),
                                 Vec3(1, 1, 0).normalized(),
                                 Vec3(0, 1, -1).normalized(),
                                 Vec3(-1, 0, 1).normalized()};
    for (const Vec3& ax : kAxes)
      for (double ang : {0.25, -0.25, 0.6, -0.6}) turns.push_back({ax, ang});
  } else if (points.size() == 2 && (points[1] - points[0]).norm() > 1e-6 * search.scale()) {
    const Vec3 ax = (points[1] - points[0]).normalized();
    for (double ang : {0.15, -0.15, 0.4, -0.4}) turns.push_back({ax, ang});
  }
  std::vector<Pose> out;
  for (const auto& [ax, ang] : turns) {
    const Mat3 Q = Eigen::AngleAxisd(ang, ax).toRotationMatrix();
    Pose q;
    q.R_BA = Q * witness.R_BA;
    q.t_BA = Q * (witness.t_BA - points[0]) + points[0];
    PcSet now;
    if (search.contacts_at(q, now) && now == pcs &&
        search.verify(pcs, q) >= search.params().min_clearance)
      out.push_back(q);
  }
  return out;
}

std::vector<Discovery> explore_translations(const WitnessSearch& search, const PcSet& pcs,
                                            const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  const SearchParams& p = search.params();
  const double tol = p.touch_tol;
  const double s_min = 10 * tol;
  const double s_max = 4 * (A.size() + B.size());
  std::vector<Vec3> normals;
  for (const Pc& pc : pcs) normals.push_back(search.contact_plane(pc, witness).first);
  std::vector<Discovery> out;
  auto record = [&](const Pose& pose) {
    PcSet found;
    if (search.contacts_at(pose, found) && !found.empty() && found != pcs)
      out.push_back({found, pose});
  };
  // Follows d from the witness keeping `kept`: the pose just clear of the broken PCs (when
  // some break), then the first contact.
  auto follow = [&](const Vec3& d, const PcSet& kept, double break_rate) {
    const double s_hit = first_contact_translation(A, B, witness, d, s_min, s_max, tol, kept);
    if (break_rate > 0) {
      // Far enough that the broken PCs clear min_clearance, at most halfway to the next contact.
      const double s =
          std::min(0.5 * s_hit, std::max(10 * p.min_clearance, p.good_clearance) / break_rate);
      if (std::isfinite(s)) {
        Pose q = witness;
        q.t_BA += s * d;
        record(q);
      }
    }
    if (std::isfinite(s_hit)) {
      Pose q = witness;
      q.t_BA += s_hit * d;
      record(q);
    }
  };
  // Sliding: directions that keep every PC.
  const std::vector<Vec3> keep_all = null_space(normals);
  if (keep_all.size() == 2) {
    for (int k = 0; k < 8; ++k) {
      const double th = 0.3 + k * M_PI / 4;
      follow(std::cos(th) * keep_all[0] + std::sin(th) * keep_all[1], pcs, 0);
    }
  } else if (keep_all.size() == 1) {
    follow(keep_all[0], pcs, 0);
    follow(-keep_all[0], pcs, 0);
  }
  // Breaking a non-empty proper subset L of the PCs, keeping the others.
  const int n = pcs.size();
  for (int mask = 1; mask + 1 < (1 << n); ++mask) {
    PcSet kept;
    std::vector<Vec3> kept_normals, lost_normals;
    Vec3 g = Vec3::Zero();
    for (int j = 0; j < n; ++j)
      if (mask >> j & 1) {
        lost_normals.push_back(normals[j]);
        g += normals[j];
      } else {
        kept.insert(pcs[j]);
        kept_normals.push_back(normals[j]);
      }
    const std::vector<Vec3> basis = null_space(kept_normals);
    if (basis.empty()) continue;
    auto rate = [&](const Vec3& d) {
      double r = kInf;
      for (const Vec3& m : lost_normals) r = std::min(r, m.dot(d));
      return r;
    };
    std::vector<Vec3> dirs;
    Vec3 g_proj = Vec3::Zero();
    for (const Vec3& b : basis) g_proj += g.dot(b) * b;
    if (g_proj.norm() > 1e-9) dirs.push_back(g_proj.normalized());
    if (basis.size() == 2 && !dirs.empty()) {
      const Vec3 side = dirs[0].cross(basis[0].cross(basis[1])).normalized();
      for (double a : {-1.2, -0.6, 0.6, 1.2})
        dirs.push_back((std::cos(a) * dirs[0] + std::sin(a) * side).normalized());
    }
    if (basis.size() == 1) {
      dirs.push_back(basis[0]);
      dirs.push_back(-basis[0]);
    }
    for (const Vec3& d : dirs) {
      const double r = rate(d);
      if (r > 1e-6) follow(d, kept, r);
    }
  }
  return out;
}

}  // namespace cf::gen

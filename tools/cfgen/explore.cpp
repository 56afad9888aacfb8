#include "explore.hpp"

#include "touch.hpp"

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
double point_segment_hit(const Vec3& p, const Vec3& d, const Vec3& q0, const Vec3& q1,
                         double s_min, double tol) {
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
  for (std::size_t i = 0; i < rows.size(); ++i) N.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
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
  auto dominated = [&](ElementKind ka, int a, ElementKind kb, int b) { return covered_by(A, B, kept, ka, a, kb, b); };
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
  auto box_of = [&](const Eigen::Vector2d& c0, const Eigen::Vector2d& c1, const Vec3& a, const Vec3& b) {
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
      if (bb.lo[0] > ba.hi[0] + slack || ba.lo[0] > bb.hi[0] + slack || bb.lo[1] > ba.hi[1] + slack ||
          ba.lo[1] > bb.hi[1] + slack || bb.hi[2] - ba.lo[2] < s_min - slack || bb.lo[2] - ba.hi[2] > best + slack)
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

std::vector<Pose> turned_witnesses(const WitnessSearch& search, const PcSet& pcs, const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  std::vector<Vec3> points;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF: points.push_back(witness.apply(A.vertices()[pc.a].p)); break;
      case PcType::kFV: points.push_back(B.vertices()[pc.b].p); break;
      case PcType::kEE:
        points.push_back(element_distance(A, witness, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b).p_b);
        break;
      default:
        return {};  // line and plane PCs leave no rotation about a point free
    }
  }
  // Turns that keep the contact points fixed: about any axis through a single point, about
  // the line through two.
  std::vector<std::pair<Vec3, double>> turns;
  if (points.size() == 1) {
    static const Vec3 kAxes[] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                                 Vec3(1, 1, 0).normalized(), Vec3(0, 1, -1).normalized(), Vec3(-1, 0, 1).normalized()};
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
    if (search.contacts_at(q, now) && now == pcs && search.verify(pcs, q) >= search.params().min_clearance)
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
    if (search.contacts_at(pose, found) && !found.empty() && found != pcs) out.push_back({found, pose});
  };
  // Follows d from the witness keeping `kept`: the pose just clear of the broken PCs (when
  // some break), then the first contact.
  auto follow = [&](const Vec3& d, const PcSet& kept, double break_rate) {
    const double s_hit = first_contact_translation(A, B, witness, d, s_min, s_max, tol, kept);
    if (break_rate > 0) {
      // Far enough that the broken PCs clear min_clearance, at most halfway to the next contact.
      const double s = std::min(0.5 * s_hit, std::max(10 * p.min_clearance, p.good_clearance) / break_rate);
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
      for (double a : {-1.2, -0.6, 0.6, 1.2}) dirs.push_back((std::cos(a) * dirs[0] + std::sin(a) * side).normalized());
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


namespace {

// Rotation of A about the axis through p along unit u by phi, after `pose`.
Pose rotated(const Pose& pose, const Vec3& p, const Vec3& u, double phi) {
  const Mat3 Q = Eigen::AngleAxisd(phi, u).toRotationMatrix();
  Pose out;
  out.R_BA = Q * pose.R_BA;
  out.t_BA = Q * (pose.t_BA - p) + p;
  return out;
}

// Roots phi in (lo, hi] of a cos(phi) + b sin(phi) + c = 0.
void trig_roots(double a, double b, double c, double lo, double hi, std::vector<double>& out) {
  const double r = std::hypot(a, b);
  if (r < 1e-12 || std::abs(c) > r) return;
  const double base = std::atan2(b, a), delta = std::acos(std::clamp(-c / r, -1.0, 1.0));
  for (double phi : {base + delta, base - delta})
    for (int k = -2; k <= 2; ++k) {
      const double x = phi + 2 * M_PI * k;
      if (x > lo && x <= hi) out.push_back(x);
    }
}

}  // namespace

double first_contact_rotation(const Polyhedron& A, const Polyhedron& B, const Pose& pose, const Vec3& p,
                              const Vec3& u, double phi_min, double phi_max, double tol, const PcSet& kept) {
  auto dominated = [&](ElementKind ka, int a, ElementKind kb, int b) { return covered_by(A, B, kept, ka, a, kb, b); };
  double best = phi_max;
  bool hit = false;
  std::vector<double> roots;
  std::vector<Vec3> pa(A.num_vertices());
  for (std::size_t i = 0; i < pa.size(); ++i) pa[i] = pose.apply(A.vertices()[i].p);
  // A point x0 turning about (p, u): x(phi) = p + r_par + cos(phi) r_perp + sin(phi) u x r_perp.
  auto circle_plane = [&](const Vec3& x0, const Vec3& n, double d, double sign, std::vector<double>& out) {
    const Vec3 r = x0 - p, r_par = r.dot(u) * u, r_perp = r - r_par;
    const Vec3 w = sign * u.cross(r_perp);
    trig_roots(n.dot(r_perp), n.dot(w), n.dot(p + r_par) - d, phi_min, best, out);
  };
  auto on_circle = [&](const Vec3& x0, double phi) {
    const Vec3 r = x0 - p, r_par = r.dot(u) * u, r_perp = r - r_par;
    return Vec3(p + r_par + std::cos(phi) * r_perp + std::sin(phi) * u.cross(r_perp));
  };
  // A turning keeps each point's height along the axis and its distance from it: a vertex
  // can reach a face only where its height lies in the face's range of heights and its
  // distance is within the face's largest (both at the face's vertices, grown by the slack the
  // edges' test below keeps).
  const double turn_slack = 1e3 * tol + 1e-9 * std::max(A.size(), B.size());  // mm
  auto height_radius = [&](const Vec3& x) {
    const double z = (x - p).dot(u);
    return Eigen::Vector2d(z, ((x - p) - z * u).norm());
  };
  std::vector<Eigen::Vector2d> hra(pa.size()), hrb(B.num_vertices());
  for (std::size_t i = 0; i < pa.size(); ++i) hra[i] = height_radius(pa[i]);
  for (std::size_t i = 0; i < hrb.size(); ++i) hrb[i] = height_radius(B.vertices()[i].p);
  struct TurnRange {
    double z_lo, z_hi, r_hi;
    bool reaches(const Eigen::Vector2d& hr) const {
      return hr[0] >= z_lo && hr[0] <= z_hi && hr[1] <= r_hi;
    }
  };
  auto turn_range = [&](const Face& F, const std::vector<Eigen::Vector2d>& hr) {
    TurnRange t{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                0.0};
    for (VertexId v : F.vertices) {
      t.z_lo = std::min(t.z_lo, hr[v.index()][0]);
      t.z_hi = std::max(t.z_hi, hr[v.index()][0]);
      t.r_hi = std::max(t.r_hi, hr[v.index()][1]);
    }
    t.z_lo -= turn_slack;
    t.z_hi += turn_slack;
    t.r_hi += turn_slack;
    return t;
  };
  // Vertices of A against faces of B.
  for (std::size_t f = 0; f < B.num_faces(); ++f) {
    const Face& F = B.faces()[f];
    const TurnRange range = turn_range(F, hrb);
    for (std::size_t v = 0; v < pa.size(); ++v) {
      if (!range.reaches(hra[v])) continue;
      roots.clear();
      circle_plane(pa[v], F.normal, F.offset, 1.0, roots);
      for (double phi : roots) {
        if (phi >= best || dominated(ElementKind::kVertex, int(v), ElementKind::kFace, int(f))) continue;
        if (B.face_inset(FaceId(int(f)), on_circle(pa[v], phi)) >= -tol) {
          best = phi;
          hit = true;
        }
      }
    }
  }
  // Vertices of B against faces of A: seen from A, B turns by -phi about the same axis.
  for (std::size_t f = 0; f < A.num_faces(); ++f) {
    const Face& F = A.faces()[f];
    const Vec3 n = pose.R_BA * F.normal;
    const double d = F.offset + n.dot(pose.t_BA);
    const TurnRange range = turn_range(F, hra);
    for (std::size_t v = 0; v < B.num_vertices(); ++v) {
      if (!range.reaches(hrb[v])) continue;
      const Vec3& q = B.vertices()[v].p;
      roots.clear();
      const Vec3 r = q - p, r_par = r.dot(u) * u, r_perp = r - r_par;
      trig_roots(n.dot(r_perp), -n.dot(u.cross(r_perp)), n.dot(p + r_par) - d, phi_min, best, roots);
      for (double phi : roots) {
        if (phi >= best || dominated(ElementKind::kFace, int(f), ElementKind::kVertex, int(v))) continue;
        const Vec3 qr = p + r_par + std::cos(phi) * r_perp - std::sin(phi) * u.cross(r_perp);
        if (A.face_inset(FaceId(int(f)), pose.inverse_apply(qr)) >= -tol) {
          best = phi;
          hit = true;
        }
      }
    }
  }
  // Edges against edges: the lines meet where g(phi) = (q0 - x0(phi)) . ((x1 - x0)(phi) x ub) = 0,
  // a trigonometric polynomial of degree 2 (six coefficients per pair); its sign changes on a
  // fine sampling are refined by bisection, then checked on the segments.
  constexpr int kSamples = 192;
  // The samples' angles, cosines and sines, kept per thread for the last range asked for:
  // the closure turns over the same range every time, and computing them takes 193 sincos
  // (and the angles a division each, for every pair of edges).
  struct SampleTable {
    bool set = false;
    double phi_min = 0, phi_max = 0;
    double phi[kSamples + 1];
    double cs[kSamples + 1][2];
  };
  thread_local SampleTable table;
  if (!table.set || table.phi_min != phi_min || table.phi_max != phi_max) {
    table.set = true;
    table.phi_min = phi_min;
    table.phi_max = phi_max;
    for (int k = 0; k <= kSamples; ++k) {
      const double phi = phi_min + (phi_max - phi_min) * k / kSamples;
      table.phi[k] = phi;
      table.cs[k][0] = std::cos(phi);
      table.cs[k][1] = std::sin(phi);
    }
  }
  const auto& cs = table.cs;
  const auto& phis = table.phi;
  // x(phi) = P + cos(phi) C + sin(phi) S for a point turning about (p, u).
  auto circle = [&](const Vec3& x0, Vec3& P, Vec3& C, Vec3& S) {
    const Vec3 r = x0 - p, r_par = r.dot(u) * u;
    P = p + r_par;
    C = r - r_par;
    S = u.cross(C);
  };
  // A turning keeps each point's height along the axis and its distance from it: an edge of
  // A can meet an edge of B only where their [height] and [distance] ranges overlap.
  struct AxisBox {
    double z_lo, z_hi, r_lo, r_hi;
  };
  auto axis_box = [&](const Vec3& a, const Vec3& b) {
    const double za = (a - p).dot(u), zb = (b - p).dot(u);
    const Vec3 ra = (a - p) - za * u, rb = (b - p) - zb * u;
    const Vec3 dr = rb - ra;
    const double s = dr.squaredNorm() > 0 ? std::clamp(-ra.dot(dr) / dr.squaredNorm(), 0.0, 1.0) : 0.0;
    return AxisBox{std::min(za, zb), std::max(za, zb), (ra + s * dr).norm(), std::max(ra.norm(), rb.norm())};
  };
  std::vector<AxisBox> b_boxes(B.num_edges());
  for (std::size_t eb = 0; eb < B.num_edges(); ++eb)
    b_boxes[eb] = axis_box(B.edge_point(EdgeId(int(eb)), 0), B.edge_point(EdgeId(int(eb)), 1));
  const double reach = 1e3 * tol;  // as the segment check below
  for (std::size_t ea = 0; ea < A.num_edges(); ++ea) {
    Vec3 P0, C0, S0, P1, C1, S1;
    const Vec3& a0 = pa[A.edges()[ea].v0.index()];
    const Vec3& a1 = pa[A.edges()[ea].v1.index()];
    const AxisBox box = axis_box(a0, a1);
    circle(a0, P0, C0, S0);
    circle(a1, P1, C1, S1);
    const Vec3 D[3] = {P1 - P0, C1 - C0, S1 - S0};
    for (std::size_t eb = 0; eb < B.num_edges(); ++eb) {
      const AxisBox& bb = b_boxes[eb];
      if (bb.z_lo > box.z_hi + reach || box.z_lo > bb.z_hi + reach || bb.r_lo > box.r_hi + reach ||
          box.r_lo > bb.r_hi + reach)
        continue;
      if (dominated(ElementKind::kEdge, int(ea), ElementKind::kEdge, int(eb))) continue;
      const Vec3& q0 = B.edge_point(EdgeId(int(eb)), 0);
      const Vec3& q1 = B.edge_point(EdgeId(int(eb)), 1);
      const Vec3 ub = q1 - q0;
      const Vec3 E[3] = {q0 - P0, -C0, -S0};
      double M[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) M[i][j] = E[i].dot(D[j].cross(ub));
      const double k0 = M[0][0], kc = M[1][0] + M[0][1], ks = M[2][0] + M[0][2], kcc = M[1][1],
                   kss = M[2][2], kcs = M[1][2] + M[2][1];
      auto g = [&](double c, double s) { return k0 + c * (kc + c * kcc + s * kcs) + s * (ks + s * kss); };
      auto g_at = [&](double phi) { return g(std::cos(phi), std::sin(phi)); };
      double prev = g(cs[0][0], cs[0][1]);
      for (int k = 1; k <= kSamples; ++k) {
        const double lo0 = phis[k - 1];
        if (lo0 >= best) break;
        const double val = g(cs[k][0], cs[k][1]);
        if ((prev <= 0) != (val <= 0)) {
          double lo = lo0, hi = phis[k], glo = prev;
          for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi), gm = g_at(mid);
            if ((glo <= 0) == (gm <= 0)) {
              lo = mid;
              glo = gm;
            } else {
              hi = mid;
            }
          }
          if (hi < best) {
            const ClosestPoints cp = segment_segment(on_circle(pa[A.edges()[ea].v0.index()], hi),
                                                     on_circle(pa[A.edges()[ea].v1.index()], hi), q0, q1);
            if (cp.distance <= 1e3 * tol) {
              best = hi;
              hit = true;
            }
          }
        }
        prev = val;
      }
    }
  }
  return hit ? best : kInf;
}

std::vector<Discovery> explore_rotations(const WitnessSearch& search, const PcSet& pcs, const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  const SearchParams& prm = search.params();
  const double tol = prm.touch_tol;
  const double len_tol = 1e-7 * search.scale();
  const int n = pcs.size();
  // Per PC: its normal, an anchor point, and for line PCs the edge's direction.
  std::vector<Vec3> normal(n), anchor(n), line(n, Vec3::Zero());
  for (int j = 0; j < n; ++j) {
    const Pc& pc = pcs[j];
    normal[j] = search.contact_plane(pc, witness).first;
    switch (pc.type) {
      case PcType::kVF: anchor[j] = witness.apply(A.vertices()[pc.a].p); break;
      case PcType::kFV: anchor[j] = B.vertices()[pc.b].p; break;
      case PcType::kEE:
        anchor[j] = element_distance(A, witness, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b).p_b;
        break;
      case PcType::kEF: {
        const Vec3 e0 = witness.apply(A.edge_point(EdgeId(pc.a), 0)), e1 = witness.apply(A.edge_point(EdgeId(pc.a), 1));
        anchor[j] = 0.5 * (e0 + e1);
        line[j] = (e1 - e0).normalized();
        break;
      }
      case PcType::kFE: {
        const Vec3& e0 = B.edge_point(EdgeId(pc.b), 0);
        const Vec3& e1 = B.edge_point(EdgeId(pc.b), 1);
        anchor[j] = 0.5 * (e0 + e1);
        line[j] = (e1 - e0).normalized();
        break;
      }
      case PcType::kFF: {
        const auto c = face_overlap_centroid(A, witness, pc.a, B, pc.b);
        anchor[j] = c ? *c : witness.apply(A.faces()[pc.a].centroid);
        break;
      }
    }
  }
  const bool point_pc[6] = {false, false, false, true, true, true};  // by PcType order FF EF FE VF FV EE
  auto is_point = [&](int j) { return point_pc[static_cast<int>(pcs[j].type)]; };
  // A rotation about (p, u) keeps PC j when the axis passes through its contact point (point
  // PCs), lies along its contact edge (line PCs), or is parallel to its normal (any PC).
  auto keeps = [&](int j, const Vec3& p, const Vec3& u) {
    if (std::abs(std::abs(u.dot(normal[j])) - 1) < 1e-9) return true;
    const Vec3 r = anchor[j] - p;
    const double off = (r - r.dot(u) * u).norm();
    if (is_point(j)) return off < len_tol;
    if (line[j].norm() > 0.5) return off < len_tol && std::abs(std::abs(u.dot(line[j])) - 1) < 1e-9;
    return false;
  };
  std::vector<Discovery> out;
  auto record = [&](const Pose& pose) {
    PcSet found;
    if (search.contacts_at(pose, found) && !found.empty() && found != pcs) out.push_back({found, pose});
  };
  for (int mask = 0; mask + 1 < (1 << n); ++mask) {  // mask: the PCs to break
    PcSet kept;
    std::vector<int> K, L;
    for (int j = 0; j < n; ++j) (mask >> j & 1 ? L : K).push_back(j);
    for (int j : K) kept.insert(pcs[j]);
    // Candidate axes from the kept PCs' anchors, lines and normals.
    std::vector<std::pair<Vec3, Vec3>> axes;
    for (int j : K) {
      axes.push_back({anchor[j], normal[j]});
      if (line[j].norm() > 0.5) axes.push_back({anchor[j], line[j]});
      for (int k : K)
        if (k != j) {
          axes.push_back({anchor[j], normal[k]});
          const Vec3 d = anchor[k] - anchor[j];
          if (d.norm() > len_tol && is_point(j) && is_point(k)) axes.push_back({anchor[j], d.normalized()});
        }
      if (K.size() == 1 && is_point(j)) {
        // Tilts about the contact point, along a tangent basis of the contact plane.
        const Vec3 t1 = normal[j].unitOrthogonal(), t2 = normal[j].cross(t1);
        for (double a : {0.0, M_PI / 4, M_PI / 2, 3 * M_PI / 4})
          axes.push_back({anchor[j], std::cos(a) * t1 + std::sin(a) * t2});
      }
    }
    std::vector<std::pair<Vec3, Vec3>> kept_axes;
    for (const auto& [p, u0] : axes) {
      const Vec3 u = u0.normalized();
      bool ok = true;
      for (int j : K) ok = ok && keeps(j, p, u);
      bool dup = false;
      for (const auto& [q, w] : kept_axes) {
        const Vec3 r = p - q;
        dup = dup || (std::abs(std::abs(u.dot(w)) - 1) < 1e-9 && (r - r.dot(w) * w).norm() < len_tol);
      }
      if (ok && !dup) kept_axes.push_back({p, u});
    }
    for (const auto& [p, u] : kept_axes)
      for (double sign : {1.0, -1.0}) {
        const Vec3 w = sign * u;
        // Broken PCs must leave: their anchors move away from B along their normals.
        double rate = kInf;
        for (int j : L) rate = std::min(rate, normal[j].dot(w.cross(anchor[j] - p)));
        if (!L.empty() && !(rate > 1e-6 * search.scale())) continue;
        const double phi_hit = first_contact_rotation(A, B, witness, p, w, 1e-9, M_PI, tol, kept);
        if (!L.empty()) {
          const double phi = std::min(0.5 * std::min(phi_hit, M_PI), std::max(10 * prm.min_clearance, prm.good_clearance) / rate);
          record(rotated(witness, p, w, phi));
        }
        if (std::isfinite(phi_hit)) record(rotated(witness, p, w, phi_hit));
      }
  }
  // Tipping: a line or plane PC turned about one of its boundary elements becomes the
  // neighbouring PC that element makes (f-f about an edge of either face: e-f or f-e; e-f or
  // f-e about an end of the edge: v-f or f-v), while the other PCs are kept.
  auto tip = [&](int j, const Vec3& p, const Vec3& u0, const Pc& neighbour) {
    const Vec3 u = u0.normalized();
    PcSet kept;
    kept.insert(neighbour);
    for (int k = 0; k < n; ++k)
      if (k != j) {
        if (!keeps(k, p, u)) return;
        kept.insert(pcs[k]);
      }
    for (double sign : {1.0, -1.0}) {
      const Vec3 w = sign * u;
      const double rate = normal[j].dot(w.cross(anchor[j] - p));  // the PC's anchor lifts
      if (!(rate > 1e-6 * search.scale())) continue;
      const double phi_hit = first_contact_rotation(A, B, witness, p, w, 1e-9, M_PI, tol, kept);
      const double phi = std::min(0.5 * std::min(phi_hit, M_PI), std::max(10 * prm.min_clearance, prm.good_clearance) / rate);
      record(rotated(witness, p, w, phi));
      if (std::isfinite(phi_hit)) record(rotated(witness, p, w, phi_hit));
    }
  };
  for (int j = 0; j < n; ++j) {
    const Pc& pc = pcs[j];
    switch (pc.type) {
      case PcType::kFF:
        for (cf::EdgeId e : A.faces()[pc.a].edges)
          tip(j, witness.apply(A.edge_point(e, 0)), witness.R_BA * A.edge(e).dir, Pc{PcType::kEF, e.value(), pc.b});
        for (cf::EdgeId e : B.faces()[pc.b].edges)
          tip(j, B.edge_point(e, 0), B.edge(e).dir, Pc{PcType::kFE, pc.a, e.value()});
        break;
      case PcType::kEF:
        for (int end = 0; end < 2; ++end) {
          const cf::VertexId v = end == 0 ? A.edges()[pc.a].v0 : A.edges()[pc.a].v1;
          tip(j, witness.apply(A.vertex(v).p), normal[j].cross(line[j]), Pc{PcType::kVF, v.value(), pc.b});
        }
        break;
      case PcType::kFE:
        for (int end = 0; end < 2; ++end) {
          const cf::VertexId v = end == 0 ? B.edges()[pc.b].v0 : B.edges()[pc.b].v1;
          tip(j, B.vertex(v).p, normal[j].cross(line[j]), Pc{PcType::kFV, pc.a, v.value()});
        }
        break;
      default:
        break;
    }
  }
  return out;
}

}  // namespace cf::gen

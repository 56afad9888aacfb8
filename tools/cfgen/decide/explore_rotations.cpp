// The closure by motion's rotations (explore.hpp): the exact first contact along a rotation,
// and the contact sets met by turning a CF's witness about axes that keep some of its PCs,
// or by tipping a line or plane PC about one of its boundary elements.

#include "cfgen/decide/explore.hpp"

#include "cfgen/verify/touch.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf::gen {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

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

namespace {

// The heights along the turning axis and the largest distance from it that a face's points
// span (grown by a slack).
struct TurnRange {
  double z_lo, z_hi, r_hi;
  bool reaches(const Eigen::Vector2d& hr) const {
    return hr[0] >= z_lo && hr[0] <= z_hi && hr[1] <= r_hi;
  }
};

// The heights along the turning axis and the distances from it that a segment spans.
struct AxisBox {
  double z_lo, z_hi, r_lo, r_hi;
};

constexpr int kSamples = 192;  // samples of the turn for the edges' sign changes

// The samples' angles, cosines and sines, kept per thread for the last range asked for: the
// closure turns over the same range every time, and computing them takes 193 sincos (and
// the angles a division each, for every pair of edges).
struct SampleTable {
  bool set = false;
  double phi_min = 0, phi_max = 0;
  double phi[kSamples + 1];
  double cs[kSamples + 1][2];
};

const SampleTable& samples(double phi_min, double phi_max) {
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
  return table;
}

// One first_contact_rotation(): A at `pose` turned about the axis through p along u over
// (phi_min, phi_max], and the first contact found so far (best, hit).
class Turn {
 public:
  Turn(const Polyhedron& A, const Polyhedron& B, const Pose& pose, const Vec3& p, const Vec3& u,
       double phi_min, double phi_max, double tol, const PcSet& kept)
      : A_(A),
        B_(B),
        pose_(pose),
        p_(p),
        u_(u),
        phi_min_(phi_min),
        phi_max_(phi_max),
        tol_(tol),
        kept_(kept),
        best_(phi_max),
        pa_(A.num_vertices()),
        hra_(pa_.size()),
        hrb_(B.num_vertices()),
        turn_slack_(1e3 * tol + 1e-9 * std::max(A.size(), B.size())) {
    for (std::size_t i = 0; i < pa_.size(); ++i) pa_[i] = pose.apply(A.vertices()[i].p);
    for (std::size_t i = 0; i < pa_.size(); ++i) hra_[i] = height_radius(pa_[i]);
    for (std::size_t i = 0; i < hrb_.size(); ++i) hrb_[i] = height_radius(B.vertices()[i].p);
  }
  double first() {
    vertices_of_a_on_faces_of_b();
    vertices_of_b_on_faces_of_a();
    edges_on_edges();
    return hit_ ? best_ : kInf;
  }

 private:
  bool dominated(ElementKind ka, int a, ElementKind kb, int b) const {
    return covered_by(A_, B_, kept_, ka, a, kb, b);
  }
  // A point x0 turning about (p, u): x(phi) = p + r_par + cos(phi) r_perp + sin(phi) u x r_perp.
  Vec3 on_circle(const Vec3& x0, double phi) const {
    const Vec3 r = x0 - p_, r_par = r.dot(u_) * u_, r_perp = r - r_par;
    return Vec3(p_ + r_par + std::cos(phi) * r_perp + std::sin(phi) * u_.cross(r_perp));
  }
  // A turning keeps each point's height along the axis and its distance from it: a vertex
  // can reach a face only where its height lies in the face's range of heights and its
  // distance is within the face's largest (both at the face's vertices, grown by the slack
  // the edges' test below keeps).
  Eigen::Vector2d height_radius(const Vec3& x) const {
    const double z = (x - p_).dot(u_);
    return Eigen::Vector2d(z, ((x - p_) - z * u_).norm());
  }
  TurnRange turn_range(const Face& F, const std::vector<Eigen::Vector2d>& hr) const {
    TurnRange t{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                0.0};
    for (VertexId v : F.vertices) {
      t.z_lo = std::min(t.z_lo, hr[v.index()][0]);
      t.z_hi = std::max(t.z_hi, hr[v.index()][0]);
      t.r_hi = std::max(t.r_hi, hr[v.index()][1]);
    }
    t.z_lo -= turn_slack_;
    t.z_hi += turn_slack_;
    t.r_hi += turn_slack_;
    return t;
  }
  AxisBox axis_box(const Vec3& a, const Vec3& b) const {
    const double za = (a - p_).dot(u_), zb = (b - p_).dot(u_);
    const Vec3 ra = (a - p_) - za * u_, rb = (b - p_) - zb * u_;
    const Vec3 dr = rb - ra;
    const double s =
        dr.squaredNorm() > 0 ? std::clamp(-ra.dot(dr) / dr.squaredNorm(), 0.0, 1.0) : 0.0;
    return AxisBox{std::min(za, zb), std::max(za, zb), (ra + s * dr).norm(),
                   std::max(ra.norm(), rb.norm())};
  }
  void take(double phi) {
    best_ = phi;
    hit_ = true;
  }
  void vertices_of_a_on_faces_of_b();
  void vertices_of_b_on_faces_of_a();
  void edges_on_edges();
  void edge_on_edge(std::size_t ea, std::size_t eb, const Vec3 (&D)[3], const Vec3& P0,
                    const Vec3& C0, const Vec3& S0);

  const Polyhedron& A_;
  const Polyhedron& B_;
  const Pose& pose_;
  const Vec3& p_;
  const Vec3& u_;
  const double phi_min_, phi_max_, tol_;
  const PcSet& kept_;
  double best_;
  bool hit_ = false;
  std::vector<Vec3> pa_;                    // A's vertices at pose_, mm
  std::vector<Eigen::Vector2d> hra_, hrb_;  // height_radius of A's and B's vertices
  const double turn_slack_;                 // mm
};

// Vertices of A against faces of B.
void Turn::vertices_of_a_on_faces_of_b() {
  std::vector<double> roots;
  for (std::size_t f = 0; f < B_.num_faces(); ++f) {
    const Face& F = B_.faces()[f];
    const TurnRange range = turn_range(F, hrb_);
    for (std::size_t v = 0; v < pa_.size(); ++v) {
      if (!range.reaches(hra_[v])) continue;
      roots.clear();
      const Vec3 r = pa_[v] - p_, r_par = r.dot(u_) * u_, r_perp = r - r_par;
      const Vec3 w = u_.cross(r_perp);
      trig_roots(F.normal.dot(r_perp), F.normal.dot(w), F.normal.dot(p_ + r_par) - F.offset,
                 phi_min_, best_, roots);
      for (double phi : roots) {
        if (phi >= best_ || dominated(ElementKind::kVertex, int(v), ElementKind::kFace, int(f)))
          continue;
        if (B_.face_inset(FaceId(int(f)), on_circle(pa_[v], phi)) >= -tol_) take(phi);
      }
    }
  }
}

// Vertices of B against faces of A: seen from A, B turns by -phi about the same axis.
void Turn::vertices_of_b_on_faces_of_a() {
  std::vector<double> roots;
  for (std::size_t f = 0; f < A_.num_faces(); ++f) {
    const Face& F = A_.faces()[f];
    const Vec3 n = pose_.R_BA * F.normal;
    const double d = F.offset + n.dot(pose_.t_BA);
    const TurnRange range = turn_range(F, hra_);
    for (std::size_t v = 0; v < B_.num_vertices(); ++v) {
      if (!range.reaches(hrb_[v])) continue;
      const Vec3& q = B_.vertices()[v].p;
      roots.clear();
      const Vec3 r = q - p_, r_par = r.dot(u_) * u_, r_perp = r - r_par;
      trig_roots(n.dot(r_perp), -n.dot(u_.cross(r_perp)), n.dot(p_ + r_par) - d, phi_min_, best_,
                 roots);
      for (double phi : roots) {
        if (phi >= best_ || dominated(ElementKind::kFace, int(f), ElementKind::kVertex, int(v)))
          continue;
        const Vec3 qr = p_ + r_par + std::cos(phi) * r_perp - std::sin(phi) * u_.cross(r_perp);
        if (A_.face_inset(FaceId(int(f)), pose_.inverse_apply(qr)) >= -tol_) take(phi);
      }
    }
  }
}

// Edges against edges, pairs whose axis boxes overlap (a turning keeps each point's height
// along the axis and its distance from it).
void Turn::edges_on_edges() {
  std::vector<AxisBox> b_boxes(B_.num_edges());
  for (std::size_t eb = 0; eb < B_.num_edges(); ++eb)
    b_boxes[eb] = axis_box(B_.edge_point(EdgeId(int(eb)), 0), B_.edge_point(EdgeId(int(eb)), 1));
  const double reach = 1e3 * tol_;  // as the segment check of edge_on_edge
  // x(phi) = P + cos(phi) C + sin(phi) S for a point turning about (p, u).
  auto circle = [&](const Vec3& x0, Vec3& P, Vec3& C, Vec3& S) {
    const Vec3 r = x0 - p_, r_par = r.dot(u_) * u_;
    P = p_ + r_par;
    C = r - r_par;
    S = u_.cross(C);
  };
  for (std::size_t ea = 0; ea < A_.num_edges(); ++ea) {
    Vec3 P0, C0, S0, P1, C1, S1;
    const Vec3& a0 = pa_[A_.edges()[ea].v0.index()];
    const Vec3& a1 = pa_[A_.edges()[ea].v1.index()];
    const AxisBox box = axis_box(a0, a1);
    circle(a0, P0, C0, S0);
    circle(a1, P1, C1, S1);
    const Vec3 D[3] = {P1 - P0, C1 - C0, S1 - S0};
    for (std::size_t eb = 0; eb < B_.num_edges(); ++eb) {
      const AxisBox& bb = b_boxes[eb];
      if (bb.z_lo > box.z_hi + reach || box.z_lo > bb.z_hi + reach || bb.r_lo > box.r_hi + reach ||
          box.r_lo > bb.r_hi + reach)
        continue;
      if (dominated(ElementKind::kEdge, int(ea), ElementKind::kEdge, int(eb))) continue;
      edge_on_edge(ea, eb, D, P0, C0, S0);
    }
  }
}

// The lines of edge ea of A (x0 + lambda D, turning) and eb of B meet where g(phi) = (q0 -
// x0(phi)) . ((x1 - x0)(phi) x ub) = 0, a trigonometric polynomial of degree 2 (six
// coefficients); its sign changes on a fine sampling are refined by bisection, then checked
// on the segments.
void Turn::edge_on_edge(std::size_t ea, std::size_t eb, const Vec3 (&D)[3], const Vec3& P0,
                        const Vec3& C0, const Vec3& S0) {
  const SampleTable& table = samples(phi_min_, phi_max_);
  const auto& cs = table.cs;
  const auto& phis = table.phi;
  const Vec3& q0 = B_.edge_point(EdgeId(int(eb)), 0);
  const Vec3& q1 = B_.edge_point(EdgeId(int(eb)), 1);
  const Vec3 ub = q1 - q0;
  const Vec3 E[3] = {q0 - P0, -C0, -S0};
  double M[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M[i][j] = E[i].dot(D[j].cross(ub));
  const double k0 = M[0][0], kc = M[1][0] + M[0][1], ks = M[2][0] + M[0][2], kcc = M[1][1],
               kss = M[2][2], kcs = M[1][2] + M[2][1];
  auto g = [&](double c, double s) {
    return k0 + c * (kc + c * kcc + s * kcs) + s * (ks + s * kss);
  };
  auto g_at = [&](double phi) { return g(std::cos(phi), std::sin(phi)); };
  double prev = g(cs[0][0], cs[0][1]);
  for (int k = 1; k <= kSamples; ++k) {
    const double lo0 = phis[k - 1];
    if (lo0 >= best_) break;
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
      if (hi < best_) {
        const ClosestPoints cp =
            segment_segment(on_circle(pa_[A_.edges()[ea].v0.index()], hi),
                            on_circle(pa_[A_.edges()[ea].v1.index()], hi), q0, q1);
        if (cp.distance <= 1e3 * tol_) take(hi);
      }
    }
    prev = val;
  }
}

}  // namespace

double first_contact_rotation(const Polyhedron& A, const Polyhedron& B, const Pose& pose,
                              const Vec3& p, const Vec3& u, double phi_min, double phi_max,
                              double tol, const PcSet& kept) {
  return Turn(A, B, pose, p, u, phi_min, phi_max, tol, kept).first();
}

namespace {

// Per PC of a CF at its witness: its contact normal, an anchor point (the contact point of a
// point PC, the middle of a line PC's edge, the centroid of a plane PC's overlap), and for
// line PCs the edge's direction (zero for the others). B's frame.
struct PcFrames {
  std::vector<Vec3> normal, anchor, line;
};

PcFrames pc_frames(const WitnessSearch& search, const PcSet& pcs, const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  const auto n = static_cast<std::size_t>(pcs.size());
  PcFrames f{std::vector<Vec3>(n), std::vector<Vec3>(n), std::vector<Vec3>(n, Vec3::Zero())};
  for (std::size_t j = 0; j < n; ++j) {
    const Pc& pc = pcs[static_cast<int>(j)];
    f.normal[j] = search.contact_plane(pc, witness).first;
    switch (pc.type) {
      case PcType::kVF:
        f.anchor[j] = witness.apply(A.vertices()[pc.a].p);
        break;
      case PcType::kFV:
        f.anchor[j] = B.vertices()[pc.b].p;
        break;
      case PcType::kEE:
        f.anchor[j] =
            element_distance(A, witness, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b).p_b;
        break;
      case PcType::kEF: {
        const Vec3 e0 = witness.apply(A.edge_point(EdgeId(pc.a), 0)),
                   e1 = witness.apply(A.edge_point(EdgeId(pc.a), 1));
        f.anchor[j] = 0.5 * (e0 + e1);
        f.line[j] = (e1 - e0).normalized();
        break;
      }
      case PcType::kFE: {
        const Vec3& e0 = B.edge_point(EdgeId(pc.b), 0);
        const Vec3& e1 = B.edge_point(EdgeId(pc.b), 1);
        f.anchor[j] = 0.5 * (e0 + e1);
        f.line[j] = (e1 - e0).normalized();
        break;
      }
      case PcType::kFF: {
        const auto c = face_overlap_centroid(A, witness, pc.a, B, pc.b);
        f.anchor[j] = c ? *c : witness.apply(A.faces()[pc.a].centroid);
        break;
      }
    }
  }
  return f;
}

}  // namespace

std::vector<Discovery> explore_rotations(const WitnessSearch& search, const PcSet& pcs,
                                         const Pose& witness) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  const SearchParams& prm = search.params();
  const double tol = prm.touch_tol;
  const double len_tol = 1e-7 * search.scale();
  const int n = pcs.size();
  const PcFrames frames = pc_frames(search, pcs, witness);
  const std::vector<Vec3>&normal = frames.normal, &anchor = frames.anchor, &line = frames.line;
  const bool point_pc[6] = {false, false, false,
                            true,  true,  true};  // by PcType order FF EF FE VF FV EE
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
    if (search.contacts_at(pose, found) && !found.empty() && found != pcs)
      out.push_back({found, pose});
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
          if (d.norm() > len_tol && is_point(j) && is_point(k))
            axes.push_back({anchor[j], d.normalized()});
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
        dup =
            dup || (std::abs(std::abs(u.dot(w)) - 1) < 1e-9 && (r - r.dot(w) * w).norm() < len_tol);
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
          const double phi = std::min(0.5 * std::min(phi_hit, M_PI),
                                      std::max(10 * prm.min_clearance, prm.good_clearance) / rate);
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
      const double phi = std::min(0.5 * std::min(phi_hit, M_PI),
                                  std::max(10 * prm.min_clearance, prm.good_clearance) / rate);
      record(rotated(witness, p, w, phi));
      if (std::isfinite(phi_hit)) record(rotated(witness, p, w, phi_hit));
    }
  };
  for (int j = 0; j < n; ++j) {
    const Pc& pc = pcs[j];
    switch (pc.type) {
      case PcType::kFF:
        for (cf::EdgeId e : A.faces()[pc.a].edges)
          tip(j, witness.apply(A.edge_point(e, 0)), witness.R_BA * A.edge(e).dir,
              Pc{PcType::kEF, e.value(), pc.b});
        for (cf::EdgeId e : B.faces()[pc.b].edges)
          tip(j, B.edge_point(e, 0), B.edge(e).dir, Pc{PcType::kFE, pc.a, e.value()});
        break;
      case PcType::kEF:
        for (int end = 0; end < 2; ++end) {
          const cf::VertexId v = end == 0 ? A.edges()[pc.a].v0 : A.edges()[pc.a].v1;
          tip(j, witness.apply(A.vertex(v).p), normal[j].cross(line[j]),
              Pc{PcType::kVF, v.value(), pc.b});
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

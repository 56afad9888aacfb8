#include "exact.hpp"
#include "tolerances.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace cf::internal {

namespace {

std::vector<EdgeWings> wings_of(const Polyhedron& m) {
  std::vector<EdgeWings> w;
  w.reserve(m.num_edges());
  for (const Edge& e : m.edges()) {
    const Vec3& nl = m.face(e.left).normal;
    const Vec3& nr = m.face(e.right).normal;
    w.push_back({nl.cross(e.dir).normalized(), e.dir.cross(nr).normalized()});
  }
  return w;
}

Mat3 task_frame(const Vec3& y, const Vec3& x_hint) {
  Vec3 x = x_hint - x_hint.dot(y) * y;
  constexpr double kParallelSq = 1e-20;  // the hint within 1e-10 rad of y: no direction
  if (!(x.squaredNorm() > kParallelSq)) {
    // Any tangent: the world axis least aligned with y.
    int axis = 0;
    y.cwiseAbs().minCoeff(&axis);
    const Vec3 a = Vec3::Unit(axis);
    x = a - a.dot(y) * y;
  }
  x.normalize();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = x.cross(y);
  return R;
}

// Distance from p to the 2D segment s0-s1, and the parameter of the nearest point on it.
double point_seg(const Vec2& p, const Vec2& s0, const Vec2& s1, double* t) {
  const Vec2 r = s1 - s0;
  const double len2 = r.squaredNorm();
  *t = len2 > 0 ? std::clamp((p - s0).dot(r) / len2, 0.0, 1.0) : 0.0;
  return (s0 + *t * r - p).norm();
}

// Minimum distance between 2D segments that do not cross, and the parameter on the first.
double segment_segment_2d(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d,
                          double* t_on_first) {
  double t, best, tb;
  best = point_seg(c, a, b, &tb);
  double v = point_seg(d, a, b, &t);
  if (v < best) best = v, tb = t;
  v = point_seg(a, c, d, &t);
  if (v < best) best = v, tb = 0;
  v = point_seg(b, c, d, &t);
  if (v < best) best = v, tb = 1;
  *t_on_first = tb;
  return best;
}

// How far the deeper wing of edge E dips below its face's tolerance under a contact plane
// of normal n (E's model frame); > 0 exactly when the solid around E runs into the plane.
double wedge_dip(const Vec3& n, const EdgeWings& w, const Edge& E,
                 const std::vector<double>& sin_tol_face) {
  return std::max(-sin_tol_face[E.left.index()] - n.dot(w.left),
                  -sin_tol_face[E.right.index()] - n.dot(w.right));
}

PairOutcome turned_away(double lin, double rot) {
  PairOutcome o;
  o.cert = {lin, rot};
  return o;
}
// Turned away for good whatever the pose (a reflex edge).
PairOutcome never() { return turned_away(0, std::numeric_limits<double>::infinity()); }

// x / scale within [0, 1]: the share left of a margin of size `scale` (1 when it has none).
double share(double x, double scale) { return scale > 0 ? std::clamp(x / scale, 0.0, 1.0) : 1.0; }

// The share left of PairTables::within_band_beside's margin for a contact at distance d
// read `gap` beside its element: 1 in the element (gap 0), 0 where the two points it measures
// reach the band's limit.
double beside_share(const PairTables& t, double d, double gap) {
  if (gap <= 0) return 1.0;
  const double lim = d >= 0 ? t.eps : t.depth;
  const double allowed = std::sqrt(std::max(0.0, lim * lim - d * d));
  return allowed > 0 ? std::clamp((allowed - gap) / allowed, 0.0, 1.0) : 0.0;
}

// The share left of the wedge tolerance of an edge whose wings dip by `dip` (wedge_dip:
// rejected above 0), its wings' tolerances being sin_l and sin_r.
double wedge_share(double dip, double sin_l, double sin_r) {
  return share(-dip, std::max(sin_l, sin_r));
}

PairOutcome contact(PcType type, int ia, int ib, double d, const Vec3& p_W, const Vec3& origin,
                    const Mat3& R_WT, double misfit, double fit) {
  PairOutcome o;
  ContactPc& c = o.contact.emplace();
  c.pc = {type, ia, ib};
  c.distance = d;
  c.fit = fit;
  c.p_W = p_W;
  c.origin_W = origin;
  c.R_WT = R_WT;
  c.misfit = misfit;
  return o;
}

// Misfit added to a contact whose open elements do not touch, only their boundaries: a line
// contact whose part over the face lies along one of the face's boundary edges or does not
// enter the face (the touch is the edges', degenerate), an e-e crossing at an end of an edge
// (a vertex on an edge), a v-f or f-v whose vertex is on the face's boundary or beside it. A
// reading that keeps the contact region whole, e.g. the e-f of the neighbouring face, must
// rank above it (docs/runtime.md).
constexpr double kAlongBoundaryPenalty = 1.0;

// Whether the 2D segment c0-c1 lies along one boundary edge of the flat face P (within tol
// of it at both ends): the open face does not touch it, only that edge does.
bool along_boundary(const Poly2& P, const Vec2& c0, const Vec2& c1, double tol) {
  double t;
  for (int l = 0; l < P.num_loops; ++l)
    for (int i = P.lb[l]; i < P.lb[l + 1]; ++i) {
      const Vec2& a = P.pts[i];
      const Vec2& b = P.pts[i + 1 == P.lb[l + 1] ? P.lb[l] : i + 1];
      if (point_seg(c0, a, b, &t) <= tol && point_seg(c1, a, b, &t) <= tol) return true;
    }
  return false;
}

// Line contact of segment s0->s1 (in the face's model frame) against face f of model m
// (flat f): shared by e-f (m = B, segment world) and f-e (m = A, segment in A's frame).
// Returns false when not a contact; else the region's centroid parameter, its deepest
// height, the in-plane gap and the region's extent as a share of the segment (from the
// first to the last point over the face; 0 beside the face). Turned away for the segment's
// heights or its in-plane gap, it leaves in *lin how far the segment must move (in the
// face's frame) to pass them. *on_boundary: the part over the face lies along the face's
// boundary, or the segment does not enter the face at all.
bool line_on_face(const PairTables& t, ExactScratch& s, const Polyhedron& m, const FlatFaces& flat,
                  int f, const Vec3& s0, const Vec3& s1, double* t_c, double* d, double* gap,
                  double* span, double* lin, bool* on_boundary) {
  *on_boundary = false;
  const Face& F = m.faces()[static_cast<std::size_t>(f)];
  const double h0 = F.normal.dot(s0) - F.offset, h1 = F.normal.dot(s1) - F.offset;
  if (std::min(h0, h1) > t.eps || std::max(h0, h1) < -t.depth) {
    *lin = std::max(std::min(h0, h1) - t.eps, -t.depth - std::max(h0, h1));
    return false;
  }
  const Vec2 a2(F.u.dot(s0), F.v.dot(s0)), b2(F.u.dot(s1), F.v.dot(s1));
  double len = 0, moment = 0, dmin = std::numeric_limits<double>::infinity();
  double first = 1, last = 0;
  const auto piece = [&](double t0, double t1) {
    len += t1 - t0;
    moment += 0.5 * (t1 * t1 - t0 * t0);
    dmin = std::min({dmin, h0 + t0 * (h1 - h0), h0 + t1 * (h1 - h0)});
    first = std::min(first, t0);
    last = std::max(last, t1);
  };
  if (flat.convex[static_cast<std::size_t>(f)]) {
    double t0, t1;
    if (clip_segment_convex(a2, b2, flat.poly(f), t.geo_tol, &t0, &t1)) piece(t0, t1);
  } else {
    clip_segment(a2, b2, flat.poly(f), t.geo_tol, OnBoundary::kInclude, s.params.data(), piece);
  }
  if (len > internal::kRelativeRounding * t.eps) {
    *t_c = moment / len;
    *d = dmin;
    *gap = 0;
    *span = last - first;
    // The clipped ends lie up to the clipping's slack beyond the boundary: 10 geo_tol, far
    // below any feature still.
    *on_boundary =
        along_boundary(flat.poly(f), a2 + first * (b2 - a2), a2 + last * (b2 - a2), 10 * t.geo_tol);
  } else {
    // Beside the face: the nearest in-plane approach to its boundary.
    const Poly2 P = flat.poly(f);
    double best = std::numeric_limits<double>::infinity(), tb = 0;
    for (int l = 0; l < P.num_loops; ++l)
      for (int i = P.lb[l]; i < P.lb[l + 1]; ++i) {
        double tt;
        const double g = segment_segment_2d(a2, b2, P.pts[i],
                                            P.pts[i + 1 == P.lb[l + 1] ? P.lb[l] : i + 1], &tt);
        if (g < best) best = g, tb = tt;
      }
    if (best > t.in_plane) {
      *lin = best - t.in_plane;
      return false;
    }
    *t_c = tb;
    *d = h0 + tb * (h1 - h0);
    *gap = best;
    *span = 0;
    *on_boundary = true;  // the segment does not enter the face: at most its boundary touches
  }
  // Beside the face, the nearest point of the segment and of the face's boundary must be
  // within the band too (they bound the elements' distance; no certificate: the elements may
  // come closer elsewhere).
  return t.in_band(*d) && t.within_band_beside(*d, *gap);
}

}  // namespace

FlatFaces::FlatFaces(const Polyhedron& m) {
  for (const Face& F : m.faces()) {
    face_first.push_back(static_cast<int>(loop_begin.size()));
    int n = 0;
    for (const auto& loop : F.loops_2d) {
      loop_begin.push_back(static_cast<int>(pts.size()));
      pts.insert(pts.end(), loop.begin(), loop.end());
      n += static_cast<int>(loop.size());
    }
    max_face_points = std::max(max_face_points, n);
  }
  face_first.push_back(static_cast<int>(loop_begin.size()));
  loop_begin.push_back(static_cast<int>(pts.size()));
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    convex.push_back(is_convex(poly(static_cast<int>(f))));
}

PairTables::PairTables(const Polyhedron& ma, const Polyhedron& mb, const Params& params,
                       const Vec3& origin)
    : a(&ma),
      b(&mb),
      prm(params.detection),
      flat_a(ma),
      flat_b(mb),
      wings_a(wings_of(ma)),
      wings_b(wings_of(mb)),
      origin_A(origin) {
  validate(params);
  eps = params.epsilon_mm;
  depth = prm.deepest_contact_mm;
  in_plane = prm.in_plane_tolerance_mm > 0 ? prm.in_plane_tolerance_mm : eps;
  const double scale = std::max(ma.size(), mb.size());
  geo_tol = kGeoTolPerMm * std::max(scale, 1.0);
  area_tol = kAreaTolPerMm2 * std::max(scale * scale, 1.0);
  reach = ma.size() + mb.size();
  for (const Vertex& v : mb.vertices())
    reach = std::max(reach, v.p.cwiseAbs().maxCoeff() + ma.size());
  orth_allow = kOrthAllowPerMm * std::max({reach, origin_A.norm(), 1.0});
  for (const Vertex& v : ma.vertices()) r_a = std::max(r_a, (v.p - origin_A).norm());
  // A face's tilt scale is its size, sqrt(area).
  for (const Face& F : ma.faces()) sin_tol_face_a.push_back(std::sin(tol_for(std::sqrt(F.area))));
  for (const Face& F : mb.faces()) sin_tol_face_b.push_back(std::sin(tol_for(std::sqrt(F.area))));
  for (const Edge& E : ma.edges()) sin_tol_edge_a.push_back(std::sin(tol_for(E.length)));
  for (const Edge& E : mb.edges()) sin_tol_edge_b.push_back(std::sin(tol_for(E.length)));
  sin_max_tol = std::sin(max_tol());
  cos_max_tol = std::cos(max_tol());
}

ExactScratch::ExactScratch(const PairTables& t) {
  q_pts.resize(static_cast<std::size_t>(t.flat_a.max_face_points));
  std::size_t max_loops = 1;
  for (const Face& F : t.a->faces()) max_loops = std::max(max_loops, F.loops.size());
  q_lb.resize(max_loops + 1);
  params.resize(static_cast<std::size_t>(
      4 + 4 * std::max(t.flat_a.max_face_points, t.flat_b.max_face_points)));
  clip_cap = t.flat_a.max_face_points + t.flat_b.max_face_points;
  clip_buf.resize(2 * static_cast<std::size_t>(clip_cap));
}

// ---- v-f: vertex of A on face of B ---------------------------------------------------------
PairOutcome vertex_face(const PairTables& t, PosedA& P, int v, int fb) {
  const Polyhedron& a = *t.a;
  const Face& F = t.b->faces()[static_cast<std::size_t>(fb)];
  const Vec3& p = P.world(a, VertexId(v));
  const double h = F.normal.dot(p) - F.offset;
  if (!t.in_band(h)) return {};
  // A's edges at the vertex must not run into B (beyond the angular tolerance).
  double fit = 1;
  for (EdgeId e : a.vertex(VertexId(v)).edges) {
    const Edge& E = a.edge(e);
    const Vec3& q = P.world(a, E.v0 == VertexId(v) ? E.v1 : E.v0);
    const double w = F.normal.dot(q - p), lim = -t.sin_tol_edge_a[e.index()] * E.length;
    if (w < lim) return turned_away(0, (lim - w) / E.length - t.geo_tol);  // q - p turns with A
    fit = std::min(fit, share(w - lim, -lim));
  }
  const Loc2 loc = locate(t.flat_b.poly(fb), Vec2(F.u.dot(p), F.v.dot(p)));
  const double gap = (loc.inside || loc.dist <= t.geo_tol) ? 0.0 : loc.dist;
  // The vertex's projection on B's plane moves at most as far as the vertex.
  if (gap > t.in_plane) return turned_away(gap - t.in_plane - t.geo_tol, 0);
  // Beside the face the vertex is hypot(h, gap) from it (a vertex below the plane beside a
  // convex edge is outside B, not h deep in it): within the band, or no contact. That
  // distance changes at most as far as the vertex moves; beyond max(eps, depth) it fails.
  if (!t.within_band_beside(h, gap))
    return turned_away(std::hypot(h, gap) - std::max(t.eps, t.depth) - t.geo_tol, 0);
  // On the face's boundary (a vertex on an edge, or outside): the open face does not touch.
  const bool boundary = !loc.inside || loc.dist <= 10 * t.geo_tol;
  return contact(PcType::kVF, v, fb, h, p, p - h * F.normal, task_frame(F.normal, F.u),
                 std::abs(h) / t.eps + gap / t.eps + (boundary ? kAlongBoundaryPenalty : 0.0),
                 fit * share(t.in_plane - gap, t.in_plane) * beside_share(t, h, gap));
}

// ---- f-v: face of A on vertex of B ---------------------------------------------------------
PairOutcome face_vertex(const PairTables& t, PosedA& P, int fa, int v) {
  const Polyhedron& b = *t.b;
  const Pose& pose = P.pose;
  const Face& F = t.a->faces()[static_cast<std::size_t>(fa)];
  const Vec3& q = b.vertex(VertexId(v)).p;
  const Vec3 qA = pose.inverse_apply(q);
  const double h = F.normal.dot(qA) - F.offset;
  if (!t.in_band(h)) return {};
  double fit = 1;
  for (EdgeId e : b.vertex(VertexId(v)).edges) {
    const Edge& E = b.edge(e);
    const Vec3& o = b.vertex(E.v0 == VertexId(v) ? E.v1 : E.v0).p;
    const Vec3 wA = pose.R_BA.transpose() * (o - q);
    const double w = F.normal.dot(wA), lim = -t.sin_tol_edge_b[e.index()] * E.length;
    if (w < lim) return turned_away(0, (lim - w) / E.length - t.geo_tol);
    fit = std::min(fit, share(w - lim, -lim));
  }
  const Loc2 loc = locate(t.flat_a.poly(fa), Vec2(F.u.dot(qA), F.v.dot(qA)));
  const double gap = (loc.inside || loc.dist <= t.geo_tol) ? 0.0 : loc.dist;
  if (gap > t.in_plane) {
    // B's vertex as A sees it, R^T (q - o) + const, moves at most the bound times
    // max(1, |q - o| / r_a).
    return P.certifying
               ? turned_away(t.seen_from_a(gap - t.in_plane, (q - P.origin_posed).norm()), 0)
               : PairOutcome{};
  }
  if (!t.within_band_beside(h, gap)) {  // as in v-f
    return P.certifying ? turned_away(t.seen_from_a(std::hypot(h, gap) - std::max(t.eps, t.depth),
                                                    (q - P.origin_posed).norm()),
                                      0)
                        : PairOutcome{};
  }
  const Vec3 nW = pose.R_BA * F.normal;
  const Vec3 onA = q - h * nW;
  const bool boundary = !loc.inside || loc.dist <= 10 * t.geo_tol;  // as in v-f
  return contact(PcType::kFV, fa, v, h, onA, onA, task_frame(-nW, pose.R_BA * F.u),
                 std::abs(h) / t.eps + gap / t.eps + (boundary ? kAlongBoundaryPenalty : 0.0),
                 fit * share(t.in_plane - gap, t.in_plane) * beside_share(t, h, gap));
}

// ---- e-f: edge of A on face of B -----------------------------------------------------------
PairOutcome edge_face(const PairTables& t, PosedA& P, ExactScratch& s, int e, int fb) {
  const Polyhedron& a = *t.a;
  const Pose& pose = P.pose;
  const Edge& E = a.edges()[static_cast<std::size_t>(e)];
  if (!E.convex) return never();
  const Face& F = t.b->faces()[static_cast<std::size_t>(fb)];
  const Vec3& p0 = P.world(a, E.v0);
  const Vec3& p1 = P.world(a, E.v1);
  const Vec3 dW = pose.R_BA * E.dir;
  const double sin_ang = std::min(1.0, std::abs(dW.dot(F.normal)));
  if (sin_ang > t.sin_max_tol) return {};
  const double dip = wedge_dip(pose.R_BA.transpose() * F.normal,
                               t.wings_a[static_cast<std::size_t>(e)], E, t.sin_tol_face_a);
  if (dip > 0) return turned_away(0, dip - t.geo_tol);
  double tc, d, gap, span, lin = 0;
  bool on_boundary = false;
  if (!line_on_face(t, s, *t.b, t.flat_b, fb, p0, p1, &tc, &d, &gap, &span, &lin, &on_boundary))
    return turned_away(lin - t.geo_tol, 0);  // A's segment moves at most the bound
  // The tilt at which the part of the edge over the face stays within epsilon (the whole
  // edge beside the face).
  const double tol = t.tol_for(span > 0 ? span * E.length : E.length);
  const double ang = std::asin(sin_ang);
  if (ang > tol) return {};
  const Vec3 p = p0 + tc * (p1 - p0);
  const double hc = F.normal.dot(p) - F.offset;
  return contact(
      PcType::kEF, e, fb, d, p, p - hc * F.normal, task_frame(F.normal, dW),
      ang / tol + std::abs(d) / t.eps + gap / t.eps + (on_boundary ? kAlongBoundaryPenalty : 0.0),
      share(tol - ang, tol) * share(t.in_plane - gap, t.in_plane) * beside_share(t, d, gap) *
          wedge_share(dip, t.sin_tol_face_a[E.left.index()], t.sin_tol_face_a[E.right.index()]));
}

// ---- f-e: face of A on edge of B -----------------------------------------------------------
PairOutcome face_edge(const PairTables& t, PosedA& P, ExactScratch& s, int fa, int e) {
  const Polyhedron& b = *t.b;
  const Pose& pose = P.pose;
  const Edge& E = b.edges()[static_cast<std::size_t>(e)];
  if (!E.convex) return never();
  const Face& F = t.a->faces()[static_cast<std::size_t>(fa)];
  const Mat3 Rt = pose.R_BA.transpose();
  const Vec3 dA = Rt * E.dir;
  const double sin_ang = std::min(1.0, std::abs(dA.dot(F.normal)));
  if (sin_ang > t.sin_max_tol) return {};
  const double dip =
      wedge_dip(pose.R_BA * F.normal, t.wings_b[static_cast<std::size_t>(e)], E, t.sin_tol_face_b);
  if (dip > 0) return turned_away(0, dip - t.geo_tol);
  const Vec3& q0 = b.vertex(E.v0).p;
  const Vec3& q1 = b.vertex(E.v1).p;
  const Vec3 q0A = pose.inverse_apply(q0), q1A = pose.inverse_apply(q1);
  double tc, d, gap, span, lin = 0;
  bool on_boundary = false;
  if (!line_on_face(t, s, *t.a, t.flat_a, fa, q0A, q1A, &tc, &d, &gap, &span, &lin, &on_boundary)) {
    // B's segment as A sees it moves at most the bound times max(1, |q - o| / r_a).
    if (!P.certifying) return {};
    return turned_away(
        t.seen_from_a(lin, std::max((q0 - P.origin_posed).norm(), (q1 - P.origin_posed).norm())),
        0);
  }
  const double tol = t.tol_for(span > 0 ? span * E.length : E.length);
  const double ang = std::asin(sin_ang);
  if (ang > tol) return {};
  const Vec3 qcA = q0A + tc * (q1A - q0A);
  const Vec3 onA = pose.apply(qcA - (F.normal.dot(qcA) - F.offset) * F.normal);
  return contact(
      PcType::kFE, fa, e, d, onA, onA, task_frame(-(pose.R_BA * F.normal), E.dir),
      ang / tol + std::abs(d) / t.eps + gap / t.eps + (on_boundary ? kAlongBoundaryPenalty : 0.0),
      share(tol - ang, tol) * share(t.in_plane - gap, t.in_plane) * beside_share(t, d, gap) *
          wedge_share(dip, t.sin_tol_face_b[E.left.index()], t.sin_tol_face_b[E.right.index()]));
}

// ---- f-f: face of A on face of B -----------------------------------------------------------
PairOutcome face_face(const PairTables& t, PosedA& P, ExactScratch& s, int fa, int fb) {
  const Polyhedron& a = *t.a;
  const Pose& pose = P.pose;
  const Face& FA = a.faces()[static_cast<std::size_t>(fa)];
  const Face& FB = t.b->faces()[static_cast<std::size_t>(fb)];
  const Vec3 nA = pose.R_BA * FA.normal;
  const double c = -nA.dot(FB.normal);
  if (c < t.cos_max_tol) return {};
  double hmin = std::numeric_limits<double>::infinity(), hmax = -hmin;
  for (VertexId v : FA.vertices) {
    const double h = FB.normal.dot(P.world(a, v)) - FB.offset;
    hmin = std::min(hmin, h);
    hmax = std::max(hmax, h);
  }
  if (hmin > t.eps || hmax < -t.depth) return {};
  // A's loops in B's face frame, reversed so that they run positively there.
  int n = 0, nl = 0;
  for (const auto& loop : FA.loops) {
    s.q_lb[static_cast<std::size_t>(nl++)] = n;
    for (std::size_t k = loop.size(); k-- > 0;) {
      const Vec3& p = P.world(a, loop[k]);
      s.q_pts[static_cast<std::size_t>(n++)] = Vec2(FB.u.dot(p), FB.v.dot(p));
    }
  }
  s.q_lb[static_cast<std::size_t>(nl)] = n;
  const Poly2 Q{s.q_pts.data(), s.q_lb.data(), nl};
  // Height of A's plane above B's plane at in-plane point (x, y): linear.
  const double nn = nA.dot(FB.normal);
  const double offA = nA.dot(pose.t_BA) + FA.offset;
  const double ku = nA.dot(FB.u) / nn, kv = nA.dot(FB.v) / nn, k0 = offA / nn - FB.offset;
  auto height = [&](const Vec2& q) { return k0 - ku * q.x() - kv * q.y(); };
  // The tilt's direction in B's plane: the overlap's extent along it is what the tilt
  // raises (orientation-independent, unlike a bounding box of the overlap).
  const Vec2 grad(ku, kv);
  // A slope (dimensionless) below the rounding has no direction.
  const Vec2 g_dir =
      grad.norm() > internal::kRelativeRounding ? Vec2(grad.normalized()) : Vec2(1, 0);
  double dmin = std::numeric_limits<double>::infinity();
  double s_lo = std::numeric_limits<double>::infinity(), s_hi = -s_lo;
  const auto visit = [&](const Vec2& q) {
    dmin = std::min(dmin, height(q));
    const double sq = q.dot(g_dir);
    s_lo = std::min(s_lo, sq);
    s_hi = std::max(s_hi, sq);
  };
  Overlap2 ov;
  if (!(t.flat_a.convex[static_cast<std::size_t>(fa)] &&
        t.flat_b.convex[static_cast<std::size_t>(fb)] &&
        overlap_convex(t.flat_b.poly(fb), Q, s.clip_buf.data(), s.clip_cap, ov, visit)))
    ov = overlap(t.flat_b.poly(fb), Q, t.geo_tol, s.params.data(), visit);
  if (!(ov.area > t.area_tol)) return {};
  // The tilt at which the whole overlap stays within epsilon.
  const double tol = t.tol_for(s_hi - s_lo);
  const double ang = std::acos(std::min(1.0, c));
  if (ang > tol || !t.in_band(dmin)) return {};
  const Vec3 origin = ov.centroid.x() * FB.u + ov.centroid.y() * FB.v + FB.offset * FB.normal;
  return contact(PcType::kFF, fa, fb, dmin, origin + height(ov.centroid) * FB.normal, origin,
                 task_frame(FB.normal, FB.u), ang / tol + std::abs(dmin) / t.eps,
                 share(tol - ang, tol));
}

// ---- e-e: edge of A crossing edge of B -----------------------------------------------------
PairOutcome edge_edge(const PairTables& t, PosedA& P, int ea, int eb) {
  const Polyhedron& a = *t.a;
  const Polyhedron& b = *t.b;
  const Pose& pose = P.pose;
  const Edge& EA = a.edges()[static_cast<std::size_t>(ea)];
  const Edge& EB = b.edges()[static_cast<std::size_t>(eb)];
  if (!EA.convex || !EB.convex) return never();
  const Vec3& p0 = P.world(a, EA.v0);
  const Vec3 uA = pose.R_BA * EA.dir;
  const Vec3& q0 = b.vertex(EB.v0).p;
  const Vec3& uB = EB.dir;
  Vec3 n = uA.cross(uB);
  const double sn = n.norm();
  // The tolerance of the shorter edge (atan(eps / L) falls with L): the larger sine.
  const double sin_par = std::max(t.sin_tol_edge_a[static_cast<std::size_t>(ea)],
                                  t.sin_tol_edge_b[static_cast<std::size_t>(eb)]);
  if (sn <= sin_par) return {};  // near-parallel: not e-e
  n /= sn;
  // Closest points of the two lines (unit directions): s along A, u along B.
  const Vec3 r = p0 - q0;
  const double bb = uA.dot(uB), c = uA.dot(r), f = uB.dot(r);
  const double den = 1 - bb * bb;
  const double s = (bb * f - c) / den;
  const double u = (f - bb * c) / den;
  const double over = std::max({0.0, -s, s - EA.length}) + std::max({0.0, -u, u - EB.length});
  if (over > t.in_plane) return {};
  const Vec3 pA = p0 + std::clamp(s, 0.0, EA.length) * uA;
  const Vec3 pB = q0 + std::clamp(u, 0.0, EB.length) * uB;
  const Vec3 sumB = b.face(EB.left).normal + b.face(EB.right).normal;
  const Vec3 sA = a.face(EA.left).normal + a.face(EA.right).normal;
  const Vec3 sumA = pose.R_BA * sA;
  const double side = n.dot(sumB - sumA);
  if (side < 0) n = -n;
  const double d = (pA - pB).dot(n);
  if (!t.in_band(d)) return {};
  // With a closest point clamped to an end the two points are also apart in the plane: they
  // must be within the band (as a vertex beside a face; no certificate, as for over).
  const double gap = over > 0 ? ((pA - pB) - d * n).norm() : 0.0;
  if (!t.within_band_beside(d, gap)) return {};
  // The wedges of the two edges must lie on their own sides of the contact plane.
  const double dip_a = wedge_dip(pose.R_BA.transpose() * n, t.wings_a[static_cast<std::size_t>(ea)],
                                 EA, t.sin_tol_face_a);
  const double dip_b = wedge_dip(-n, t.wings_b[static_cast<std::size_t>(eb)], EB, t.sin_tol_face_b);
  if (dip_a > 0 || dip_b > 0) {
    // n = m / |m| (m = uA x uB, |m| = sn) turns by at most 2 |dm| / sn <= 2 rho / sn, A's
    // view of it by rho more; `side` moves by at most rho (2 |sumB - sumA| / sn + |sA|),
    // and n's sign holds while it does not reach 0.
    const double turn = std::max(dip_a / (1 + 2 / sn), dip_b * sn / 2);
    const double flip = std::abs(side) / (2 * (sumB - sumA).norm() / sn + sA.norm());
    return turned_away(0, std::min(turn, flip) - t.geo_tol);
  }
  // A crossing at an end of either edge is a vertex on an edge (degenerate): the open edges
  // do not cross there.
  const bool at_end = std::min({std::abs(s), std::abs(s - EA.length), std::abs(u),
                                std::abs(u - EB.length)}) <= t.geo_tol;
  const double fit =
      share(sn - sin_par, sin_par) * share(t.in_plane - over, t.in_plane) *
      beside_share(t, d, gap) *
      wedge_share(dip_a, t.sin_tol_face_a[EA.left.index()], t.sin_tol_face_a[EA.right.index()]) *
      wedge_share(dip_b, t.sin_tol_face_b[EB.left.index()], t.sin_tol_face_b[EB.right.index()]);
  return contact(PcType::kEE, ea, eb, d, pA, pB, task_frame(n, uB),
                 std::abs(d) / t.eps + over / t.eps + (at_end ? kAlongBoundaryPenalty : 0.0), fit);
}

}  // namespace cf::internal

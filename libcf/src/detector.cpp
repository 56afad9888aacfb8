#include <cf/detector.hpp>

#include "bvh.hpp"
#include "check.hpp"
#include "detector_poly.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace cf {

namespace {

using detail::Vec2;

// Flattened 2D loops of every face of a model, in each face's own (u, v) frame.
struct FlatFaces {
  std::vector<Vec2> pts;
  std::vector<int> loop_begin;  // per loop, plus a sentinel
  std::vector<int> face_first;  // per face, its first loop index, plus a sentinel
  std::vector<char> convex;     // per face, detail::is_convex
  int max_face_points = 0;

  explicit FlatFaces(const Polyhedron& m) {
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
    for (std::size_t f = 0; f < m.num_faces(); ++f) convex.push_back(detail::is_convex(poly(static_cast<int>(f))));
  }
  FlatFaces() = default;
  detail::Poly2 poly(int f) const {
    const int l0 = face_first[static_cast<std::size_t>(f)];
    const int l1 = face_first[static_cast<std::size_t>(f) + 1];
    return {pts.data(), loop_begin.data() + l0, l1 - l0};
  }
};

// Per edge, the unit in-face directions perpendicular to it pointing into its left and
// right faces (model frame): how the solid continues away from the edge.
struct EdgeWings {
  Vec3 left, right;
};

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
  if (!(x.squaredNorm() > 1e-20)) {
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

// Minimum distance between 2D segments that do not cross, and the parameter on the first.
double segment_segment_2d(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d,
                          double* t_on_first) {
  auto point_seg = [](const Vec2& p, const Vec2& s0, const Vec2& s1, double* t) {
    const Vec2 r = s1 - s0;
    const double len2 = r.squaredNorm();
    *t = len2 > 0 ? std::clamp((p - s0).dot(r) / len2, 0.0, 1.0) : 0.0;
    return (s0 + *t * r - p).norm();
  };
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

}  // namespace

// BVH leaves of a model: one element for small models (with bigger leaves, leaf boxes of the
// paper's cube and L-block overlap everything), posed like inner nodes (cheaper than exact
// boxes there: 2.4 against 2.8 us per tick). Big models' nodes are also tested as oriented
// boxes, four at a time (detail::descend_wide): a curved surface's patches are tilted, and
// the axis-aligned box of a tilted patch is as thick as it is wide, so that two surfaces in
// contact overlap over many patches; and their leaves hold one face with the edges and
// vertices it owns, which tile the surface, each element with its own box tested in the
// leaf (on 2,000-face spheres 7% fewer instructions than leaves of 2 elements of any kind,
// 15% fewer at the paper's epsilon). docs/performance.md has the figures.
constexpr std::size_t kBigModelElements = 256;
bool is_big(const Polyhedron& m) { return m.num_vertices() + m.num_edges() + m.num_faces() >= kBigModelElements; }
detail::Leaves leaves_for(const Polyhedron& m) {
  return is_big(m) ? detail::Leaves::kFaceGroups : detail::Leaves::kElements;
}

struct ContactDetector::Impl {
  Polyhedron a, b;
  Params all;           // as given (params())
  DetectionParams prm;  // all.detection
  double eps, depth, in_plane, geo_tol, area_tol;
  detail::Bvh bvh_a, bvh_b;
  FlatFaces flat_a, flat_b;
  std::vector<EdgeWings> wings_a, wings_b;
  // sin of the angular tolerance of each face (from its extent) and edge (from its length):
  // the trigonometry of the per-pair tests, done once.
  std::vector<double> sin_tol_face_a, sin_tol_face_b, sin_tol_edge_a, sin_tol_edge_b;
  double sin_max_tol = 0, cos_max_tol = 1;
  // A's nodes' (and elements') boxes in B's frame at the current pose (computed on first
  // use per call).
  struct PosedBox {
    Eigen::Vector3f c, h;  // mm, B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedBox> a_box;
  struct PosedWide {  // big models: a wide node's four boxes
    detail::Box4 box;  // B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedWide> a_wide;
  // Big models: A's elements' boxes, from A's vertices posed in single precision.
  struct PosedElem {
    detail::ElemBox box;  // B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedElem> a_elem;
  std::vector<Eigen::Array4f> a_vert;  // mm, A's vertices relative to bvh_a.origin(), A's frame
  struct PosedVertex {
    Eigen::Array4f p;  // mm, B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedVertex> a_vert_posed;
  // A model of kBigModelElements or more: leaves of face groups, each element's own box
  // tested in the leaf, and nodes tested as oriented boxes too.
  bool big = false;
  Mat3 absR = Mat3::Identity();
  // Compact copies of what the cheap rejections read (most pairs the boxes pass are not
  // contacts: on 2,000-face spheres about 1 in 80 is), so that a rejection touches a few
  // contiguous bytes rather than the polyhedra's feature records. B's are fixed; A's are
  // posed on first use per call.
  struct Plane {
    Vec3 n;             // unit outward normal, B's frame
    double off = 0;     // mm: plane { x : n . x == off }
    std::uint64_t stamp = 0;
  };
  struct Seg {
    Vec3 p0, dir;       // mm, B's frame; dir unit
    double len = 0;     // mm
    std::uint64_t stamp = 0;
  };
  std::vector<Plane> plane_b, plane_a;
  std::vector<Seg> seg_b, seg_a;
  Eigen::Matrix3f Rf = Eigen::Matrix3f::Identity(), absRf = Eigen::Matrix3f::Identity();
  Eigen::Array4f Rcol[3];  // R_BA's columns, lane 3 zero (A's vertices' posing)
  Eigen::Array4f a_origin;              // mm, bvh_a's origin posed, B's frame
  // The same on all four lanes (for the wide nodes' posing): R_BA(i, k), |R_BA(i, k)|, and
  // a_origin[i].
  Eigen::Array4f Rb[3][3], absRb[3][3], ob[3];
  // Scratch (sized once).
  std::vector<detail::NodePair> stack;
  std::vector<Vec2> q_pts;
  std::vector<int> q_lb;
  std::vector<double> params;
  std::vector<Vec2> clip_buf;  // 2 * clip_cap points
  int clip_cap = 0;
  std::vector<Vec3> aw;  // A's vertices in the world at the current pose
  std::vector<std::uint64_t> aw_stamp;
  std::uint64_t stamp = 0;
  // Per call.
  Pose pose;
  ContactSet* out = nullptr;
  std::size_t pairs = 0;
  std::array<int, ContactSet::kCapacity> reps{};  // first member of each plane group
  // Temporal coherence (big models, DetectionParams::reuse_margin_mm): the element pairs whose
  // boxes overlapped with A's boxes grown by the margin at kept_pose. Every pair that can
  // touch at a pose where no point of A is further than the margin from where it was at
  // kept_pose is among them, so such a pose tests only those. A kept pair turned away
  // carries a certificate (Cert): while A has moved and turned less than it allows, the
  // pair is skipped.
  static constexpr std::size_t kMaxKept = 1 << 14;
  // A pair turned away stays turned away while A's points move less than `lin` (the
  // motion bound, motion_bound) or A turns less than `rot` (|R1 - R0|_F, which bounds how
  // far any unit vector of A, or of B seen from A, turns) from the pose it was turned away
  // at. <= 0: no certificate. Each keeps geo_tol in hand for rounding.
  struct Cert {
    double lin = 0;  // mm
    double rot = 0;  // Frobenius norm of the change of R_BA
  };
  Cert cert;  // set by the exact tests when they turn a pair away (for kept pairs)
  bool certifying = false;  // kept pairs are being recorded or served: the exact tests' certificates count
  // The kept pairs, and their certificates counted from kept_pose (kept_lin, kept_rot,
  // rounded down; side by side, so that four are checked at once): both measures are
  // metrics, so a pair certified at a pose `lin` from kept_pose holds at any pose less
  // than `lin` minus that from kept_pose. Tight while A moves on (the usual servo loop),
  // and it makes the check two comparisons with this call's distances from kept_pose.
  // Padded to a multiple of 4 with certificates that always hold.
  std::vector<detail::NodePair> kept;  // (A position, B position) in the BVHs' element lists
  std::vector<float> kept_lin, kept_rot;
  std::size_t num_kept = 0;
  bool kept_valid = false, recording = false, kept_overflow = false, reused = false;
  Pose kept_pose, last_pose;
  double moved_from_kept = 0, turned_from_kept = 0;  // this call's pose from kept_pose
  // mm: how far |(R^T R - I) o_A| (o_A: bvh_a's origin, A's frame) may be at a pose kept
  // pairs serve or are kept at. The certificates of B's points seen from A hold for
  // rotations; a rotation rounded to float (1e-7) is well within this, a pose further off
  // orthonormal is detected from scratch.
  double orth_allow = 0;
  Vec3 origin_posed = Vec3::Zero();  // mm, bvh_a's origin at the current pose, B's frame
  bool have_last = false;
  float grow = 0;    // mm, added to A's posed boxes in this call
  double r_a = 0;    // mm, A's furthest vertex from bvh_a's origin
  // Per type of PC that can dominate (f-f, e-f, f-e), the contacts of that type that fit
  // well enough to.
  std::array<std::array<int, ContactSet::kCapacity>, 3> dominators{};
  // sort_contacts' scratch. Its keys hold element indices in 24 bits.
  static_assert(ContactSet::kCapacity <= 256, "a contact's position is 8 bits of its sort key");
  bool small_indices = false;
  std::array<std::uint64_t, ContactSet::kCapacity> sort_keys{};
  std::array<ContactPc, ContactSet::kCapacity> sort_buf{};

  Impl(const Polyhedron& ma, const Polyhedron& mb, const Params& params_in)
      : a(ma), b(mb), all(params_in), prm(params_in.detection), flat_a(ma), flat_b(mb), wings_a(wings_of(ma)), wings_b(wings_of(mb)) {
    auto check = [](double v, const char* name, bool positive) {
      if (!std::isfinite(v) || v < 0 || (positive && v == 0))
        throw Error(std::string("ContactDetector: parameter ") + name + " must be " +
                    (positive ? "positive" : "non-negative") + ", got " + std::to_string(v));
    };
    const DetectionParams& p = prm;
    check(all.epsilon_mm, "epsilon_mm", true);
    check(p.max_penetration_mm, "max_penetration_mm", false);
    check(p.min_angular_tolerance_rad, "min_angular_tolerance_rad", true);
    check(p.max_angular_tolerance_rad, "max_angular_tolerance_rad", true);
    check(p.dominance_penalty, "dominance_penalty", false);
    check(p.dominance_fit, "dominance_fit", false);
    check(p.reuse_margin_mm, "reuse_margin_mm", false);
    if (!std::isfinite(p.in_plane_tolerance_mm) || !std::isfinite(p.angular_tolerance_rad))
      throw Error("ContactDetector: in_plane_tolerance_mm and angular_tolerance_rad must be finite");
    eps = all.epsilon_mm;
    depth = p.max_penetration_mm;
    in_plane = p.in_plane_tolerance_mm > 0 ? p.in_plane_tolerance_mm : eps;
    const double scale = std::max(ma.size(), mb.size());
    // Coincidence tolerance for boundaries in 2D: far below any feature, far above rounding.
    geo_tol = 1e-9 * std::max(scale, 1.0);
    area_tol = 1e-12 * std::max(scale * scale, 1.0);
    bvh_a = detail::Bvh(ma, 0.0, 1, 0.5 * (ma.bbox_min() + ma.bbox_max()), leaves_for(ma));
    // The boxes are single precision: widen B's by far more than the rounding of the
    // overlap test's few float operations on coordinates of this scale.
    double reach = ma.size() + mb.size();
    for (const Vertex& v : mb.vertices()) reach = std::max(reach, v.p.cwiseAbs().maxCoeff() + ma.size());
    const double float_slack = 1e-5 * std::max(reach, 1.0);
    orth_allow = 1e-5 * std::max({reach, bvh_a.origin().norm(), 1.0});
    // B's boxes grow by the deepest band and the in-plane allowance, so that every pair the
    // exact tests could accept has overlapping boxes.
    // A pair the tests accept is within max(eps, depth) across the plane and in_plane along
    // it, so within max(eps, depth, hypot(eps, in_plane)) of B's element.
    bvh_b = detail::Bvh(mb, std::max({eps, depth, std::hypot(eps, in_plane)}) + geo_tol + float_slack, 1, Vec3::Zero(), leaves_for(mb));
    big = is_big(ma) || is_big(mb);
    stack.resize(detail::stack_capacity(bvh_a, bvh_b));
    q_pts.resize(static_cast<std::size_t>(flat_a.max_face_points));
    std::size_t max_loops = 1;
    for (const Face& F : ma.faces()) max_loops = std::max(max_loops, F.loops.size());
    q_lb.resize(max_loops + 1);
    params.resize(static_cast<std::size_t>(
        4 + 4 * std::max(flat_a.max_face_points, flat_b.max_face_points)));
    clip_cap = flat_a.max_face_points + flat_b.max_face_points;
    clip_buf.resize(2 * static_cast<std::size_t>(clip_cap));
    aw.resize(ma.num_vertices());
    aw_stamp.assign(ma.num_vertices(), 0);
    // A face's tilt scale is its size, sqrt(area).
    for (const Face& F : ma.faces()) sin_tol_face_a.push_back(std::sin(tol_for(std::sqrt(F.area))));
    for (const Face& F : mb.faces()) sin_tol_face_b.push_back(std::sin(tol_for(std::sqrt(F.area))));
    for (const Edge& E : ma.edges()) sin_tol_edge_a.push_back(std::sin(tol_for(E.length)));
    for (const Edge& E : mb.edges()) sin_tol_edge_b.push_back(std::sin(tol_for(E.length)));
    sin_max_tol = std::sin(max_tol());
    cos_max_tol = std::cos(max_tol());
    if (big) {
      a_wide.resize(bvh_a.wide().size());
      a_elem.resize(bvh_a.elements().size());
      for (const Vertex& v : ma.vertices()) {
        a_vert.emplace_back() << (v.p - bvh_a.origin()).cast<float>(), 0.0f;
        r_a = std::max(r_a, (v.p - bvh_a.origin()).norm());
      }
      a_vert_posed.resize(ma.num_vertices());
      if (prm.use_bvh && prm.reuse_margin_mm > 0) {
        kept.resize(kMaxKept);
        kept_lin.resize(kMaxKept + 3);
        kept_rot.resize(kMaxKept + 3);
      }
    } else {
      a_box.resize(bvh_a.nodes().size());
    }
    for (const Face& F : mb.faces()) plane_b.push_back({F.normal, F.offset, 0});
    for (const Edge& E : mb.edges()) seg_b.push_back({mb.vertex(E.v0).p, E.dir, E.length, 0});
    plane_a.resize(ma.num_faces());
    seg_a.resize(ma.num_edges());
    constexpr std::size_t kKeyIndices = std::size_t{1} << 24;
    small_indices = std::max({ma.num_vertices(), ma.num_edges(), ma.num_faces(), mb.num_vertices(),
                              mb.num_edges(), mb.num_faces()}) < kKeyIndices;
  }

  // Small models: does A's BVH node `ia` (posed) overlap B's node? The axis-aligned boxes
  // in B's frame, then, for inner nodes, B's box on A's node's own axes.
  __attribute__((always_inline)) bool overlap(std::int32_t ia, const detail::BvhNode& A, const detail::BvhNode& B) {
    PosedBox& P = a_box[static_cast<std::size_t>(ia)];
    if (P.stamp != stamp) pose_box(P, A);
    const Eigen::Vector3f d = P.c - B.center;
    if (std::abs(d.x()) > P.h.x() + B.half.x() || std::abs(d.y()) > P.h.y() + B.half.y() ||
        std::abs(d.z()) > P.h.z() + B.half.z())
      return false;
    if (A.leaf()) return true;
    // B's box on A's axes: centre offset R^T d, half extents |R^T| B.half.
    for (int k = 0; k < 3; ++k) {
      const float dk = Rf(0, k) * d.x() + Rf(1, k) * d.y() + Rf(2, k) * d.z();
      const float hk = absRf(0, k) * B.half.x() + absRf(1, k) * B.half.y() + absRf(2, k) * B.half.z();
      if (std::abs(dk) > A.half[k] + hk) return false;
    }
    return true;
  }

  // A's vertex v posed, single precision (rounding as in pose_wide).
  const Eigen::Array4f& posed_vertex(VertexId v) {
    PosedVertex& P = a_vert_posed[v.index()];
    if (P.stamp != stamp) {
      const Eigen::Array4f& q = a_vert[v.index()];
      P.p = Rcol[0] * q[0] + Rcol[1] * q[1] + Rcol[2] * q[2] + a_origin;
      P.stamp = stamp;
    }
    return P.p;
  }

  // A big model's element at position i of its BVH, posed: the box of its posed vertices.
  __attribute__((noinline)) void pose_element(PosedElem& P, int i) {
    P.stamp = stamp;
    Eigen::Array4f lo = Eigen::Array4f::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
    auto add = [&](VertexId v) {
      const Eigen::Array4f& p = posed_vertex(v);
      lo = lo.min(p);
      hi = hi.max(p);
    };
    const detail::BvhElement& x = bvh_a.elements()[static_cast<std::size_t>(i)];
    switch (x.kind) {
      case ElementKind::kVertex:
        add(VertexId(x.index));
        break;
      case ElementKind::kEdge:
        add(a.edges()[static_cast<std::size_t>(x.index)].v0);
        add(a.edges()[static_cast<std::size_t>(x.index)].v1);
        break;
      case ElementKind::kFace:
        for (VertexId v : a.faces()[static_cast<std::size_t>(x.index)].vertices) add(v);
        break;
    }
    P.box.c = 0.5f * (lo + hi);
    P.box.h = (0.5f * (hi - lo) + 2.4e-7f * P.box.c.abs()) * 1.0000003f + Eigen::Array4f(grow, grow, grow, 0.0f);
  }

  // Does A's element at position ia of its BVH (posed) overlap B's element at ib?
  bool element_boxes_overlap(int ia, int ib) {
    PosedElem& P = a_elem[static_cast<std::size_t>(ia)];
    if (P.stamp != stamp) pose_element(P, ia);
    return !detail::boxes_apart(P.box, bvh_b.element_boxes()[static_cast<std::size_t>(ib)]);
  }

  // A's node at the current pose: its box in B's frame.
  __attribute__((noinline)) void pose_box(PosedBox& P, const detail::BvhNode& N) {
    P.stamp = stamp;
    detail::round_out(pose.apply(N.center.cast<double>()), absR * N.half.cast<double>(), P.c, P.h);
  }

  // A big model's wide node w at the current pose, in B's frame, in single precision. Its
  // centres are relative to bvh_a's origin (within A's size), whose posed place is computed
  // in double once per call, so the rounding (a few parts in 1e7 of A's size plus that
  // place) stays far below B's boxes' float slack wherever the two boxes could overlap. The
  // posed axis-aligned box of the oriented box bounds the node as well: the overlap of the
  // two is kept.
  const detail::Box4& posed_wide(std::int32_t w) {
    PosedWide& P = a_wide[static_cast<std::size_t>(w)];
    if (P.stamp != stamp) pose_wide(P, w);
    return P.box;
  }
  __attribute__((noinline)) void pose_wide(PosedWide& P, std::int32_t w) {
    using V = Eigen::Array4f;
    P.stamp = stamp;
    const detail::Box4& N = bvh_a.wide()[static_cast<std::size_t>(w)].box;
    detail::Box4& Q = P.box;
    // Unrolled: at -O2 GCC keeps these loops of 3 and spills the temporaries.
    CF_UNROLL3
    for (int k = 0; k < 3; ++k)
      CF_UNROLL3
      for (int i = 0; i < 3; ++i) Q.ax[k][i] = N.ax[k][0] * Rb[i][0] + N.ax[k][1] * Rb[i][1] + N.ax[k][2] * Rb[i][2];
    CF_UNROLL3
    for (int i = 0; i < 3; ++i) {
      const V c = N.c[0] * Rb[i][0] + N.c[1] * Rb[i][1] + N.c[2] * Rb[i][2] + ob[i];
      const V oc = N.oc[0] * Rb[i][0] + N.oc[1] * Rb[i][1] + N.oc[2] * Rb[i][2] + ob[i];
      const V h = N.h[0] * absRb[i][0] + N.h[1] * absRb[i][1] + N.h[2] * absRb[i][2];
      const V oh = Q.ax[0][i].abs() * N.oh[0] + Q.ax[1][i].abs() * N.oh[1] + Q.ax[2][i].abs() * N.oh[2];
      const V lo = (c - h).max(oc - oh), hi = (c + h).min(oc + oh);
      Q.c[i] = 0.5f * (lo + hi);
      // Widened by the rounding of the midpoint and of the half difference.
      Q.h[i] = ((0.5f * (hi - lo)).max(0.0f) + 2.4e-7f * Q.c[i].abs()) * 1.0000003f + grow;
      Q.oc[i] = oc;
      Q.oh[i] = N.oh[i] + grow;
    }
  }

  // The largest angular tolerance any pair can get: a cheap early out before the contact
  // region, and with it the pair's own tolerance, is known.
  double max_tol() const { return prm.angular_tolerance_rad > 0 ? prm.angular_tolerance_rad : prm.max_angular_tolerance_rad; }

  double tol_for(double extent) const {
    if (prm.angular_tolerance_rad > 0) return prm.angular_tolerance_rad;
    const double t = std::atan(eps / std::max(extent, 1e-12));
    return std::clamp(t, prm.min_angular_tolerance_rad, prm.max_angular_tolerance_rad);
  }

  // Does the solid around edge E stay on the +n side of a contact plane (n in E's model
  // frame)? Both wings (the in-face directions into its faces) may dip below the plane by
  // at most their face's angular tolerance.
  static bool wedge_above(const Vec3& n, const EdgeWings& w, const Edge& E, const std::vector<double>& sin_tol_face) {
    return n.dot(w.left) >= -sin_tol_face[E.left.index()] && n.dot(w.right) >= -sin_tol_face[E.right.index()];
  }
  // How far the deeper wing dips below the tolerance (> 0 exactly when not wedge_above).
  static double wedge_dip(const Vec3& n, const EdgeWings& w, const Edge& E, const std::vector<double>& sin_tol_face) {
    return std::max(-sin_tol_face[E.left.index()] - n.dot(w.left), -sin_tol_face[E.right.index()] - n.dot(w.right));
  }
  // The certificate of a distance `gap` of B's point(s), at most `reach` from A's posed
  // origin o, as A sees them: R^T (q - o) + R^T R o_A moves at most the motion bound times
  // max(1, reach / r_a), plus the change of R^T R o_A, which is o_A for a rotation and at
  // most orth_allow from it at the poses kept pairs serve.
  double seen_from_a(double gap, double reach) const {
    return (gap - 2 * orth_allow) / std::max(1.0, reach / r_a) - geo_tol;
  }
  // A pair turned away for good whatever the pose (a reflex edge).
  void never() { cert.rot = std::numeric_limits<double>::infinity(); }

  const Vec3& world(VertexId v) {
    const std::size_t i = v.index();
    if (aw_stamp[i] != stamp) {
      aw[i] = pose.apply(a.vertex(v).p);
      aw_stamp[i] = stamp;
    }
    return aw[i];
  }

  void emit(PcType type, int ia, int ib, double d, const Vec3& p_W, const Vec3& origin,
            const Mat3& R_WT, double misfit) {
    ContactPc c;
    c.pc = {type, ia, ib};
    c.distance = d;
    c.p_W = p_W;
    c.origin_W = origin;
    c.R_WT = R_WT;
    c.misfit = misfit;
    out->push(c);
  }

  bool in_band(double d) const { return d <= eps && d >= -depth; }

  // ---- v-f: vertex of A on face of B ------------------------------------------------------
  void vf(int v, int fb) {
    const Face& F = b.faces()[static_cast<std::size_t>(fb)];
    const Vec3& p = world(VertexId(v));
    const double h = F.normal.dot(p) - F.offset;
    if (!in_band(h)) return;
    // A's edges at the vertex must not run into B (beyond the angular tolerance).
    for (EdgeId e : a.vertex(VertexId(v)).edges) {
      const Edge& E = a.edge(e);
      const Vec3& q = world(E.v0 == VertexId(v) ? E.v1 : E.v0);
      const double w = F.normal.dot(q - p), lim = -sin_tol_edge_a[e.index()] * E.length;
      if (w < lim) {
        // q - p, of length E.length, turns with A.
        cert.rot = (lim - w) / E.length - geo_tol;
        return;
      }
    }
    const detail::Loc2 loc = detail::locate(flat_b.poly(fb), Vec2(F.u.dot(p), F.v.dot(p)));
    const double gap = (loc.inside || loc.dist <= geo_tol) ? 0.0 : loc.dist;
    if (gap > in_plane) {
      // The vertex's projection on B's plane moves at most as far as the vertex.
      cert.lin = gap - in_plane - geo_tol;
      return;
    }
    emit(PcType::kVF, v, fb, h, p, p - h * F.normal, task_frame(F.normal, F.u),
         std::abs(h) / eps + gap / eps);
  }

  // ---- f-v: face of A on vertex of B -------------------------------------------------------
  void fv(int fa, int v) {
    const Face& F = a.faces()[static_cast<std::size_t>(fa)];
    const Vec3& q = b.vertex(VertexId(v)).p;
    const Vec3 qA = pose.inverse_apply(q);
    const double h = F.normal.dot(qA) - F.offset;
    if (!in_band(h)) return;
    for (EdgeId e : b.vertex(VertexId(v)).edges) {
      const Edge& E = b.edge(e);
      const Vec3& o = b.vertex(E.v0 == VertexId(v) ? E.v1 : E.v0).p;
      const Vec3 wA = pose.R_BA.transpose() * (o - q);
      const double w = F.normal.dot(wA), lim = -sin_tol_edge_b[e.index()] * E.length;
      if (w < lim) {
        cert.rot = (lim - w) / E.length - geo_tol;
        return;
      }
    }
    const detail::Loc2 loc = detail::locate(flat_a.poly(fa), Vec2(F.u.dot(qA), F.v.dot(qA)));
    const double gap = (loc.inside || loc.dist <= geo_tol) ? 0.0 : loc.dist;
    if (gap > in_plane) {
      // B's vertex as A sees it, R^T (q - o) + const, moves at most the bound times
      // max(1, |q - o| / r_a).
      if (certifying) cert.lin = seen_from_a(gap - in_plane, (q - origin_posed).norm());
      return;
    }
    const Vec3 nW = pose.R_BA * F.normal;
    const Vec3 onA = q - h * nW;
    emit(PcType::kFV, fa, v, h, onA, onA, task_frame(-nW, pose.R_BA * F.u),
         std::abs(h) / eps + gap / eps);
  }

  // Line contact of segment s0->s1 (in the face's model frame) against face f of model m
  // (flat f): shared by e-f (m = B, segment world) and f-e (m = A, segment in A's frame).
  // Returns false when not a contact; else the region's centroid parameter, its deepest
  // height, the in-plane gap and the region's extent as a share of the segment (from the
  // first to the last point over the face; 0 beside the face). Turned away for the
  // segment's heights or its in-plane gap, it leaves in cert.lin how far the segment must
  // move (in the face's frame) to pass them.
  bool line_on_face(const Polyhedron& m, const FlatFaces& flat, int f, const Vec3& s0,
                    const Vec3& s1, double* t_c, double* d, double* gap, double* span) {
    const Face& F = m.faces()[static_cast<std::size_t>(f)];
    const double h0 = F.normal.dot(s0) - F.offset, h1 = F.normal.dot(s1) - F.offset;
    if (std::min(h0, h1) > eps || std::max(h0, h1) < -depth) {
      cert.lin = std::max(std::min(h0, h1) - eps, -depth - std::max(h0, h1));
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
      if (detail::clip_segment_convex(a2, b2, flat.poly(f), geo_tol, &t0, &t1)) piece(t0, t1);
    } else {
      detail::clip_segment(a2, b2, flat.poly(f), geo_tol, detail::OnBoundary::kInclude, params.data(), piece);
    }
    if (len > 1e-12) {
      *t_c = moment / len;
      *d = dmin;
      *gap = 0;
      *span = last - first;
    } else {
      // Beside the face: the nearest in-plane approach to its boundary.
      const detail::Poly2 P = flat.poly(f);
      double best = std::numeric_limits<double>::infinity(), tb = 0;
      for (int l = 0; l < P.num_loops; ++l)
        for (int i = P.lb[l]; i < P.lb[l + 1]; ++i) {
          double t;
          const double g = segment_segment_2d(a2, b2, P.pts[i],
                                              P.pts[i + 1 == P.lb[l + 1] ? P.lb[l] : i + 1], &t);
          if (g < best) best = g, tb = t;
        }
      if (best > in_plane) {
        cert.lin = best - in_plane;
        return false;
      }
      *t_c = tb;
      *d = h0 + tb * (h1 - h0);
      *gap = best;
      *span = 0;
    }
    return in_band(*d);
  }

  // ---- e-f: edge of A on face of B ---------------------------------------------------------
  void ef(int e, int fb) {
    const Edge& E = a.edges()[static_cast<std::size_t>(e)];
    if (!E.convex) return never();
    const Face& F = b.faces()[static_cast<std::size_t>(fb)];
    const Vec3& p0 = world(E.v0);
    const Vec3& p1 = world(E.v1);
    const Vec3 dW = pose.R_BA * E.dir;
    const double sin_ang = std::min(1.0, std::abs(dW.dot(F.normal)));
    if (sin_ang > sin_max_tol) return;
    const double dip = wedge_dip(pose.R_BA.transpose() * F.normal, wings_a[static_cast<std::size_t>(e)], E, sin_tol_face_a);
    if (dip > 0) {
      cert.rot = dip - geo_tol;
      return;
    }
    double tc, d, gap, span;
    if (!line_on_face(b, flat_b, fb, p0, p1, &tc, &d, &gap, &span)) {
      cert.lin -= geo_tol;  // A's segment moves at most the bound
      return;
    }
    // The tilt at which the part of the edge over the face stays within epsilon (the whole
    // edge beside the face).
    const double tol = tol_for(span > 0 ? span * E.length : E.length);
    const double ang = std::asin(sin_ang);
    if (ang > tol) return;
    const Vec3 p = p0 + tc * (p1 - p0);
    const double hc = F.normal.dot(p) - F.offset;
    emit(PcType::kEF, e, fb, d, p, p - hc * F.normal, task_frame(F.normal, dW),
         ang / tol + std::abs(d) / eps + gap / eps);
  }

  // ---- f-e: face of A on edge of B ---------------------------------------------------------
  void fe(int fa, int e) {
    const Edge& E = b.edges()[static_cast<std::size_t>(e)];
    if (!E.convex) return never();
    const Face& F = a.faces()[static_cast<std::size_t>(fa)];
    const Mat3 Rt = pose.R_BA.transpose();
    const Vec3 dA = Rt * E.dir;
    const double sin_ang = std::min(1.0, std::abs(dA.dot(F.normal)));
    if (sin_ang > sin_max_tol) return;
    const double dip = wedge_dip(pose.R_BA * F.normal, wings_b[static_cast<std::size_t>(e)], E, sin_tol_face_b);
    if (dip > 0) {
      cert.rot = dip - geo_tol;
      return;
    }
    const Vec3& q0 = b.vertex(E.v0).p;
    const Vec3& q1 = b.vertex(E.v1).p;
    const Vec3 q0A = pose.inverse_apply(q0), q1A = pose.inverse_apply(q1);
    double tc, d, gap, span;
    if (!line_on_face(a, flat_a, fa, q0A, q1A, &tc, &d, &gap, &span)) {
      // B's segment as A sees it moves at most the bound times max(1, |q - o| / r_a).
      if (certifying) cert.lin = seen_from_a(cert.lin, std::max((q0 - origin_posed).norm(), (q1 - origin_posed).norm()));
      return;
    }
    const double tol = tol_for(span > 0 ? span * E.length : E.length);
    const double ang = std::asin(sin_ang);
    if (ang > tol) return;
    const Vec3 qcA = q0A + tc * (q1A - q0A);
    const Vec3 onA = pose.apply(qcA - (F.normal.dot(qcA) - F.offset) * F.normal);
    emit(PcType::kFE, fa, e, d, onA, onA, task_frame(-(pose.R_BA * F.normal), E.dir),
         ang / tol + std::abs(d) / eps + gap / eps);
  }

  // ---- f-f: face of A on face of B ---------------------------------------------------------
  void ff(int fa, int fb) {
    const Face& FA = a.faces()[static_cast<std::size_t>(fa)];
    const Face& FB = b.faces()[static_cast<std::size_t>(fb)];
    const Vec3 nA = pose.R_BA * FA.normal;
    const double c = -nA.dot(FB.normal);
    if (c < cos_max_tol) return;
    double hmin = std::numeric_limits<double>::infinity(), hmax = -hmin;
    for (VertexId v : FA.vertices) {
      const double h = FB.normal.dot(world(v)) - FB.offset;
      hmin = std::min(hmin, h);
      hmax = std::max(hmax, h);
    }
    if (hmin > eps || hmax < -depth) return;
    // A's loops in B's face frame, reversed so that they run positively there.
    int n = 0, nl = 0;
    for (const auto& loop : FA.loops) {
      q_lb[static_cast<std::size_t>(nl++)] = n;
      for (std::size_t k = loop.size(); k-- > 0;) {
        const Vec3& p = world(loop[k]);
        q_pts[static_cast<std::size_t>(n++)] = Vec2(FB.u.dot(p), FB.v.dot(p));
      }
    }
    q_lb[static_cast<std::size_t>(nl)] = n;
    const detail::Poly2 Q{q_pts.data(), q_lb.data(), nl};
    // Height of A's plane above B's plane at in-plane point (x, y): linear.
    const double nn = nA.dot(FB.normal);
    const double offA = nA.dot(pose.t_BA) + FA.offset;
    const double ku = nA.dot(FB.u) / nn, kv = nA.dot(FB.v) / nn, k0 = offA / nn - FB.offset;
    auto height = [&](const Vec2& q) { return k0 - ku * q.x() - kv * q.y(); };
    // The tilt's direction in B's plane: the overlap's extent along it is what the tilt
    // raises (orientation-independent, unlike a bounding box of the overlap).
    const Vec2 grad(ku, kv);
    const Vec2 g_dir = grad.norm() > 1e-12 ? Vec2(grad.normalized()) : Vec2(1, 0);
    double dmin = std::numeric_limits<double>::infinity();
    double s_lo = std::numeric_limits<double>::infinity(), s_hi = -s_lo;
    const auto visit = [&](const Vec2& q) {
      dmin = std::min(dmin, height(q));
      const double s = q.dot(g_dir);
      s_lo = std::min(s_lo, s);
      s_hi = std::max(s_hi, s);
    };
    detail::Overlap2 ov;
    if (!(flat_a.convex[static_cast<std::size_t>(fa)] && flat_b.convex[static_cast<std::size_t>(fb)] &&
          detail::overlap_convex(flat_b.poly(fb), Q, clip_buf.data(), clip_cap, ov, visit)))
      ov = detail::overlap(flat_b.poly(fb), Q, geo_tol, params.data(), visit);
    if (!(ov.area > area_tol)) return;
    // The tilt at which the whole overlap stays within epsilon.
    const double tol = tol_for(s_hi - s_lo);
    const double ang = std::acos(std::min(1.0, c));
    if (ang > tol || !in_band(dmin)) return;
    const Vec3 origin = ov.centroid.x() * FB.u + ov.centroid.y() * FB.v + FB.offset * FB.normal;
    emit(PcType::kFF, fa, fb, dmin, origin + height(ov.centroid) * FB.normal, origin,
         task_frame(FB.normal, FB.u), ang / tol + std::abs(dmin) / eps);
  }

  // ---- e-e: edge of A crossing edge of B ---------------------------------------------------
  void ee(int ea, int eb) {
    const Edge& EA = a.edges()[static_cast<std::size_t>(ea)];
    const Edge& EB = b.edges()[static_cast<std::size_t>(eb)];
    if (!EA.convex || !EB.convex) return never();
    const Vec3& p0 = world(EA.v0);
    const Vec3 uA = pose.R_BA * EA.dir;
    const Vec3& q0 = b.vertex(EB.v0).p;
    const Vec3& uB = EB.dir;
    Vec3 n = uA.cross(uB);
    const double sn = n.norm();
    // The tolerance of the shorter edge (atan(eps / L) falls with L): the larger sine.
    if (sn <= std::max(sin_tol_edge_a[static_cast<std::size_t>(ea)], sin_tol_edge_b[static_cast<std::size_t>(eb)]))
      return;  // near-parallel: not e-e
    n /= sn;
    // Closest points of the two lines (unit directions): s along A, t along B.
    const Vec3 r = p0 - q0;
    const double bb = uA.dot(uB), c = uA.dot(r), f = uB.dot(r);
    const double den = 1 - bb * bb;
    const double s = (bb * f - c) / den;
    const double t = (f - bb * c) / den;
    const double over = std::max({0.0, -s, s - EA.length}) + std::max({0.0, -t, t - EB.length});
    if (over > in_plane) return;
    const Vec3 pA = p0 + std::clamp(s, 0.0, EA.length) * uA;
    const Vec3 pB = q0 + std::clamp(t, 0.0, EB.length) * uB;
    const Vec3 sumB = b.face(EB.left).normal + b.face(EB.right).normal;
    const Vec3 sA = a.face(EA.left).normal + a.face(EA.right).normal;
    const Vec3 sumA = pose.R_BA * sA;
    const double side = n.dot(sumB - sumA);
    if (side < 0) n = -n;
    const double d = (pA - pB).dot(n);
    if (!in_band(d)) return;
    // The wedges of the two edges must lie on their own sides of the contact plane.
    const double dip_a = wedge_dip(pose.R_BA.transpose() * n, wings_a[static_cast<std::size_t>(ea)], EA, sin_tol_face_a);
    const double dip_b = wedge_dip(-n, wings_b[static_cast<std::size_t>(eb)], EB, sin_tol_face_b);
    if (dip_a > 0 || dip_b > 0) {
      // n = m / |m| (m = uA x uB, |m| = sn) turns by at most 2 |dm| / sn <= 2 rho / sn, A's
      // view of it by rho more; `side` moves by at most rho (2 |sumB - sumA| / sn + |sA|),
      // and n's sign holds while it does not reach 0.
      const double turn = std::max(dip_a / (1 + 2 / sn), dip_b * sn / 2);
      const double flip = std::abs(side) / (2 * (sumB - sumA).norm() / sn + sA.norm());
      cert.rot = std::min(turn, flip) - geo_tol;
      return;
    }
    emit(PcType::kEE, ea, eb, d, pA, pB, task_frame(n, uB), std::abs(d) / eps + over / eps);
  }

  const Plane& posed_plane_a(int f) {
    Plane& P = plane_a[static_cast<std::size_t>(f)];
    if (P.stamp != stamp) {
      const Face& F = a.faces()[static_cast<std::size_t>(f)];
      P.n = pose.R_BA * F.normal;
      P.off = F.offset + P.n.dot(pose.t_BA);
      P.stamp = stamp;
    }
    return P;
  }
  const Seg& posed_seg_a(int e) {
    Seg& S = seg_a[static_cast<std::size_t>(e)];
    if (S.stamp != stamp) {
      const Edge& E = a.edges()[static_cast<std::size_t>(e)];
      S.p0 = world(E.v0);
      S.dir = pose.R_BA * E.dir;
      S.len = E.length;
      S.stamp = stamp;
    }
    return S;
  }
  // Cheap necessary conditions of each type's exact test (same tolerances, looser or
  // equal), so that most pairs are turned away before the exact test loads the features.
  bool segment_in_band(const Vec3& p0, const Vec3& dir, double len, const Vec3& n, double off) const {
    const double h0 = n.dot(p0) - off, h1 = h0 + len * n.dot(dir);
    return std::min(h0, h1) <= eps + geo_tol && std::max(h0, h1) >= -depth - geo_tol;
  }
  // in_band with room for the rounding of a differently ordered computation.
  bool near_band(double d) const { return d <= eps + geo_tol && d >= -depth - geo_tol; }
  // How far heights h0 <= h1 (or one height) lie outside near_band's band.
  double band_gap(double lo, double hi) const { return std::max(lo - eps - geo_tol, -depth - geo_tol - hi); }

  // With kCertify, a pair turned away also gets its certificate in *ct. A height over B's
  // plane moves at most as far as A's points. A unit vector of A turns by at most
  // |R1 - R0|_F, so a dot product's margin d is a rotational certificate d. A height over
  // A's plane of B's point q is (R n_A).(q - o) up to a constant (o: A's origin posed), so
  // it moves by at most the motion bound times max(1, |q - o| / r_a). Where two conditions
  // fail, either one keeps the pair away.
  template <bool kCertify>
  __attribute__((always_inline)) bool may_touch(ElementKind ka, int ia, ElementKind kb, int ib, Cert* ct) {
    using K = ElementKind;
    if (ka == K::kVertex) {  // v-f
      const Plane& B = plane_b[static_cast<std::size_t>(ib)];
      const double h = B.n.dot(world(VertexId(ia))) - B.off;
      if (near_band(h)) return true;
      if constexpr (kCertify) ct->lin = band_gap(h, h) - geo_tol;
      return false;
    }
    if (ka == K::kEdge) {
      const Seg& A = posed_seg_a(ia);
      if (kb == K::kFace) {  // e-f
        const Plane& B = plane_b[static_cast<std::size_t>(ib)];
        const double tilt = std::abs(A.dir.dot(B.n)) - (sin_max_tol + 1e-12);
        if constexpr (!kCertify) {
          return tilt <= 0 && segment_in_band(A.p0, A.dir, A.len, B.n, B.off);
        } else {
          const double h0 = B.n.dot(A.p0) - B.off, h1 = h0 + A.len * B.n.dot(A.dir);
          const double gap = band_gap(std::min(h0, h1), std::max(h0, h1));
          if (tilt <= 0 && gap <= 0) return true;
          ct->lin = gap - geo_tol;
          ct->rot = tilt - geo_tol;
          return false;
        }
      }
      // e-e: not near-parallel, and the lines within the band of each other.
      const Seg& B = seg_b[static_cast<std::size_t>(ib)];
      const Vec3 n = A.dir.cross(B.dir);
      const double sn = n.norm();
      const double parallel =
          std::max(sin_tol_edge_a[static_cast<std::size_t>(ia)], sin_tol_edge_b[static_cast<std::size_t>(ib)]) - 1e-12 - sn;
      if (parallel >= 0) {
        // n turns by at most as much as A's direction.
        if constexpr (kCertify) ct->rot = parallel - geo_tol;
        return false;
      }
      const Vec3 r = A.p0 - B.p0;
      const double band = std::max(eps, depth) + geo_tol;
      const double apart = std::abs(n.dot(r)) - band * sn;
      if (apart > 0) {
        // n.r moves by at most |dn| |r| + |dr| (|n| <= 1, |dn| <= bound / r_a, |dr| <=
        // bound), band sn by band |dn|.
        if constexpr (kCertify) ct->lin = apart / (1 + (r.norm() + band) / r_a) - geo_tol;
        return false;
      }
      // The lines' closest points (as in ee) beyond the segments by at most in_plane.
      const double bb = A.dir.dot(B.dir), c = A.dir.dot(r), f = B.dir.dot(r);
      const double den = 1 - bb * bb;
      const double s = (bb * f - c) / den, t = (f - bb * c) / den;
      if (std::max({0.0, -s, s - A.len}) + std::max({0.0, -t, t - B.len}) <= in_plane + geo_tol) return true;
      // No certificate: the closest points move too fast near parallel.
      return false;
    }
    const Plane& A = posed_plane_a(ia);
    if (kb == K::kFace) {  // f-f
      const double tilt = cos_max_tol - 1e-12 + A.n.dot(plane_b[static_cast<std::size_t>(ib)].n);
      if (tilt <= 0) return true;
      if constexpr (kCertify) ct->rot = tilt - geo_tol;
      return false;
    }
    if (kb == K::kEdge) {  // f-e
      const Seg& B = seg_b[static_cast<std::size_t>(ib)];
      const double tilt = std::abs(A.n.dot(B.dir)) - (sin_max_tol + 1e-12);
      if constexpr (!kCertify) {
        return tilt <= 0 && segment_in_band(B.p0, B.dir, B.len, A.n, A.off);
      } else {
        const double h0 = A.n.dot(B.p0) - A.off, h1 = h0 + B.len * A.n.dot(B.dir);
        const double gap = band_gap(std::min(h0, h1), std::max(h0, h1));
        if (tilt <= 0 && gap <= 0) return true;
        const double reach = std::max((B.p0 - origin_posed).norm(), (B.p0 + B.len * B.dir - origin_posed).norm());
        ct->lin = seen_from_a(gap, reach);
        ct->rot = tilt - geo_tol;
        return false;
      }
    }
    const Vec3& q = b.vertex(VertexId(ib)).p;  // f-v
    const double h = A.n.dot(q) - A.off;
    if (near_band(h)) return true;
    if constexpr (kCertify) ct->lin = seen_from_a(band_gap(h, h), (q - origin_posed).norm());
    return false;
  }

  // Elements at positions ia, ib of the two BVHs' element lists, in leaves that overlap
  // where B's leaves hold no element lanes (B small).
  __attribute__((always_inline)) void pair(int ia, int ib) {
    const detail::BvhElement& x = bvh_a.elements()[static_cast<std::size_t>(ia)];
    const detail::BvhElement& y = bvh_b.elements()[static_cast<std::size_t>(ib)];
    if (!detail::kinds_can_touch(detail::kind_bit(x.kind), detail::kind_bit(y.kind))) return;
    if (big && !element_boxes_overlap(ia, ib)) return;
    boxed_pair(ia, ib, x, y);
  }

  // The kept pairs at a pose served from them: those whose certificates do not hold
  // (four checked at once) go through the cheap rejections and the exact test, and get
  // their new certificates. Not through the element boxes: with the certificates, posing
  // A's elements for them cost more than the boxes saved (5% more instructions).
  void reuse_kept() {
    // Rounded up, so that a skip is never wrong by rounding.
    const float moved = static_cast<float>(moved_from_kept) * 1.000001f;
    const float turned = static_cast<float>(turned_from_kept) * 1.000001f;
    const Eigen::Array4f moved4 = Eigen::Array4f::Constant(moved), turned4 = Eigen::Array4f::Constant(turned);
    for (std::size_t k = 0; k < num_kept; k += 4) {
      const Eigen::Map<const Eigen::Array4f> lin(kept_lin.data() + k), rot(kept_rot.data() + k);
      unsigned test = ~(detail::greater_mask4(lin, moved4) | detail::greater_mask4(rot, turned4)) & 0xFu;
      while (test != 0) {
        const std::size_t i = k + static_cast<std::size_t>(__builtin_ctz(test));
        test &= test - 1;
        kept_pair(i);
      }
    }
  }

  __attribute__((always_inline)) void kept_pair(std::size_t i) {
    const int ia = kept[i].a, ib = kept[i].b;
    const detail::BvhElement& x = bvh_a.elements()[static_cast<std::size_t>(ia)];
    const detail::BvhElement& y = bvh_b.elements()[static_cast<std::size_t>(ib)];
    ++pairs;
    store(i, certified_test(x, y));
  }

  // The cheap rejection and the exact test of a pair, for kept pairs: the certificate of
  // whichever turned it away (none when it passed both).
  __attribute__((always_inline)) Cert certified_test(const detail::BvhElement& x, const detail::BvhElement& y) {
    Cert c;
    if (may_touch<true>(x.kind, x.index, y.kind, y.index, &c)) {
      cert = Cert{};
      exact(x, y);
      c = cert;
    }
    return c;
  }

  // Keeps pair i's certificate, from this call's pose, counted from kept_pose.
  void store(std::size_t i, const Cert& c) {
    const double lin = c.lin - moved_from_kept, rot = c.rot - turned_from_kept;
    kept_lin[i] = lin > 0 ? static_cast<float>(lin) * 0.999999f : 0.0f;
    kept_rot[i] = rot > 0 ? static_cast<float>(rot) * 0.999999f : 0.0f;
  }

  // Leaves of the two BVHs whose boxes overlap: their element pairs whose kinds can touch
  // and whose own boxes overlap. B's face-group leaves hold their element boxes on SIMD
  // lanes: each of A's elements is tested against all of them at once.
  void leaf_pair(const detail::BvhNode& A, const detail::BvhNode& B) {
    if (bvh_b.leaf_boxes().empty()) {
      for (int i = 0; i < A.count; ++i)
        for (int j = 0; j < B.count; ++j) pair(A.element() + i, B.element() + j);
      return;
    }
    const detail::LeafBoxes& L = bvh_b.leaf_boxes()[static_cast<std::size_t>(bvh_b.leaf_index(B))];
    for (int i = 0; i < A.count; ++i) {
      const int ia = A.element() + i;
      const detail::BvhElement& x = bvh_a.elements()[static_cast<std::size_t>(ia)];
      unsigned lanes = L.touchable_by[static_cast<std::size_t>(x.kind)];
      if (lanes == 0) continue;
      PosedElem& P = a_elem[static_cast<std::size_t>(ia)];
      if (P.stamp != stamp) pose_element(P, ia);
      lanes &= detail::overlapping_lanes(P.box, L);
      while (lanes != 0) {
        const int ib = B.element() + __builtin_ctz(lanes);
        lanes &= lanes - 1;
        boxed_pair(ia, ib, x, bvh_b.elements()[static_cast<std::size_t>(ib)]);
      }
    }
  }

  // A pair past the kinds and the boxes.
  __attribute__((always_inline)) void boxed_pair(int ia, int ib, const detail::BvhElement& x,
                                                 const detail::BvhElement& y) {
    ++pairs;
    if (!recording) {
      if (may_touch<false>(x.kind, x.index, y.kind, y.index, nullptr)) exact(x, y);
      return;
    }
    const Cert c = certified_test(x, y);
    if (num_kept < kept.size()) {
      kept[num_kept] = {ia, ib};
      store(num_kept++, c);
    } else {
      kept_overflow = true;
    }
  }

  // Bounds how far any point of A moves from pose p0 to p1 (mm): the move of bvh_a's origin
  // plus |R1 - R0| times A's reach from it (Frobenius norm, a bound of the spectral norm for
  // any matrices).
  double motion_bound(const Pose& p0, const Pose& p1) const {
    const Vec3& o = bvh_a.origin();
    return (p1.apply(o) - p0.apply(o)).norm() + (p1.R_BA - p0.R_BA).norm() * r_a;
  }

  void exact(const detail::BvhElement& x, const detail::BvhElement& y) {
    using K = ElementKind;
    switch (x.kind) {
      case K::kVertex:
        if (y.kind == K::kFace) vf(x.index, y.index);
        break;
      case K::kEdge:
        if (y.kind == K::kFace) ef(x.index, y.index);
        else if (y.kind == K::kEdge) ee(x.index, y.index);
        break;
      case K::kFace:
        if (y.kind == K::kFace) ff(x.index, y.index);
        else if (y.kind == K::kEdge) fe(x.index, y.index);
        else fv(x.index, y.index);
        break;
    }
  }

  // Sorts the contacts by PC. On packed keys (type, a, b, position) and then one gather:
  // an insertion sort moving 160-byte contacts cost half of finish() on 70 contacts. A few
  // contacts (the paper's blocks) sort faster as they are.
  static constexpr int kFewContacts = 8;
  void sort_contacts(ContactSet& cs) {
    const int n = cs.size();
    if (!small_indices || n <= kFewContacts) {
      std::sort(cs.begin(), cs.end(), [](const ContactPc& x, const ContactPc& y) { return x.pc < y.pc; });
      return;
    }
    for (int i = 0; i < n; ++i) {
      const Pc& p = cs[i].pc;
      sort_keys[static_cast<std::size_t>(i)] = static_cast<std::uint64_t>(p.type) << 56 |
                                               static_cast<std::uint64_t>(p.a) << 32 |
                                               static_cast<std::uint64_t>(p.b) << 8 | static_cast<std::uint64_t>(i);
    }
    std::sort(sort_keys.begin(), sort_keys.begin() + n);
    int first_moved = 0;
    while (first_moved < n && (sort_keys[static_cast<std::size_t>(first_moved)] & 0xFFu) == static_cast<std::uint64_t>(first_moved))
      ++first_moved;
    for (int i = first_moved; i < n; ++i)
      sort_buf[static_cast<std::size_t>(i)] = cs[static_cast<int>(sort_keys[static_cast<std::size_t>(i)] & 0xFFu)];
    for (int i = first_moved; i < n; ++i) cs[i] = sort_buf[static_cast<std::size_t>(i)];
  }

  void finish(ContactSet& cs) {
    sort_contacts(cs);
    const int n = cs.size();
    // Dominance (SPEC 4) by a contact whose shape fits well: its misfit without the distance
    // term (angle / tolerance + in-plane gap / epsilon) is at most dominance_fit. A looser
    // dominator (a face tilted by more than that share of its tolerance over an edge that
    // touches exactly) does not settle the reading: both stand and the previous CF or the fit
    // decides (a hysteresis band instead of a flip at the tolerance). misfit is not changed
    // until every flag is set, so the shapes below are the emitted ones.
    // A dominator's elements hold this one's: of the same or a higher dimension on each
    // side and a higher one on one side at least (two distinct PCs of the same kinds never
    // hold one another). So only f-f, e-f and f-e dominate (below them: v-v, v-e and e-v,
    // which are not PCs), and each type has its possible dominators' types.
    std::array<int, 3> num_dom{};  // f-f, e-f, f-e: PcType's first three
    static_assert(static_cast<int>(PcType::kFF) == 0 && static_cast<int>(PcType::kEF) == 1 &&
                  static_cast<int>(PcType::kFE) == 2);
    for (int j = 0; j < n; ++j) {
      const ContactPc& cj = cs[j];
      const auto t = static_cast<std::size_t>(cj.pc.type);
      if (t < 3 && cj.misfit - std::abs(cj.distance) / eps <= prm.dominance_fit)
        dominators[t][static_cast<std::size_t>(num_dom[t]++)] = j;
    }
    const auto dominated_by = [&](const ContactPc& ci, PcType type) {
      const auto t = static_cast<std::size_t>(type);
      const ElementKind ai = a_kind(ci.pc.type), bi = b_kind(ci.pc.type), aj = a_kind(type), bj = b_kind(type);
      for (int k = 0; k < num_dom[t]; ++k) {
        const ContactPc& cj = cs[dominators[t][static_cast<std::size_t>(k)]];
        if (in_closure(a, ai, ci.pc.a, aj, cj.pc.a) && in_closure(b, bi, ci.pc.b, bj, cj.pc.b))
          return true;
      }
      return false;
    };
    for (ContactPc& ci : cs) {
      if (num_dom[0] + num_dom[1] + num_dom[2] == 0) break;
      switch (ci.pc.type) {
        case PcType::kFF:
          break;
        case PcType::kEF:
        case PcType::kFE:
          ci.dominated = dominated_by(ci, PcType::kFF);
          break;
        case PcType::kVF:
          ci.dominated = dominated_by(ci, PcType::kEF) || dominated_by(ci, PcType::kFF);
          break;
        case PcType::kFV:
          ci.dominated = dominated_by(ci, PcType::kFE) || dominated_by(ci, PcType::kFF);
          break;
        case PcType::kEE:
          ci.dominated = dominated_by(ci, PcType::kEF) || dominated_by(ci, PcType::kFE) ||
                         dominated_by(ci, PcType::kFF);
          break;
      }
    }
    for (ContactPc& c : cs)
      if (c.dominated) c.misfit += prm.dominance_penalty;
    // Contact planes: greedy clustering in canonical order.
    const double cos_tol = std::cos(prm.angular_tolerance_rad > 0 ? prm.angular_tolerance_rad
                                                              : prm.max_angular_tolerance_rad);
    int groups = 0;
    for (int i = 0; i < n; ++i) {
      ContactPc& ci = cs[i];
      const Vec3 ni = ci.R_WT.col(1);
      // Compare with each group's first member.
      for (int g = 0; g < groups; ++g) {
        const ContactPc& cj = cs[reps[static_cast<std::size_t>(g)]];
        const Vec3 nj = cj.R_WT.col(1);
        if (ni.dot(nj) >= cos_tol && std::abs(nj.dot(ci.origin_W - cj.origin_W)) <= eps &&
            std::abs(ni.dot(cj.origin_W - ci.origin_W)) <= eps) {
          ci.plane = static_cast<std::int16_t>(g);
          break;
        }
      }
      if (ci.plane < 0) {
        reps[static_cast<std::size_t>(groups)] = i;
        ci.plane = static_cast<std::int16_t>(groups++);
      }
    }
    cs.set_num_planes(groups);
  }

  void detect(const Pose& p, ContactSet& cs) {
    pose = p;
    out = &cs;
    cs.clear();
    pairs = 0;
    ++stamp;  // 64 bits: never wraps, so the per-pose caches need no reset
    if (!prm.use_bvh) {
      // Every pair straight to the exact tests: the reference for the culling (boxes and
      // the cheap rejections alike).
      for (const detail::BvhElement& x : bvh_a.elements())
        for (const detail::BvhElement& y : bvh_b.elements()) {
          ++pairs;
          exact(x, y);
        }
      finish(cs);
      out = nullptr;
      return;
    }
    absR = pose.R_BA.cwiseAbs();
    Rf = pose.R_BA.cast<float>();
    absRf = absR.cast<float>();
    for (int k = 0; k < 3; ++k) Rcol[k] << Rf.col(k), 0.0f;
    origin_posed = pose.apply(bvh_a.origin());
    a_origin << origin_posed.cast<float>(), 0.0f;
    for (int i = 0; i < 3 && big; ++i) {
      for (int k = 0; k < 3; ++k) {
        Rb[i][k].setConstant(Rf(i, k));
        absRb[i][k].setConstant(absRf(i, k));
      }
      ob[i].setConstant(a_origin[i]);
    }
    reused = false;
    grow = 0;
    recording = false;
    if (!kept.empty()) {
      const double moved = have_last ? motion_bound(last_pose, pose) : std::numeric_limits<double>::infinity();
      last_pose = pose;
      have_last = true;
      const bool rotation = ((pose.R_BA.transpose() * pose.R_BA - Mat3::Identity()) * bvh_a.origin()).norm() <= orth_allow;
      moved_from_kept = kept_valid ? motion_bound(kept_pose, pose) : std::numeric_limits<double>::infinity();
      if (rotation && moved_from_kept <= prm.reuse_margin_mm) {
        reused = true;
        turned_from_kept = (pose.R_BA - kept_pose.R_BA).norm();
        certifying = true;
        reuse_kept();
        certifying = false;
        finish(cs);
        out = nullptr;
        return;
      }
      // Keep pairs for the next poses only while A moves slowly enough for them to serve a
      // few; otherwise (poses far apart) the grown boxes would only cost.
      kept_valid = false;
      recording = rotation && moved <= 0.5 * prm.reuse_margin_mm;
      if (recording) {
        grow = static_cast<float>(prm.reuse_margin_mm);
        num_kept = 0;
        kept_overflow = false;
        moved_from_kept = turned_from_kept = 0;  // this pose is the new kept_pose
        certifying = true;
      }
    }
    // The stack is sized for the trees' depths, so the descents cannot overflow it.
    const auto leaves = [this](const detail::BvhNode& A, const detail::BvhNode& B) { leaf_pair(A, B); };
    const bool complete =
        big ? detail::descend_wide(
                  bvh_a, bvh_b,
                  [this](std::int32_t w) -> const detail::Box4& { return posed_wide(w); },
                  stack.data(), stack.size(), leaves)
            : detail::descend(
                  bvh_a, bvh_b,
                  [this](std::int32_t ia, std::int32_t, const detail::BvhNode& A,
                         const detail::BvhNode& B) { return overlap(ia, A, B); },
                  stack.data(), stack.size(), leaves);
    CF_DEMAND(complete);
    if (recording && !kept_overflow) {
      kept_valid = true;
      kept_pose = pose;
      // Padding that is always skipped.
      for (std::size_t k = num_kept; k % 4 != 0; ++k) kept_lin[k] = std::numeric_limits<float>::infinity();
    }
    recording = certifying = false;
    finish(cs);
    out = nullptr;
  }
};

ContactDetector::ContactDetector(const Polyhedron& a, const Polyhedron& b, const Params& params)
    : impl_(std::make_unique<Impl>(a, b, params)) {}
ContactDetector::~ContactDetector() = default;
ContactDetector::ContactDetector(ContactDetector&&) noexcept = default;
ContactDetector& ContactDetector::operator=(ContactDetector&&) noexcept = default;

void ContactDetector::detect(const Pose& pose, ContactSet& out) { impl_->detect(pose, out); }
const Params& ContactDetector::params() const { return impl_->all; }
const Polyhedron& ContactDetector::model_a() const { return impl_->a; }
const Polyhedron& ContactDetector::model_b() const { return impl_->b; }
std::size_t ContactDetector::last_pairs_tested() const { return impl_->pairs; }
bool ContactDetector::last_reused_pairs() const { return impl_->reused; }

}  // namespace cf

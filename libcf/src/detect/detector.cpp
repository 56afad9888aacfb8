#include <cf/detector.hpp>

#include "detect.hpp"

#include "all_pairs.hpp"
#include "bvh.hpp"
#include "cheap_rejections.hpp"
#include "check.hpp"
#include "coherence.hpp"
#include "exact.hpp"
#include "finish_contacts.hpp"
#include "tolerances.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace cf::internal {

// BVH leaves of a model: one element for small models (with bigger leaves, leaf boxes of the
// paper's cube and L-block overlap everything), posed like inner nodes (cheaper than exact
// boxes there: 2.4 against 2.8 us per tick). Big models' nodes are also tested as oriented
// boxes, four at a time (internal::descend_wide): a curved surface's patches are tilted, and
// the axis-aligned box of a tilted patch is as thick as it is wide, so that two surfaces in
// contact overlap over many patches; and their leaves hold one face with the edges and
// vertices it owns, which tile the surface, each element with its own box tested in the
// leaf (on 2,000-face spheres 7% fewer instructions than leaves of 2 elements of any kind,
// 15% fewer at the paper's epsilon). docs/performance.md has the figures.
constexpr std::size_t kBigModelElements = 256;
static bool is_big(const Polyhedron& m) {
  return m.num_vertices() + m.num_edges() + m.num_faces() >= kBigModelElements;
}
static internal::Leaves leaves_for(const Polyhedron& m) {
  return is_big(m) ? internal::Leaves::kFaceGroups : internal::Leaves::kElements;
}

// The immutable part: the models, their trees and the exact tests' tables.
struct DetectModel {
  Polyhedron a, b;
  Params all;  // as given (params())
  // The exact tests' tables (exact.hpp): the model pair and the tolerances, built once.
  PairTables tab;
  Bvh bvh_a, bvh_b;
  // A model of kBigModelElements or more: leaves of face groups, each element's own box
  // tested in the leaf, and nodes tested as oriented boxes too.
  bool big = false;
  std::vector<Eigen::Array4f> a_vert;  // mm, A's vertices relative to bvh_a.origin(), A's frame
  FinishContext finishing;             // what finish_contacts reads (finish_contacts.hpp)

  DetectModel(const Polyhedron& ma, const Polyhedron& mb, const Params& params_in)
      : a(ma), b(mb), all(params_in), tab(a, b, params_in, 0.5 * (ma.bbox_min() + ma.bbox_max())) {
    const double eps = tab.eps, depth = tab.depth, in_plane = tab.in_plane;
    bvh_a = Bvh(a, 0.0, 1, tab.origin_A, leaves_for(a));
    // The boxes are single precision: widen B's by far more than the rounding of the
    // overlap test's few float operations on coordinates of this scale.
    constexpr double kFloatTestSlack = 1e-5;  // relative: 80 times a float's rounding
    const double float_slack = kFloatTestSlack * std::max(tab.reach, 1.0);
    // B's boxes grow by the deepest band and the in-plane allowance, so that every pair the
    // exact tests could accept has overlapping boxes.
    // A pair the tests accept is within max(eps, depth) across the plane and in_plane along
    // it, so within max(eps, depth, hypot(eps, in_plane)) of B's element.
    bvh_b = Bvh(b, std::max({eps, depth, std::hypot(eps, in_plane)}) + tab.geo_tol + float_slack, 1,
                Vec3::Zero(), leaves_for(b));
    big = is_big(a) || is_big(b);
    if (big)
      for (const Vertex& v : a.vertices())
        a_vert.emplace_back() << (v.p - bvh_a.origin()).cast<float>(), 0.0f;
    constexpr std::size_t kKeyIndices = std::size_t{1} << 24;
    finishing.a = &a;
    finishing.b = &b;
    finishing.epsilon_mm = eps;
    finishing.dominance_fit = tab.prm.dominance_fit;
    finishing.dominance_penalty = tab.prm.dominance_penalty;
    finishing.cos_plane_tolerance = tab.cos_max_tol;
    finishing.small_indices =
        std::max({a.num_vertices(), a.num_edges(), a.num_faces(), b.num_vertices(), b.num_edges(),
                  b.num_faces()}) < kKeyIndices;
  }
  DetectModel(const DetectModel&) = delete;  // tab and finishing point into a and b
  DetectModel& operator=(const DetectModel&) = delete;
};

// The per-thread part: the caches of the current pose, scratch and the kept pairs. Its
// methods read the model through `mp`, set by detect().
struct DetectState {
  const DetectModel* mp = nullptr;

  // A's nodes' (and elements') boxes in B's frame at the current pose (computed on first
  // use per call).
  struct PosedBox {
    Eigen::Vector3f c, h;  // mm, B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedBox> a_box;
  struct PosedWide {     // big models: a wide node's four boxes
    internal::Box4 box;  // B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedWide> a_wide;
  // Big models: A's elements' boxes, from A's vertices posed in single precision.
  struct PosedElem {
    internal::ElemBox box;  // B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedElem> a_elem;
  struct PosedVertex {
    Eigen::Array4f p;  // mm, B's frame
    std::uint64_t stamp = 0;
  };
  std::vector<PosedVertex> a_vert_posed;
  Mat3 absR = Mat3::Identity();
  internal::CheapRejections cheap;  // cheap_rejections.hpp
  Eigen::Matrix3f Rf = Eigen::Matrix3f::Identity(), absRf = Eigen::Matrix3f::Identity();
  Eigen::Array4f Rcol[3];   // R_BA's columns, lane 3 zero (A's vertices' posing)
  Eigen::Array4f a_origin;  // mm, bvh_a's origin posed, B's frame
  // The same on all four lanes (for the wide nodes' posing): R_BA(i, k), |R_BA(i, k)|, and
  // a_origin[i].
  Eigen::Array4f Rb[3][3], absRb[3][3], ob[3];
  // Scratch (sized once).
  std::vector<internal::NodePair> stack;
  internal::ExactScratch scratch;
  // Per call: the pose, A's vertices posed at it, the stamp of the per-pose caches.
  internal::PosedA posed;
  ContactSet* out = nullptr;
  std::size_t pairs = 0;
  // Temporal coherence (coherence.hpp): the pairs kept at a pose and their certificates.
  using Cert = internal::Cert;
  internal::KeptPairs kept;
  bool recording = false, reused = false;
  float grow = 0;                          // mm, added to A's posed boxes in this call
  internal::FinishScratch finish_scratch;  // finish_contacts.hpp

  explicit DetectState(const DetectModel& m) : cheap(m.tab), scratch(m.tab), posed(m.a) {
    stack.resize(stack_capacity(m.bvh_a, m.bvh_b));
    if (m.big) {
      a_wide.resize(m.bvh_a.wide().size());
      a_elem.resize(m.bvh_a.elements().size());
      a_vert_posed.resize(m.a.num_vertices());
      if (m.tab.prm.use_bvh && m.tab.prm.reuse_margin_mm > 0) kept.enable();
    } else {
      a_box.resize(m.bvh_a.nodes().size());
    }
  }

  // Small models: does A's BVH node `ia` (posed) overlap B's node? The axis-aligned boxes
  // in B's frame, then, for inner nodes, B's box on A's node's own axes.
  __attribute__((always_inline)) bool overlap(std::int32_t ia, const internal::BvhNode& A,
                                              const internal::BvhNode& B) {
    PosedBox& P = a_box[static_cast<std::size_t>(ia)];
    if (P.stamp != posed.stamp) pose_box(P, A);
    const Eigen::Vector3f d = P.c - B.center;
    if (std::abs(d.x()) > P.h.x() + B.half.x() || std::abs(d.y()) > P.h.y() + B.half.y() ||
        std::abs(d.z()) > P.h.z() + B.half.z())
      return false;
    if (A.leaf()) return true;
    // B's box on A's axes: centre offset R^T d, half extents |R^T| B.half.
    for (int k = 0; k < 3; ++k) {
      const float dk = Rf(0, k) * d.x() + Rf(1, k) * d.y() + Rf(2, k) * d.z();
      const float hk =
          absRf(0, k) * B.half.x() + absRf(1, k) * B.half.y() + absRf(2, k) * B.half.z();
      if (std::abs(dk) > A.half[k] + hk) return false;
    }
    return true;
  }

  // A's vertex v posed, single precision (rounding as in pose_wide).
  const Eigen::Array4f& posed_vertex(VertexId v) {
    const DetectModel& M = *mp;
    PosedVertex& P = a_vert_posed[v.index()];
    if (P.stamp != posed.stamp) {
      const Eigen::Array4f& q = M.a_vert[v.index()];
      P.p = Rcol[0] * q[0] + Rcol[1] * q[1] + Rcol[2] * q[2] + a_origin;
      P.stamp = posed.stamp;
    }
    return P.p;
  }

  // A big model's element at position i of its BVH, posed: the box of its posed vertices.
  __attribute__((noinline)) void pose_element(PosedElem& P, int i) {
    const DetectModel& M = *mp;
    P.stamp = posed.stamp;
    Eigen::Array4f lo = Eigen::Array4f::Constant(std::numeric_limits<float>::infinity()), hi = -lo;
    auto add = [&](VertexId v) {
      const Eigen::Array4f& p = posed_vertex(v);
      lo = lo.min(p);
      hi = hi.max(p);
    };
    const internal::BvhElement& x = M.bvh_a.elements()[static_cast<std::size_t>(i)];
    switch (x.kind) {
      case ElementKind::kVertex:
        add(VertexId(x.index));
        break;
      case ElementKind::kEdge:
        add(M.a.edges()[static_cast<std::size_t>(x.index)].v0);
        add(M.a.edges()[static_cast<std::size_t>(x.index)].v1);
        break;
      case ElementKind::kFace:
        for (VertexId v : M.a.faces()[static_cast<std::size_t>(x.index)].vertices) add(v);
        break;
    }
    P.box.c = 0.5f * (lo + hi);
    // The midpoint and the half difference each rounded once more: twice the rounding.
    constexpr float kMidpoint = 2 * static_cast<float>(internal::kFloatRounding);
    P.box.h = (0.5f * (hi - lo) + kMidpoint * P.box.c.abs()) * internal::kFloatGrowth +
              Eigen::Array4f(grow, grow, grow, 0.0f);
  }

  // Does A's element at position ia of its BVH (posed) overlap B's element at ib?
  bool element_boxes_overlap(int ia, int ib) {
    const DetectModel& M = *mp;
    PosedElem& P = a_elem[static_cast<std::size_t>(ia)];
    if (P.stamp != posed.stamp) pose_element(P, ia);
    return !internal::boxes_apart(P.box, M.bvh_b.element_boxes()[static_cast<std::size_t>(ib)]);
  }

  // A's node at the current pose: its box in B's frame.
  __attribute__((noinline)) void pose_box(PosedBox& P, const internal::BvhNode& N) {
    P.stamp = posed.stamp;
    internal::round_out(posed.pose.apply(N.center.cast<double>()), absR * N.half.cast<double>(),
                        P.c, P.h);
  }

  // A big model's wide node w at the current pose, in B's frame, in single precision. Its
  // centres are relative to bvh_a's origin (within A's size), whose posed place is computed
  // in double once per call, so the rounding (a few parts in 1e7 of A's size plus that
  // place) stays far below B's boxes' float slack wherever the two boxes could overlap. The
  // posed axis-aligned box of the oriented box bounds the node as well: the overlap of the
  // two is kept.
  const internal::Box4& posed_wide(std::int32_t w) {
    PosedWide& P = a_wide[static_cast<std::size_t>(w)];
    if (P.stamp != posed.stamp) pose_wide(P, w);
    return P.box;
  }
  __attribute__((noinline)) void pose_wide(PosedWide& P, std::int32_t w) {
    const DetectModel& M = *mp;
    using V = Eigen::Array4f;
    P.stamp = posed.stamp;
    const internal::Box4& N = M.bvh_a.wide()[static_cast<std::size_t>(w)].box;
    internal::Box4& Q = P.box;
    // Unrolled: at -O2 GCC keeps these loops of 3 and spills the temporaries.
    CF_UNROLL3
    for (int k = 0; k < 3; ++k) CF_UNROLL3
    for (int i = 0; i < 3; ++i)
      Q.ax[k][i] = N.ax[k][0] * Rb[i][0] + N.ax[k][1] * Rb[i][1] + N.ax[k][2] * Rb[i][2];
    CF_UNROLL3
    for (int i = 0; i < 3; ++i) {
      const V c = N.c[0] * Rb[i][0] + N.c[1] * Rb[i][1] + N.c[2] * Rb[i][2] + ob[i];
      const V oc = N.oc[0] * Rb[i][0] + N.oc[1] * Rb[i][1] + N.oc[2] * Rb[i][2] + ob[i];
      const V h = N.h[0] * absRb[i][0] + N.h[1] * absRb[i][1] + N.h[2] * absRb[i][2];
      const V oh =
          Q.ax[0][i].abs() * N.oh[0] + Q.ax[1][i].abs() * N.oh[1] + Q.ax[2][i].abs() * N.oh[2];
      const V lo = (c - h).max(oc - oh), hi = (c + h).min(oc + oh);
      Q.c[i] = 0.5f * (lo + hi);
      // Widened by the rounding of the midpoint and of the half difference.
      constexpr float kMidpoint = 2 * static_cast<float>(internal::kFloatRounding);
      Q.h[i] =
          ((0.5f * (hi - lo)).max(0.0f) + kMidpoint * Q.c[i].abs()) * internal::kFloatGrowth + grow;
      Q.oc[i] = oc;
      Q.oh[i] = N.oh[i] + grow;
    }
  }
  // Elements at positions ia, ib of the two BVHs' element lists, in leaves that overlap
  // where B's leaves hold no element lanes (B small).
  __attribute__((always_inline)) void pair(int ia, int ib) {
    const DetectModel& M = *mp;
    const internal::BvhElement& x = M.bvh_a.elements()[static_cast<std::size_t>(ia)];
    const internal::BvhElement& y = M.bvh_b.elements()[static_cast<std::size_t>(ib)];
    if (!internal::kinds_can_touch(internal::kind_bit(x.kind), internal::kind_bit(y.kind))) return;
    if (M.big && !element_boxes_overlap(ia, ib)) return;
    boxed_pair(ia, ib, x, y);
  }

  // The cheap rejection and the exact test of a pair, for kept pairs: the certificate of
  // whichever turned it away (none when it passed both).
  __attribute__((always_inline)) Cert certified_test(const internal::BvhElement& x,
                                                     const internal::BvhElement& y) {
    const DetectModel& M = *mp;
    Cert c;
    if (cheap.may_touch<true>(M.tab, posed, x.kind, x.index, y.kind, y.index, &c)) c = exact(x, y);
    return c;
  }

  // Leaves of the two BVHs whose boxes overlap: their element pairs whose kinds can touch
  // and whose own boxes overlap. B's face-group leaves hold their element boxes on SIMD
  // lanes: each of A's elements is tested against all of them at once.
  void leaf_pair(const internal::BvhNode& A, const internal::BvhNode& B) {
    const DetectModel& M = *mp;
    if (M.bvh_b.leaf_boxes().empty()) {
      for (int i = 0; i < A.count; ++i)
        for (int j = 0; j < B.count; ++j) pair(A.element() + i, B.element() + j);
      return;
    }
    const internal::LeafBoxes& L =
        M.bvh_b.leaf_boxes()[static_cast<std::size_t>(M.bvh_b.leaf_index(B))];
    for (int i = 0; i < A.count; ++i) {
      const int ia = A.element() + i;
      const internal::BvhElement& x = M.bvh_a.elements()[static_cast<std::size_t>(ia)];
      unsigned lanes = L.touchable_by[static_cast<std::size_t>(x.kind)];
      if (lanes == 0) continue;
      PosedElem& P = a_elem[static_cast<std::size_t>(ia)];
      if (P.stamp != posed.stamp) pose_element(P, ia);
      lanes &= internal::overlapping_lanes(P.box, L);
      while (lanes != 0) {
        const int ib = B.element() + __builtin_ctz(lanes);
        lanes &= lanes - 1;
        boxed_pair(ia, ib, x, M.bvh_b.elements()[static_cast<std::size_t>(ib)]);
      }
    }
  }

  // A pair past the kinds and the boxes.
  __attribute__((always_inline)) void boxed_pair(int ia, int ib, const internal::BvhElement& x,
                                                 const internal::BvhElement& y) {
    const DetectModel& M = *mp;
    ++pairs;
    if (!recording) {
      if (cheap.may_touch<false>(M.tab, posed, x.kind, x.index, y.kind, y.index, nullptr))
        exact(x, y);
      return;
    }
    kept.record(ia, ib, certified_test(x, y));
  }

  // The exact test of a pair (exact.hpp): its contact goes to the output; returns the
  // certificate of a pair turned away.
  __attribute__((always_inline)) Cert exact(const internal::BvhElement& x,
                                            const internal::BvhElement& y) {
    const DetectModel& M = *mp;
    internal::PairOutcome o =
        internal::exact_test(M.tab, posed, scratch, x.kind, x.index, y.kind, y.index);
    if (o.contact) out->push(*o.contact);
    return o.cert;
  }

  void detect(const DetectModel& M, const Pose& p, ContactSet& cs) {
    mp = &M;
    posed.pose = p;
    const Pose& pose = posed.pose;
    out = &cs;
    cs.clear();
    pairs = 0;
    ++posed.stamp;  // 64 bits: never wraps, so the per-pose caches need no reset
    if (!M.tab.prm.use_bvh) {
      pairs =
          internal::detect_all_pairs(M.tab, posed, scratch, cs);  // the reference (all_pairs.hpp)
      internal::finish_contacts(M.finishing, finish_scratch, cs);
      out = nullptr;
      return;
    }
    absR = pose.R_BA.cwiseAbs();
    Rf = pose.R_BA.cast<float>();
    absRf = absR.cast<float>();
    for (int k = 0; k < 3; ++k) Rcol[k] << Rf.col(k), 0.0f;
    posed.origin_posed = pose.apply(M.bvh_a.origin());
    a_origin << posed.origin_posed.cast<float>(), 0.0f;
    for (int i = 0; i < 3 && M.big; ++i) {
      for (int k = 0; k < 3; ++k) {
        Rb[i][k].setConstant(Rf(i, k));
        absRb[i][k].setConstant(absRf(i, k));
      }
      ob[i].setConstant(a_origin[i]);
    }
    reused = false;
    grow = 0;
    recording = false;
    if (kept.enabled()) {
      switch (kept.start(M.tab, pose, M.tab.prm.reuse_margin_mm)) {
        case internal::KeptPairs::Mode::kServe:
          // The kept pairs whose certificates do not hold go through the cheap rejections and
          // the exact test. Not through the element boxes: with the certificates, posing A's
          // elements for them cost more than the boxes saved (5% more instructions).
          reused = true;
          posed.certifying = true;
          kept.serve([this, &M](int ia, int ib) {
            ++pairs;
            return certified_test(M.bvh_a.elements()[static_cast<std::size_t>(ia)],
                                  M.bvh_b.elements()[static_cast<std::size_t>(ib)]);
          });
          posed.certifying = false;
          internal::finish_contacts(M.finishing, finish_scratch, cs);
          out = nullptr;
          return;
        case internal::KeptPairs::Mode::kRecord:
          recording = true;
          grow = static_cast<float>(M.tab.prm.reuse_margin_mm);
          posed.certifying = true;
          break;
        case internal::KeptPairs::Mode::kOff:
          break;
      }
    }
    // The stack is sized for the trees' depths, so the descents cannot overflow it.
    const auto leaves = [this](const internal::BvhNode& A, const internal::BvhNode& B) {
      leaf_pair(A, B);
    };
    const bool complete =
        M.big ? internal::descend_wide(
                    M.bvh_a, M.bvh_b,
                    [this](std::int32_t w) -> const internal::Box4& { return posed_wide(w); },
                    stack.data(), stack.size(), leaves)
              : internal::descend(
                    M.bvh_a, M.bvh_b,
                    [this](std::int32_t ia, std::int32_t, const internal::BvhNode& A,
                           const internal::BvhNode& B) { return overlap(ia, A, B); },
                    stack.data(), stack.size(), leaves);
    CF_DEMAND(complete);
    if (recording) kept.finish_recording(pose);
    recording = posed.certifying = false;
    internal::finish_contacts(M.finishing, finish_scratch, cs);
    out = nullptr;
  }
};

void DetectModelDelete::operator()(const DetectModel* m) const { delete m; }
void DetectStateDelete::operator()(DetectState* s) const { delete s; }
DetectModelPtr make_detect_model(const Polyhedron& a, const Polyhedron& b, const Params& params) {
  return DetectModelPtr(new DetectModel(a, b, params));
}
DetectStatePtr make_detect_state(const DetectModel& m) {
  return DetectStatePtr(new DetectState(m));
}
void detect(const DetectModel& m, DetectState& s, const Pose& pose, ContactSet& out) {
  s.detect(m, pose, out);
}
const Params& params_of(const DetectModel& m) { return m.all; }
const Polyhedron& model_a_of(const DetectModel& m) { return m.a; }
const Polyhedron& model_b_of(const DetectModel& m) { return m.b; }
std::size_t pairs_tested(const DetectState& s) { return s.pairs; }
bool reused_pairs(const DetectState& s) { return s.reused; }

}  // namespace cf::internal

namespace cf {

struct ContactDetector::Impl {
  internal::DetectModelPtr model;
  internal::DetectStatePtr state;
};

ContactDetector::ContactDetector(const Polyhedron& a, const Polyhedron& b, const Params& params)
    : impl_(std::make_unique<Impl>()) {
  impl_->model = internal::make_detect_model(a, b, params);
  impl_->state = internal::make_detect_state(*impl_->model);
}
ContactDetector::~ContactDetector() = default;
ContactDetector::ContactDetector(ContactDetector&&) noexcept = default;
ContactDetector& ContactDetector::operator=(ContactDetector&&) noexcept = default;

void ContactDetector::detect(const Pose& pose, ContactSet& out) {
  internal::detect(*impl_->model, *impl_->state, pose, out);
}
const Params& ContactDetector::params() const { return internal::params_of(*impl_->model); }
const Polyhedron& ContactDetector::model_a() const { return internal::model_a_of(*impl_->model); }
const Polyhedron& ContactDetector::model_b() const { return internal::model_b_of(*impl_->model); }
std::size_t ContactDetector::last_pairs_tested() const {
  return internal::pairs_tested(*impl_->state);
}
bool ContactDetector::last_reused_pairs() const { return internal::reused_pairs(*impl_->state); }

}  // namespace cf

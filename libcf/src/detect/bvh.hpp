#pragma once
// Private: a bounding box tree over the elements (vertices, edges, faces) of one polyhedron,
// in its own frame (per node an axis-aligned box and an oriented box), and the simultaneous
// descent of two such trees with one of them posed. Built once; queries allocate nothing.
//
// Each node knows which element kinds lie below it, so that a descent skips node pairs that
// cannot hold a PC type (vertex against vertex or edge, edge against vertex) without opening
// them.

#include "tolerances.hpp"

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <cmath>
// CF_NO_SIMD builds the plain Eigen forms of the SIMD tests (for checking them).
#if defined(__SSE__) && !defined(CF_NO_SIMD)
#define CF_SSE 1
#include <xmmintrin.h>
#endif
#include <cstdint>
#include <vector>

namespace cf::internal {

// Unrolls the next loop of 3 (GCC and Clang): -O2 does not.
#define CF_UNROLL3 _Pragma("GCC unroll 3")

/// A 3-vector in the first three of four float lanes, the fourth 0. Written out because
/// Eigen's comma initialiser from a Vector3f made GCC 12 -O3 warn of a 16-byte load from it.
inline Eigen::Array4f lanes4(const Eigen::Ref<const Eigen::Vector3f>& v) {
  return {v.x(), v.y(), v.z(), 0.0f};
}

struct BvhElement {
  ElementKind kind;
  std::int32_t index;
};

/// Bit of an element kind in BvhNode::kinds.
inline std::uint8_t kind_bit(ElementKind k) {
  return static_cast<std::uint8_t>(1u << static_cast<unsigned>(k));
}

/// A node: an axis-aligned box (single precision, rounded outwards, so it still bounds its
/// elements; 32 bytes so that descents stay in cache) and either two children (`child`,
/// `child + 1`) or a few elements (leaf).
struct BvhNode {
  Eigen::Vector3f center;      // mm, model frame
  Eigen::Vector3f half;        // mm, half extents, >= 0
  std::int32_t child = 0;      // inner: index of the first child; leaf: ~(first element index)
  std::uint8_t kinds = 0;      // kind_bit of every element below
  std::uint8_t touchable = 0;  // touchable_by_a(kinds), for the descent
  std::uint8_t count = 0;      // leaf: number of elements
  bool leaf() const { return child < 0; }
  std::int32_t left() const { return child; }
  std::int32_t right() const { return child + 1; }
  std::int32_t element() const { return ~child; }
};

/// Sets `c`, `h` to a single-precision box that contains the box (center, half). Rounding
/// to float errs by at most 2^-24 relative: widen by the centre's error (< 1.2e-7 |center|)
/// and then by 3e-7 relative, more than the half extent's own rounding.
inline void round_out(const Vec3& center, const Vec3& half, Eigen::Vector3f& c,
                      Eigen::Vector3f& h) {
  c = center.cast<float>();
  h = ((half + internal::kFloatRounding * center.cwiseAbs()).cast<float>() *
       internal::kFloatGrowth);
}

/// A node's boxes (4-lane rows, lane 3 zero), from which the wide nodes' lanes are filled:
/// its axis-aligned box and its oriented box, the principal axes of its points, which for a
/// patch of surface put one axis along its normal, where the patch is thin (an axis-aligned
/// box of a tilted patch is as thick as it is wide). Single precision, rounded outwards.
struct alignas(16) NodeBox {
  Eigen::Array4f c, h;    // mm, axis-aligned box: centre and half extents
  Eigen::Array4f oc, oh;  // mm, oriented box: centre, and half extents along ax[k]
  Eigen::Array4f ax[3];   // the oriented box's unit axes; ax[0] the thinnest spread
};

/// An element's axis-aligned box as 4-lane rows (lane 3 zero). Single precision, rounded
/// outwards.
struct alignas(16) ElemBox {
  Eigen::Array4f c, h;  // mm: centre and half extents
};

/// A face-group leaf's element boxes on SIMD lanes, lane j for its j-th element, so that
/// one element of the other model is tested against all of them at once. Unused lanes
/// never overlap anything.
struct alignas(16) LeafBoxes {
  static constexpr int kLanes = 4;
  Eigen::Array4f c[3],
      h[3];  // mm: centres (relative to the tree's origin) and half extents, per axis
  /// Per kind of an element of the other model (posed as A): the lanes whose elements it
  /// can form a PC type with (bit j for lane j).
  std::uint8_t touchable_by[3] = {0, 0, 0};
};

/// Bit j set where lane j of x is greater than y's.
__attribute__((always_inline)) inline unsigned greater_mask4(const Eigen::Array4f& x,
                                                             const Eigen::Array4f& y) {
#if defined(CF_SSE)
  return static_cast<unsigned>(
      _mm_movemask_ps(_mm_cmpgt_ps(_mm_load_ps(x.data()), _mm_load_ps(y.data()))));
#else
  unsigned m = 0;
  for (int j = 0; j < 4; ++j) m |= (x[j] > y[j] ? 1u : 0u) << j;
  return m;
#endif
}

/// Is some lane of x greater than y's?
__attribute__((always_inline)) inline bool any_greater(const Eigen::Array4f& x,
                                                       const Eigen::Array4f& y) {
  return greater_mask4(x, y) != 0;
}

/// The lanes of leaf boxes q whose boxes overlap box p (same frame), as bits.
__attribute__((always_inline)) inline unsigned overlapping_lanes(const ElemBox& p,
                                                                 const LeafBoxes& q) {
#if defined(CF_SSE)
  // On SSE registers, unrolled (as the wide nodes' test below).
  const __m128 sign = _mm_set1_ps(-0.0f);
  __m128 apart = _mm_setzero_ps();
  CF_UNROLL3
  for (int i = 0; i < 3; ++i)
    apart = _mm_or_ps(
        apart, _mm_cmpgt_ps(
                   _mm_andnot_ps(sign, _mm_sub_ps(_mm_load_ps(q.c[i].data()), _mm_set1_ps(p.c[i]))),
                   _mm_add_ps(_mm_load_ps(q.h[i].data()), _mm_set1_ps(p.h[i]))));
  return ~static_cast<unsigned>(_mm_movemask_ps(apart)) & 0xFu;
#else
  unsigned apart = 0;
  for (int i = 0; i < 3; ++i) apart |= greater_mask4((q.c[i] - p.c[i]).abs(), q.h[i] + p.h[i]);
  return ~apart & 0xFu;
#endif
}

/// Are two element boxes (in one frame) disjoint?
__attribute__((always_inline)) inline bool boxes_apart(const ElemBox& p, const ElemBox& q) {
  return any_greater((p.c - q.c).abs(), p.h + q.h);
}

/// Four nodes' boxes side by side, one node per SIMD lane (structure of arrays): the
/// axis-aligned box and the oriented box of each, as in NodeBox.
struct alignas(16) Box4 {
  Eigen::Array4f c[3], h[3];    // mm: axis-aligned box, centre and half extents, per axis
  Eigen::Array4f oc[3], oh[3];  // mm: oriented box, centre per axis, half extent along ax[k]
  Eigen::Array4f ax[3][3];      // ax[k][i]: component i of the oriented box's axis k

  /// Every lane zero.
  void set_zero() {
    for (int i = 0; i < 3; ++i) {
      c[i].setZero();
      h[i].setZero();
      oc[i].setZero();
      oh[i].setZero();
      for (int k = 0; k < 3; ++k) ax[k][i].setZero();
    }
  }
  /// Lane j set to node box n.
  void set_lane(int j, const NodeBox& n) {
    for (int i = 0; i < 3; ++i) {
      c[i][j] = n.c[i];
      h[i][j] = n.h[i];
      oc[i][j] = n.oc[i];
      oh[i][j] = n.oh[i];
      for (int k = 0; k < 3; ++k) ax[k][i][j] = n.ax[k][i];
    }
  }
};

/// A node of the 4-wide tree: up to four nodes of the binary tree (children or
/// grandchildren of one node), tested at once.
struct WideNode {
  Box4 box;                                 // lane j: binary node node[j]'s boxes
  std::int32_t node[4] = {-1, -1, -1, -1};  // binary node per lane; -1 for an unused lane
  std::int32_t wide[4] = {-1, -1, -1,
                          -1};  // its wide node when inner; -1 for a leaf or an unused lane
  /// By a mask of element kinds (kind_bit bits): the lanes holding some of those kinds, and
  /// the lanes holding elements that can touch some of them (empty for unused lanes).
  std::uint8_t lanes_holding[8] = {};
  std::uint8_t lanes_touching[8] = {};
};

/// The lanes of q whose boxes overlap lane s of p (same frame), as bits: the axis-aligned
/// boxes, then the oriented boxes on the two thinnest axes (ax[0], for a patch of surface its
/// normal), each box projected on the other's. The other four face axes and the nine cross
/// axes cull less than they cost (on 2,000-face spheres 10% more instructions with all six
/// face axes). Unused lanes of q give any answer: the caller masks them.
__attribute__((always_inline)) inline unsigned overlapping_lanes(const Box4& p, int s,
                                                                 const Box4& q) {
#if defined(CF_SSE)
  // Written on SSE registers and unrolled: GCC at -O2, which an embedding application may
  // use, keeps loops of 3 and spills Eigen's 4-float temporaries to memory here.
  const __m128 sign = _mm_set1_ps(-0.0f);
  const auto ld = [](const Eigen::Array4f& v) { return _mm_load_ps(v.data()); };
  const auto abs = [&](__m128 x) { return _mm_andnot_ps(sign, x); };
  const auto bc = [&](const Eigen::Array4f& v) { return _mm_set1_ps(v[s]); };
  const auto dot = [](__m128 x0, __m128 x1, __m128 x2, __m128 y0, __m128 y1, __m128 y2) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(x0, y0), _mm_mul_ps(x1, y1)), _mm_mul_ps(x2, y2));
  };
  __m128 apart = _mm_setzero_ps();
  CF_UNROLL3
  for (int i = 0; i < 3; ++i)
    apart = _mm_or_ps(apart, _mm_cmpgt_ps(abs(_mm_sub_ps(ld(q.c[i]), bc(p.c[i]))),
                                          _mm_add_ps(ld(q.h[i]), bc(p.h[i]))));
  if (_mm_movemask_ps(apart) == 0xF) return 0;
  const __m128 d0 = _mm_sub_ps(ld(q.oc[0]), bc(p.oc[0])), d1 = _mm_sub_ps(ld(q.oc[1]), bc(p.oc[1])),
               d2 = _mm_sub_ps(ld(q.oc[2]), bc(p.oc[2]));
  const __m128 n0 = ld(q.ax[0][0]), n1 = ld(q.ax[0][1]), n2 = ld(q.ax[0][2]);  // q's normals
  const __m128 m0 = bc(p.ax[0][0]), m1 = bc(p.ax[0][1]), m2 = bc(p.ax[0][2]);  // p's normal
  // On q's normal: p's oriented box projects to sum_j |n . p.ax[j]| p.oh[j].
  __m128 r = _mm_add_ps(ld(q.oh[0]), _mm_mul_ps(abs(dot(n0, n1, n2, m0, m1, m2)), bc(p.oh[0])));
  CF_UNROLL3
  for (int j = 1; j < 3; ++j)
    r = _mm_add_ps(r,
                   _mm_mul_ps(abs(dot(n0, n1, n2, bc(p.ax[j][0]), bc(p.ax[j][1]), bc(p.ax[j][2]))),
                              bc(p.oh[j])));
  apart = _mm_or_ps(apart, _mm_cmpgt_ps(abs(dot(n0, n1, n2, d0, d1, d2)), r));
  // On p's normal: q's oriented box projects to sum_j |m . q.ax[j]| q.oh[j].
  r = _mm_add_ps(bc(p.oh[0]), _mm_mul_ps(abs(dot(n0, n1, n2, m0, m1, m2)), ld(q.oh[0])));
  CF_UNROLL3
  for (int j = 1; j < 3; ++j)
    r = _mm_add_ps(r,
                   _mm_mul_ps(abs(dot(ld(q.ax[j][0]), ld(q.ax[j][1]), ld(q.ax[j][2]), m0, m1, m2)),
                              ld(q.oh[j])));
  apart = _mm_or_ps(apart, _mm_cmpgt_ps(abs(dot(m0, m1, m2, d0, d1, d2)), r));
  return ~static_cast<unsigned>(_mm_movemask_ps(apart)) & 0xFu;
#else
  using V = Eigen::Array4f;
  unsigned apart = 0;
  for (int i = 0; i < 3; ++i)
    apart |= greater_mask4((q.c[i] - p.c[i][s]).abs(), q.h[i] + p.h[i][s]);
  if (apart == 0xFu) return 0;
  const V d[3] = {q.oc[0] - p.oc[0][s], q.oc[1] - p.oc[1][s], q.oc[2] - p.oc[2][s]};
  // |q's axis k . p's axis j|
  const auto c = [&](int k, int j) {
    return (q.ax[k][0] * p.ax[j][0][s] + q.ax[k][1] * p.ax[j][1][s] + q.ax[k][2] * p.ax[j][2][s])
        .abs();
  };
  const V tq = q.ax[0][0] * d[0] + q.ax[0][1] * d[1] + q.ax[0][2] * d[2];
  apart |= greater_mask4(
      tq.abs(), q.oh[0] + c(0, 0) * p.oh[0][s] + c(0, 1) * p.oh[1][s] + c(0, 2) * p.oh[2][s]);
  const V tp = d[0] * p.ax[0][0][s] + d[1] * p.ax[0][1][s] + d[2] * p.ax[0][2][s];
  apart |= greater_mask4(tp.abs(),
                         c(0, 0) * q.oh[0] + c(1, 0) * q.oh[1] + c(2, 0) * q.oh[2] + p.oh[0][s]);
  return ~apart & 0xFu;
#endif
}

/// What a leaf holds: a few elements of any kind, or a few faces each with the edges and
/// vertices it owns (for fine meshes: leaves that tile the surface, so that sibling boxes
/// overlap less).
enum class Leaves { kElements, kFaceGroups };

class Bvh {
 public:
  Bvh() = default;
  /// `inflate` mm is added to every box on each side.
  /// Leaves of at most `leaf_size` spatially close elements, or face groups.
  /// boxes()' centres are relative to `origin` (mm, model frame), so that single-precision
  /// arithmetic on them errs relative to the model's size, not to its distance from its
  /// frame's origin.
  Bvh(const Polyhedron& m, double inflate, int leaf_size, const Vec3& origin = Vec3::Zero(),
      Leaves leaves = Leaves::kElements);
  const Vec3& origin() const { return origin_; }
  /// Per element (in elements() order), its own box (inflated like the nodes'), centre
  /// relative to origin().
  const std::vector<ElemBox>& element_boxes() const { return elem_boxes_; }
  /// Face-group trees with leaves of one group: per leaf, its elements' boxes on lanes
  /// (empty otherwise); leaf_boxes()[leaf_index(n)] for leaf node n.
  const std::vector<LeafBoxes>& leaf_boxes() const { return leaf_boxes_; }
  std::int32_t leaf_index(const BvhNode& n) const {
    return leaf_of_element_[static_cast<std::size_t>(n.element())];
  }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  /// Per node, its axis-aligned and oriented boxes (inflated alike), centres relative to
  /// origin().
  const std::vector<NodeBox>& boxes() const { return boxes_; }
  /// The 4-wide tree over the same nodes: wide()[0] holds the root alone (lane 0), so that a
  /// descent starts from a lane like every other step.
  const std::vector<WideNode>& wide() const { return wide_; }
  const std::vector<BvhElement>& elements() const { return elements_; }
  int depth() const { return depth_; }

 private:
  // Appends the wide node for lanes `members` (binary nodes), and below it those of its
  // inner lanes; returns its index.
  std::int32_t add_wide(const std::int32_t* members, int count);
  std::vector<BvhNode> nodes_;
  std::vector<NodeBox> boxes_;
  std::vector<WideNode> wide_;
  Vec3 origin_ = Vec3::Zero();
  std::vector<BvhElement> elements_;
  std::vector<ElemBox> elem_boxes_;
  std::vector<LeafBoxes> leaf_boxes_;
  std::vector<std::int32_t>
      leaf_of_element_;  // leaf_boxes_ index of the leaf starting at an element
  int depth_ = 0;
};

struct NodePair {
  std::int32_t a, b;
};
inline std::size_t stack_capacity(const Bvh& a, const Bvh& b) {
  return static_cast<std::size_t>(4 * (a.depth() + b.depth()) + 8);
}

/// The kinds (mask) of B's elements that an element of a kind in mask `ka` of A can form a
/// PC type with (v-f, e-f, e-e, f-f, f-e, f-v).
inline std::uint8_t touchable_by_a(std::uint8_t ka) {
  const std::uint8_t V = kind_bit(ElementKind::kVertex), E = kind_bit(ElementKind::kEdge),
                     F = kind_bit(ElementKind::kFace);
  return static_cast<std::uint8_t>(((ka & V) ? F : 0) | ((ka & E) ? (E | F) : 0) |
                                   ((ka & F) ? (V | E | F) : 0));
}

/// Can an element of a kind in mask `ka` (of A) and one in mask `kb` (of B) form a PC type?
inline bool kinds_can_touch(std::uint8_t ka, std::uint8_t kb) {
  return (touchable_by_a(ka) & kb) != 0;
}

/// Calls leaves(const BvhNode& a, const BvhNode& b) for every pair of leaves whose bounding
/// volumes overlap and whose kinds can touch, where tree `a` is posed into tree `b`'s frame:
/// `overlap(ia, ib, node_a, node_b)` tells whether A's node `ia` (posed; the caller caches
/// its posed box) overlaps B's node `ib`. `stack` is caller-owned scratch of at least
/// `stack_capacity(a, b)` entries. Returns false when the stack overflowed (some pairs were
/// skipped).
template <class Overlap, class LeafPair>
bool descend(const Bvh& ta, const Bvh& tb, Overlap&& overlap, NodePair* stack, std::size_t cap,
             LeafPair&& leaves) {
  if (ta.nodes().empty() || tb.nodes().empty()) return true;
  const auto& na = ta.nodes();
  const auto& nb = tb.nodes();
  std::size_t top = 0;
  stack[top++] = {0, 0};
  bool ok = true;
  while (top > 0) {
    const NodePair p = stack[--top];
    const BvhNode& A = na[static_cast<std::size_t>(p.a)];
    const BvhNode& B = nb[static_cast<std::size_t>(p.b)];
    if (!(A.touchable & B.kinds) || !overlap(p.a, p.b, A, B)) continue;
    if (A.leaf() && B.leaf()) {
      leaves(A, B);
      continue;
    }
    if (top + 2 > cap) {
      ok = false;
      continue;
    }
    // Split the bigger box (or the only inner node).
    const bool split_a = B.leaf() || (!A.leaf() && A.half.squaredNorm() >= B.half.squaredNorm());
    if (split_a) {
      stack[top++] = {A.right(), p.b};
      stack[top++] = {A.left(), p.b};
    } else {
      stack[top++] = {p.a, B.right()};
      stack[top++] = {p.a, B.left()};
    }
  }
  return ok;
}

/// As descend, over the 4-wide trees (Bvh::wide()): a step tests one lane of one tree
/// against the four lanes of a wide node of the other at once. `posed_a(w)` returns tree
/// `a`'s wide node w's boxes posed into `b`'s frame (the caller caches them).
template <class PosedA, class LeafPair>
bool descend_wide(const Bvh& ta, const Bvh& tb, PosedA&& posed_a, NodePair* stack, std::size_t cap,
                  LeafPair&& leaves) {
  if (ta.wide().empty() || tb.wide().empty()) return true;
  const auto& wa = ta.wide();
  const auto& wb = tb.wide();
  const auto& na = ta.nodes();
  const auto& nb = tb.nodes();
  // Stack entries are lanes, 4 * wide node + lane; the roots are lane 0 of wide node 0.
  if (!(wb[0].lanes_holding[na[0].touchable] & overlapping_lanes(posed_a(0), 0, wb[0].box) & 1u))
    return true;
  std::size_t top = 0;
  stack[top++] = {0, 0};
  bool ok = true;
  while (top > 0) {
    const NodePair p = stack[--top];
    const std::int32_t ia = p.a >> 2, ib = p.b >> 2;
    const int la = p.a & 3, lb = p.b & 3;
    const WideNode& WA = wa[static_cast<std::size_t>(ia)];
    const WideNode& WB = wb[static_cast<std::size_t>(ib)];
    const BvhNode& A = na[static_cast<std::size_t>(WA.node[la])];
    const BvhNode& B = nb[static_cast<std::size_t>(WB.node[lb])];
    if (A.leaf() && B.leaf()) {
      leaves(A, B);
      continue;
    }
    if (top + 4 > cap) {
      ok = false;
      continue;
    }
    // Open the bigger box (or the only inner node) into its wide node's lanes.
    if (B.leaf() || (!A.leaf() && A.half.squaredNorm() >= B.half.squaredNorm())) {
      const std::int32_t w = WA.wide[la];
      unsigned lanes = wa[static_cast<std::size_t>(w)].lanes_touching[B.kinds];
      if (lanes != 0) lanes &= overlapping_lanes(WB.box, lb, posed_a(w));
      for (; lanes != 0; lanes &= lanes - 1) stack[top++] = {4 * w + __builtin_ctz(lanes), p.b};
    } else {
      const std::int32_t w = WB.wide[lb];
      const WideNode& W = wb[static_cast<std::size_t>(w)];
      unsigned lanes = W.lanes_holding[A.touchable];
      if (lanes != 0) lanes &= overlapping_lanes(posed_a(ia), la, W.box);
      for (; lanes != 0; lanes &= lanes - 1) stack[top++] = {p.a, 4 * w + __builtin_ctz(lanes)};
    }
  }
  return ok;
}

}  // namespace cf::internal

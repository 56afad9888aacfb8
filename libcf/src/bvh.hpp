#pragma once
// Private: a bounding box tree over the elements (vertices, edges, faces) of one polyhedron,
// in its own frame (per node an axis-aligned box and an oriented box), and the simultaneous
// descent of two such trees with one of them posed. Built once; queries allocate nothing.
//
// Each node knows which element kinds lie below it, so that a descent skips node pairs that
// cannot hold a PC type (vertex against vertex or edge, edge against vertex) without opening
// them.

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <cmath>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#include <cstdint>
#include <vector>

namespace cf::detail {

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
  Eigen::Vector3f center;  // mm, model frame
  Eigen::Vector3f half;    // mm, half extents, >= 0
  std::int32_t child = 0;  // inner: index of the first child; leaf: ~(first element index)
  std::uint8_t kinds = 0;  // kind_bit of every element below
  std::uint8_t touchable = 0;  // touchable_by_a(kinds), for the descent
  std::uint8_t count = 0;  // leaf: number of elements
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
  h = ((half + 1.2e-7 * center.cwiseAbs()).cast<float>() * 1.0000003f);
}

/// What a big model's node test reads, as 4-lane rows (lane 3 zero) so that the test runs
/// on SIMD registers: the node's axis-aligned box and its oriented box, the principal axes
/// of its points, which for a patch of surface put one axis along its normal, where the
/// patch is thin (an axis-aligned box of a tilted patch is as thick as it is wide). Single
/// precision, rounded outwards.
struct alignas(16) NodeBox {
  Eigen::Array4f c, h;    // mm, axis-aligned box: centre and half extents
  Eigen::Array4f oc, oh;  // mm, oriented box: centre, and half extents along ax[k]
  Eigen::Array4f ax[3];   // the oriented box's unit axes; ax[0] the thinnest spread
  Eigen::Array4f axt[3];  // the same transposed: axt[i][k] == ax[k][i]
};

/// An element's axis-aligned box as 4-lane rows (lane 3 zero). Single precision, rounded
/// outwards.
struct alignas(16) ElemBox {
  Eigen::Array4f c, h;  // mm: centre and half extents
};

/// A face-group leaf's element boxes on SIMD lanes, lane j for its j-th element, so that
/// one element of the other model is tested against all of them at once. Unused lanes
/// never overlap anything.
struct alignas(32) LeafBoxes {
  static constexpr int kLanes = 8;
  using Lanes = Eigen::Array<float, kLanes, 1>;
  Lanes c[3], h[3];  // mm: centres (relative to the tree's origin) and half extents, per axis
  /// Per kind of an element of the other model (posed as A): the lanes whose elements it
  /// can form a PC type with (bit j for lane j).
  std::uint8_t touchable_by[3] = {0, 0, 0};
};

/// Is some lane of x greater than y's? (Eigen's any() on a comparison reduces lane by lane.)
__attribute__((always_inline)) inline bool any_greater(const Eigen::Array4f& x, const Eigen::Array4f& y) {
#if defined(__SSE__)
  return _mm_movemask_ps(_mm_cmpgt_ps(_mm_load_ps(x.data()), _mm_load_ps(y.data()))) != 0;
#else
  return (x > y).any();
#endif
}

/// Bit j set where lane j of x is greater than y's.
__attribute__((always_inline)) inline unsigned greater_mask(const LeafBoxes::Lanes& x, const LeafBoxes::Lanes& y) {
#if defined(__SSE__)
  return static_cast<unsigned>(_mm_movemask_ps(_mm_cmpgt_ps(_mm_load_ps(x.data()), _mm_load_ps(y.data()))) |
                               (_mm_movemask_ps(_mm_cmpgt_ps(_mm_load_ps(x.data() + 4), _mm_load_ps(y.data() + 4))) << 4));
#else
  unsigned m = 0;
  for (int j = 0; j < LeafBoxes::kLanes; ++j) m |= (x[j] > y[j] ? 1u : 0u) << j;
  return m;
#endif
}

/// The lanes of leaf boxes q whose boxes overlap box p (same frame), as bits.
__attribute__((always_inline)) inline unsigned overlapping_lanes(const ElemBox& p, const LeafBoxes& q) {
  unsigned apart = 0;
  for (int i = 0; i < 3; ++i) apart |= greater_mask((q.c[i] - p.c[i]).abs(), q.h[i] + p.h[i]);
  return ~apart & ((1u << LeafBoxes::kLanes) - 1);
}

/// Are two element boxes (in one frame) disjoint?
__attribute__((always_inline)) inline bool boxes_apart(const ElemBox& p, const ElemBox& q) {
  return any_greater((p.c - q.c).abs(), p.h + q.h);
}

/// Are two node boxes (in one frame) disjoint? The axis-aligned boxes first, then the
/// oriented boxes on their six face axes (the nine cross axes add little for patches), all
/// of one box's axes at once.
__attribute__((always_inline)) inline bool boxes_apart(const NodeBox& p, const NodeBox& q) {
  using V = Eigen::Array4f;
  if (any_greater((p.c - q.c).abs(), p.h + q.h)) return true;
  const V d = p.oc - q.oc;
  // On q's axes: the centres' offset, and p's half extents (|q^T p.ax[j]| p.oh[j]).
  const V tq = q.axt[0] * d[0] + q.axt[1] * d[1] + q.axt[2] * d[2];
  V rp = V::Zero();
  for (int j = 0; j < 3; ++j)
    rp += (q.axt[0] * p.ax[j][0] + q.axt[1] * p.ax[j][1] + q.axt[2] * p.ax[j][2]).abs() * p.oh[j];
  if (any_greater(tq.abs(), q.oh + rp)) return true;
  const V tp = p.axt[0] * d[0] + p.axt[1] * d[1] + p.axt[2] * d[2];
  V rq = V::Zero();
  for (int k = 0; k < 3; ++k)
    rq += (p.axt[0] * q.ax[k][0] + p.axt[1] * q.ax[k][1] + p.axt[2] * q.ax[k][2]).abs() * q.oh[k];
  return any_greater(tp.abs(), p.oh + rq);
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
  std::int32_t leaf_index(const BvhNode& n) const { return leaf_of_element_[static_cast<std::size_t>(n.element())]; }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  /// Per node, its axis-aligned and oriented boxes (inflated alike), centres relative to
  /// origin().
  const std::vector<NodeBox>& boxes() const { return boxes_; }
  const std::vector<BvhElement>& elements() const { return elements_; }
  int depth() const { return depth_; }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<NodeBox> boxes_;
  Vec3 origin_ = Vec3::Zero();
  std::vector<BvhElement> elements_;
  std::vector<ElemBox> elem_boxes_;
  std::vector<LeafBoxes> leaf_boxes_;
  std::vector<std::int32_t> leaf_of_element_;  // leaf_boxes_ index of the leaf starting at an element
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
  return static_cast<std::uint8_t>(((ka & V) ? F : 0) | ((ka & E) ? (E | F) : 0) | ((ka & F) ? (V | E | F) : 0));
}

/// Can an element of a kind in mask `ka` (of A) and one in mask `kb` (of B) form a PC type?
inline bool kinds_can_touch(std::uint8_t ka, std::uint8_t kb) { return (touchable_by_a(ka) & kb) != 0; }

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

}  // namespace cf::detail

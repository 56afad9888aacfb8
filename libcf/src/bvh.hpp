#pragma once
// Private: an axis-aligned bounding box tree over the elements (vertices, edges, faces) of
// one polyhedron, in its own frame, and the simultaneous descent of two such trees with
// one of them posed (boxes of the posed tree are mapped as oriented boxes and bounded by
// their world-axis boxes). Built once; queries allocate nothing.

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace cf::detail {

struct BvhElement {
  ElementKind kind;
  std::int32_t index;
};

struct BvhNode {
  Vec3 center;  // box centre, model frame
  Vec3 half;    // half extents, >= 0
  // Inner node: children left/right. Leaf: elements [first, first + count).
  std::int32_t left = -1, right = -1;
  std::int32_t first = 0, count = 0;
  bool leaf() const { return count > 0; }
};

class Bvh {
 public:
  Bvh() = default;
  /// `inflate` mm is added to every box on each side.
  Bvh(const Polyhedron& m, double inflate, int leaf_size = 2);
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  const std::vector<BvhElement>& elements() const { return elements_; }
  int depth() const { return depth_; }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<BvhElement> elements_;
  int depth_ = 0;
};

/// Calls visit(const BvhElement& a, const BvhElement& b) for every pair of leaf elements
/// whose boxes overlap, where tree `a` is posed by `pose` into tree `b`'s frame.
/// `stack` is caller-owned scratch of at least `stack_capacity(a, b)` entries.
/// Returns false when the stack overflowed (some pairs were skipped).
struct NodePair {
  std::int32_t a, b;
};
inline std::size_t stack_capacity(const Bvh& a, const Bvh& b) {
  return static_cast<std::size_t>(4 * (a.depth() + b.depth()) + 8);
}

template <class Visit>
bool descend(const Bvh& ta, const Pose& pose, const Bvh& tb, NodePair* stack, std::size_t cap,
             Visit&& visit) {
  if (ta.nodes().empty() || tb.nodes().empty()) return true;
  const Mat3& R = pose.R_BA;
  const Mat3 absR = R.cwiseAbs();
  const auto& na = ta.nodes();
  const auto& nb = tb.nodes();
  std::size_t top = 0;
  stack[top++] = {0, 0};
  bool ok = true;
  while (top > 0) {
    const NodePair p = stack[--top];
    const BvhNode& A = na[static_cast<std::size_t>(p.a)];
    const BvhNode& B = nb[static_cast<std::size_t>(p.b)];
    const Vec3 c = R * A.center + pose.t_BA;
    const Vec3 h = absR * A.half;
    if (std::abs(c.x() - B.center.x()) > h.x() + B.half.x() ||
        std::abs(c.y() - B.center.y()) > h.y() + B.half.y() ||
        std::abs(c.z() - B.center.z()) > h.z() + B.half.z())
      continue;
    if (A.leaf() && B.leaf()) {
      for (int i = 0; i < A.count; ++i)
        for (int j = 0; j < B.count; ++j)
          visit(ta.elements()[static_cast<std::size_t>(A.first + i)],
                tb.elements()[static_cast<std::size_t>(B.first + j)]);
      continue;
    }
    if (top + 2 > cap) {
      ok = false;
      continue;
    }
    // Split the bigger box (or the only inner node).
    const bool split_a = B.leaf() || (!A.leaf() && A.half.squaredNorm() >= B.half.squaredNorm());
    if (split_a) {
      stack[top++] = {A.right, p.b};
      stack[top++] = {A.left, p.b};
    } else {
      stack[top++] = {p.a, B.right};
      stack[top++] = {p.a, B.left};
    }
  }
  return ok;
}

}  // namespace cf::detail

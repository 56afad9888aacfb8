#include "bvh.hpp"

#include <algorithm>
#include <cmath>

namespace cf::detail {
namespace {

struct Item {
  BvhElement e;
  Vec3 lo, hi;
  Vec3 centroid() const { return 0.5 * (lo + hi); }
};

}  // namespace

Bvh::Bvh(const Polyhedron& m, double inflate, int leaf_size) {
  leaf_size = std::clamp(leaf_size, 1, 255);
  std::vector<Item> items;
  items.reserve(m.num_vertices() + m.num_edges() + m.num_faces());
  for (std::size_t i = 0; i < m.num_vertices(); ++i) {
    const Vec3& p = m.vertices()[i].p;
    items.push_back({{ElementKind::kVertex, static_cast<std::int32_t>(i)}, p, p});
  }
  for (std::size_t i = 0; i < m.num_edges(); ++i) {
    const EdgeId e(static_cast<std::int32_t>(i));
    const Vec3& p = m.edge_point(e, 0);
    const Vec3& q = m.edge_point(e, 1);
    items.push_back({{ElementKind::kEdge, e.value()}, p.cwiseMin(q), p.cwiseMax(q)});
  }
  for (std::size_t i = 0; i < m.num_faces(); ++i) {
    const Face& F = m.faces()[i];
    Vec3 lo = m.vertex(F.vertices[0]).p, hi = lo;
    for (VertexId v : F.vertices) {
      lo = lo.cwiseMin(m.vertex(v).p);
      hi = hi.cwiseMax(m.vertex(v).p);
    }
    items.push_back({{ElementKind::kFace, static_cast<std::int32_t>(i)}, lo, hi});
  }
  if (items.empty()) return;
  nodes_.reserve(2 * items.size());
  // Iterative top-down build: median split along the longest axis of the centroids.
  struct Task {
    std::int32_t node, begin, end, depth;
  };
  std::vector<Task> tasks;
  nodes_.emplace_back();
  tasks.push_back({0, 0, static_cast<std::int32_t>(items.size()), 1});
  while (!tasks.empty()) {
    const Task t = tasks.back();
    tasks.pop_back();
    depth_ = std::max(depth_, t.depth);
    Vec3 lo = items[static_cast<std::size_t>(t.begin)].lo, hi = items[static_cast<std::size_t>(t.begin)].hi;
    Vec3 clo = items[static_cast<std::size_t>(t.begin)].centroid(), chi = clo;
    for (std::int32_t i = t.begin; i < t.end; ++i) {
      const Item& it = items[static_cast<std::size_t>(i)];
      lo = lo.cwiseMin(it.lo);
      hi = hi.cwiseMax(it.hi);
      clo = clo.cwiseMin(it.centroid());
      chi = chi.cwiseMax(it.centroid());
    }
    BvhNode& n = nodes_[static_cast<std::size_t>(t.node)];
    round_out(0.5 * (lo + hi), 0.5 * (hi - lo) + Vec3::Constant(inflate), n.center, n.half);
    for (std::int32_t i = t.begin; i < t.end; ++i) n.kinds |= kind_bit(items[static_cast<std::size_t>(i)].e.kind);
    if (t.end - t.begin <= leaf_size) {
      n.child = ~t.begin;
      n.count = static_cast<std::uint8_t>(t.end - t.begin);
      continue;
    }
    // Median split along the longest axis of the centroids.
    int axis = 0;
    (chi - clo).maxCoeff(&axis);
    const std::int32_t mid = (t.begin + t.end) / 2;
    std::nth_element(items.begin() + t.begin, items.begin() + mid, items.begin() + t.end,
                     [axis](const Item& x, const Item& y) {
                       const double cx = x.lo[axis] + x.hi[axis], cy = y.lo[axis] + y.hi[axis];
                       if (cx != cy) return cx < cy;
                       if (x.e.kind != y.e.kind) return x.e.kind < y.e.kind;
                       return x.e.index < y.e.index;
                     });
    const auto l = static_cast<std::int32_t>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[static_cast<std::size_t>(t.node)].child = l;
    tasks.push_back({l, t.begin, mid, t.depth + 1});
    tasks.push_back({l + 1, mid, t.end, t.depth + 1});
  }
  elements_.reserve(items.size());
  for (const Item& it : items) {
    elements_.push_back(it.e);
    elem_c_.emplace_back();
    elem_h_.emplace_back();
    round_out(0.5 * (it.lo + it.hi), 0.5 * (it.hi - it.lo) + Vec3::Constant(inflate), elem_c_.back(), elem_h_.back());
  }
}

}  // namespace cf::detail

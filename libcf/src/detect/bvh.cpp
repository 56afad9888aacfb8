#include "bvh.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace cf::internal {
namespace {

// A unit of the build: one element, or a face with the edges and vertices it owns.
struct Item {
  std::int32_t first, count;  // its elements: members[first, first + count)
  Vec3 lo, hi;
  Vec3 centroid() const { return 0.5 * (lo + hi); }
};

// Appends the points that span element e (its vertex, its edge's ends, its face's vertices).
void points_of(const Polyhedron& m, const BvhElement& e, std::vector<Vec3>& pts) {
  const auto i = static_cast<std::size_t>(e.index);
  switch (e.kind) {
    case ElementKind::kVertex:
      pts.push_back(m.vertices()[i].p);
      break;
    case ElementKind::kEdge:
      pts.push_back(m.edge_point(EdgeId(e.index), 0));
      pts.push_back(m.edge_point(EdgeId(e.index), 1));
      break;
    case ElementKind::kFace:
      for (VertexId v : m.faces()[i].vertices) pts.push_back(m.vertex(v).p);
      break;
  }
}

// The axis-aligned bounds of points (at least one).
void bounds_of(const std::vector<Vec3>& pts, Vec3& lo, Vec3& hi) {
  lo = hi = pts[0];
  for (const Vec3& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
}

// Sets o's oriented box to that of points: principal axes of their spread, extents from the
// points.
void obb_of(const std::vector<Vec3>& pts, double inflate, const Vec3& origin, NodeBox& o) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Mat3 cov = Mat3::Zero();
  for (const Vec3& p : pts) cov += (p - mean) * (p - mean).transpose();
  Mat3 axes = Eigen::SelfAdjointEigenSolver<Mat3>(cov).eigenvectors();
  if (!axes.allFinite()) axes = Mat3::Identity();
  axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : pts) {
    const Vec3 q = axes.transpose() * p;
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Eigen::Matrix3f axes_f = axes.cast<float>();
  for (int k = 0; k < 3; ++k) {
    o.ax[k] = lanes4(axes_f.col(k));
  }
  // The float axes are off by about 1e-7 rad: widen by that much of the box's reach.
  const Vec3 centre_local = 0.5 * (lo + hi);
  const double reach = (0.5 * (hi - lo)).norm() + 1.0;
  Eigen::Vector3f c, h;
  constexpr double kAxisTurn = 1e-6;  // rad: ten times the float axes' own error
  round_out(axes * centre_local - origin,
            0.5 * (hi - lo) + Vec3::Constant(inflate + kAxisTurn * reach), c, h);
  o.oc = lanes4(c);
  o.oh = lanes4(h);
}

// A face owns the edges it has on its left and the vertices for which it is the first
// incident face: each element is owned once, and lies on its owner's boundary, so a face's
// group has the face's own box. Groups of more than kMaxGroup elements are cut into pieces.
constexpr std::int32_t kMaxGroup = LeafBoxes::kLanes;

// The build's units: members in item order, and the items over them.
struct Items {
  std::vector<BvhElement> members;
  std::vector<Item> items;
  std::vector<Vec3> pts;  // scratch

  // Closes the item of members[first, end).
  void close(const Polyhedron& m, std::int32_t first) {
    const auto end = static_cast<std::int32_t>(members.size());
    if (end == first) return;
    pts.clear();
    for (std::int32_t i = first; i < end; ++i)
      points_of(m, members[static_cast<std::size_t>(i)], pts);
    Vec3 lo, hi;
    bounds_of(pts, lo, hi);
    items.push_back({first, end - first, lo, hi});
  }
  // One element as an item of its own.
  void add_single(const Polyhedron& m, ElementKind kind, std::int32_t i) {
    const auto first = static_cast<std::int32_t>(members.size());
    members.push_back({kind, i});
    close(m, first);
  }
};

// Every vertex, edge and face an item of its own.
void element_items(const Polyhedron& m, Items& it) {
  for (std::size_t i = 0; i < m.num_vertices(); ++i)
    it.add_single(m, ElementKind::kVertex, static_cast<std::int32_t>(i));
  for (std::size_t i = 0; i < m.num_edges(); ++i)
    it.add_single(m, ElementKind::kEdge, static_cast<std::int32_t>(i));
  for (std::size_t i = 0; i < m.num_faces(); ++i)
    it.add_single(m, ElementKind::kFace, static_cast<std::int32_t>(i));
}

// Each face with the elements it owns (pieces of at most kMaxGroup), then the vertices on no
// face alone.
void face_group_items(const Polyhedron& m, Items& it) {
  std::vector<std::vector<BvhElement>> owned(m.num_faces());
  std::vector<std::int32_t> faceless;  // vertices on no face: items of their own
  for (std::size_t e = 0; e < m.num_edges(); ++e)
    owned[m.edges()[e].left.index()].push_back({ElementKind::kEdge, static_cast<std::int32_t>(e)});
  for (std::size_t v = 0; v < m.num_vertices(); ++v) {
    const auto iv = static_cast<std::int32_t>(v);
    if (m.vertices()[v].faces.empty())
      faceless.push_back(iv);
    else
      owned[m.vertices()[v].faces.front().index()].push_back({ElementKind::kVertex, iv});
  }
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    auto first = static_cast<std::int32_t>(it.members.size());
    it.members.push_back({ElementKind::kFace, static_cast<std::int32_t>(f)});
    for (const BvhElement& e : owned[f]) {
      if (static_cast<std::int32_t>(it.members.size()) - first == kMaxGroup) {
        it.close(m, first);
        first = static_cast<std::int32_t>(it.members.size());
      }
      it.members.push_back(e);
    }
    it.close(m, first);
  }
  for (std::int32_t v : faceless) it.add_single(m, ElementKind::kVertex, v);
}

// A node over items [begin, end): its boxes (axis-aligned and oriented, inflated), the kinds
// below it; clo and chi bound the items' centroids.
void fit_node(const Polyhedron& m, Items& it, std::int32_t begin, std::int32_t end, double inflate,
              const Vec3& origin, BvhNode& n, NodeBox& box, Vec3& clo, Vec3& chi) {
  const auto& items = it.items;
  Vec3 lo = items[static_cast<std::size_t>(begin)].lo,
       hi = items[static_cast<std::size_t>(begin)].hi;
  clo = items[static_cast<std::size_t>(begin)].centroid(), chi = clo;
  for (std::int32_t i = begin; i < end; ++i) {
    const Item& item = items[static_cast<std::size_t>(i)];
    lo = lo.cwiseMin(item.lo);
    hi = hi.cwiseMax(item.hi);
    clo = clo.cwiseMin(item.centroid());
    chi = chi.cwiseMax(item.centroid());
  }
  round_out(0.5 * (lo + hi), 0.5 * (hi - lo) + Vec3::Constant(inflate), n.center, n.half);
  it.pts.clear();
  for (std::int32_t i = begin; i < end; ++i) {
    const Item& item = items[static_cast<std::size_t>(i)];
    for (std::int32_t k = item.first; k < item.first + item.count; ++k) {
      points_of(m, it.members[static_cast<std::size_t>(k)], it.pts);
      n.kinds |= kind_bit(it.members[static_cast<std::size_t>(k)].kind);
    }
  }
  obb_of(it.pts, inflate, origin, box);
  Eigen::Vector3f c, h;
  round_out(0.5 * (lo + hi) - origin, 0.5 * (hi - lo) + Vec3::Constant(inflate), c, h);
  box.c = lanes4(c);
  box.h = lanes4(h);
  n.touchable = touchable_by_a(n.kinds);
}

// Median split of items [begin, end) along the longest axis of their centroids' bounds (ties
// by element, so that the tree does not depend on the sort's implementation).
std::int32_t median_split(Items& it, std::int32_t begin, std::int32_t end, const Vec3& clo,
                          const Vec3& chi) {
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const std::int32_t mid = (begin + end) / 2;
  const auto& members = it.members;
  std::nth_element(it.items.begin() + begin, it.items.begin() + mid, it.items.begin() + end,
                   [axis, &members](const Item& x, const Item& y) {
                     const double cx = x.lo[axis] + x.hi[axis], cy = y.lo[axis] + y.hi[axis];
                     if (cx != cy) return cx < cy;
                     const BvhElement& ex = members[static_cast<std::size_t>(x.first)];
                     const BvhElement& ey = members[static_cast<std::size_t>(y.first)];
                     if (ex.kind != ey.kind) return ex.kind < ey.kind;
                     return ex.index < ey.index;
                   });
  return mid;
}

// Iterative top-down build over the items: leaves of at most leaf_size items (child = ~first
// item for now). Returns the depth.
int build_tree(const Polyhedron& m, Items& it, double inflate, int leaf_size, const Vec3& origin,
               std::vector<BvhNode>& nodes, std::vector<NodeBox>& boxes) {
  struct Task {
    std::int32_t node, begin, end, depth;
  };
  int depth = 0;
  std::vector<Task> tasks;
  nodes.emplace_back();
  boxes.resize(2 * it.items.size());  // a binary tree over n items has fewer than 2n nodes
  tasks.push_back({0, 0, static_cast<std::int32_t>(it.items.size()), 1});
  while (!tasks.empty()) {
    const Task t = tasks.back();
    tasks.pop_back();
    depth = std::max(depth, t.depth);
    Vec3 clo, chi;
    BvhNode& n = nodes[static_cast<std::size_t>(t.node)];
    fit_node(m, it, t.begin, t.end, inflate, origin, n, boxes[static_cast<std::size_t>(t.node)],
             clo, chi);
    if (t.end - t.begin <= leaf_size) {
      n.child = ~t.begin;  // items for now; elements below
      n.count = static_cast<std::uint8_t>(t.end - t.begin);
      continue;
    }
    const std::int32_t mid = median_split(it, t.begin, t.end, clo, chi);
    const auto l = static_cast<std::int32_t>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[static_cast<std::size_t>(t.node)].child = l;
    tasks.push_back({l, t.begin, mid, t.depth + 1});
    tasks.push_back({l + 1, mid, t.end, t.depth + 1});
  }
  boxes.resize(nodes.size());
  return depth;
}

// The elements in the items' final order with their own boxes; returns where each item's
// elements start (and, last, their count).
std::vector<std::int32_t> place_elements(const Polyhedron& m, Items& it, double inflate,
                                         const Vec3& origin, std::vector<BvhElement>& elements,
                                         std::vector<ElemBox>& elem_boxes) {
  std::vector<std::int32_t> offset(it.items.size() + 1, 0);
  elements.reserve(it.members.size());
  for (std::size_t i = 0; i < it.items.size(); ++i) {
    offset[i] = static_cast<std::int32_t>(elements.size());
    const Item& item = it.items[i];
    for (std::int32_t k = item.first; k < item.first + item.count; ++k) {
      const BvhElement& e = it.members[static_cast<std::size_t>(k)];
      elements.push_back(e);
      it.pts.clear();
      points_of(m, e, it.pts);
      Vec3 lo, hi;
      bounds_of(it.pts, lo, hi);
      Eigen::Vector3f c, h;
      round_out(0.5 * (lo + hi) - origin, 0.5 * (hi - lo) + Vec3::Constant(inflate), c, h);
      ElemBox& b = elem_boxes.emplace_back();
      b.c = lanes4(c);
      b.h = lanes4(h);
    }
  }
  offset[it.items.size()] = static_cast<std::int32_t>(elements.size());
  return offset;
}

// Leaf n's elements' boxes on lanes (one group: at most kMaxGroup == LeafBoxes::kLanes).
LeafBoxes lane_boxes(const BvhNode& n, const std::vector<BvhElement>& elements,
                     const std::vector<ElemBox>& elem_boxes) {
  static_assert(kMaxGroup <= LeafBoxes::kLanes);
  LeafBoxes L;
  for (int i = 0; i < 3; ++i) {
    L.c[i].setZero();
    L.h[i].setConstant(-1e30f);  // unused lanes: apart from every box
  }
  for (int j = 0; j < n.count; ++j) {
    const auto k = static_cast<std::size_t>(n.element() + j);
    for (int i = 0; i < 3; ++i) {
      L.c[i][j] = elem_boxes[k].c[i];
      L.h[i][j] = elem_boxes[k].h[i];
    }
    for (int ka = 0; ka < 3; ++ka)
      if (kinds_can_touch(kind_bit(static_cast<ElementKind>(ka)), kind_bit(elements[k].kind)))
        L.touchable_by[ka] = static_cast<std::uint8_t>(L.touchable_by[ka] | (1u << j));
  }
  return L;
}

}  // namespace

Bvh::Bvh(const Polyhedron& m, double inflate, int leaf_size, const Vec3& origin, Leaves leaves)
    : origin_(origin) {
  leaf_size = std::clamp(leaf_size, 1, leaves == Leaves::kFaceGroups ? 255 / kMaxGroup : 255);
  Items it;
  it.members.reserve(m.num_vertices() + m.num_edges() + m.num_faces());
  if (leaves == Leaves::kElements)
    element_items(m, it);
  else
    face_group_items(m, it);
  if (it.items.empty()) return;
  nodes_.reserve(2 * it.items.size());
  depth_ = build_tree(m, it, inflate, leaf_size, origin, nodes_, boxes_);
  // Leaves from item ranges to element ranges.
  const std::vector<std::int32_t> offset =
      place_elements(m, it, inflate, origin, elements_, elem_boxes_);
  const bool lanes = leaves == Leaves::kFaceGroups && leaf_size == 1;
  if (lanes) leaf_of_element_.assign(elements_.size(), -1);
  for (BvhNode& n : nodes_)
    if (n.leaf()) {
      const std::int32_t b = ~n.child, e = b + n.count;
      n.child = ~offset[static_cast<std::size_t>(b)];
      n.count = static_cast<std::uint8_t>(offset[static_cast<std::size_t>(e)] -
                                          offset[static_cast<std::size_t>(b)]);
      if (!lanes) continue;
      leaf_of_element_[static_cast<std::size_t>(n.element())] =
          static_cast<std::int32_t>(leaf_boxes_.size());
      leaf_boxes_.push_back(lane_boxes(n, elements_, elem_boxes_));
    }
  const std::int32_t root = 0;
  wide_.reserve(nodes_.size() / 2 + 1);
  add_wide(&root, 1);
}

std::int32_t Bvh::add_wide(const std::int32_t* members, int count) {
  const auto w = static_cast<std::int32_t>(wide_.size());
  wide_.emplace_back();
  {
    WideNode& W = wide_.back();
    W.box.set_zero();
    for (int j = 0; j < count; ++j) {
      const std::int32_t n = members[j];
      const BvhNode& N = nodes_[static_cast<std::size_t>(n)];
      W.node[j] = n;
      W.box.set_lane(j, boxes_[static_cast<std::size_t>(n)]);
      for (unsigned mask = 1; mask < 8; ++mask) {
        if (N.kinds & mask)
          W.lanes_holding[mask] = static_cast<std::uint8_t>(W.lanes_holding[mask] | (1u << j));
        if (N.touchable & mask)
          W.lanes_touching[mask] = static_cast<std::uint8_t>(W.lanes_touching[mask] | (1u << j));
      }
    }
  }
  // Each inner lane opens into up to four nodes: its children, the larger (by box) of them
  // split again while there is room.
  for (int j = 0; j < count; ++j) {
    const BvhNode& N = nodes_[static_cast<std::size_t>(members[j])];
    if (N.leaf()) continue;
    std::int32_t open[4] = {N.left(), N.right(), -1, -1};
    int n_open = 2;
    while (n_open < 4) {
      int pick = -1;
      float best = -1;
      for (int k = 0; k < n_open; ++k) {
        const BvhNode& C = nodes_[static_cast<std::size_t>(open[k])];
        if (!C.leaf() && C.half.squaredNorm() > best) best = C.half.squaredNorm(), pick = k;
      }
      if (pick < 0) break;
      const BvhNode& C = nodes_[static_cast<std::size_t>(open[pick])];
      open[pick] = C.left();
      open[n_open++] = C.right();
    }
    const std::int32_t child = add_wide(open, n_open);
    wide_[static_cast<std::size_t>(w)].wide[j] = child;  // wide_ may have moved: index again
  }
  return w;
}

}  // namespace cf::internal

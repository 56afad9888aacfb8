// The bounding volume tree's boxes (libcf/src/detect/bvh.*): every node's axis-aligned and oriented
// boxes hold the points of the elements below it, the 4-wide tree holds every node once,
// and the SIMD box tests agree with plain double-precision ones.
#include "detect/bvh.hpp"
#include "runtime_models.hpp"

#include <catch2/catch.hpp>

#include <random>

namespace {

using cf::Vec3;
namespace tmod = cf::testmodels;

// A single-precision box holds its points up to float rounding of coordinates of a few
// hundred mm (about 3e-5 mm); the boxes are inflated by 1e-6 of their reach (>= 1 mm) on top,
// so a check 1e-4 mm loose is far below any feature and far above rounding.
constexpr double kSlack = 1e-4;

Vec3 head(const Eigen::Array4f& v) { return v.head<3>().cast<double>().matrix(); }

// Is p inside the node's axis-aligned box and its oriented box?
bool in_boxes(const cf::internal::NodeBox& n, const Vec3& p) {
  if (((p - head(n.c)).cwiseAbs() - head(n.h)).maxCoeff() > kSlack) return false;
  for (int k = 0; k < 3; ++k)
    if (std::abs(head(n.ax[k]).dot(p - head(n.oc))) > n.oh[k] + kSlack) return false;
  return true;
}

void points(const cf::Polyhedron& m, const cf::internal::BvhElement& e, std::vector<Vec3>& out) {
  out.clear();
  switch (e.kind) {
    case cf::ElementKind::kVertex:
      out.push_back(m.vertex(cf::VertexId(e.index)).p);
      break;
    case cf::ElementKind::kEdge:
      out.push_back(m.edge_point(cf::EdgeId(e.index), 0));
      out.push_back(m.edge_point(cf::EdgeId(e.index), 1));
      break;
    case cf::ElementKind::kFace:
      for (cf::VertexId v : m.faces()[static_cast<std::size_t>(e.index)].vertices)
        out.push_back(m.vertex(v).p);
      break;
  }
}

// Separated by the axis-aligned boxes, or on either oriented box's thinnest axis, in double
// precision.
bool apart_reference(const cf::internal::NodeBox& p, const cf::internal::NodeBox& q) {
  if (((head(p.c) - head(q.c)).cwiseAbs() - head(p.h) - head(q.h)).maxCoeff() > 0) return true;
  const Vec3 d = head(p.oc) - head(q.oc);
  auto apart_on = [&](const Vec3& u) {
    double r = 0;
    for (int k = 0; k < 3; ++k)
      r += std::abs(u.dot(head(p.ax[k]))) * p.oh[k] + std::abs(u.dot(head(q.ax[k]))) * q.oh[k];
    return std::abs(u.dot(d)) > r;
  };
  return apart_on(head(p.ax[0])) || apart_on(head(q.ax[0]));
}

// A random box: oriented box at centre c with random axes and half extents, the axis-aligned
// box around it grown by `aabb_grow`.
cf::internal::NodeBox random_box(std::mt19937& rng, const Vec3& c, double aabb_grow) {
  std::uniform_real_distribution<double> u(-1, 1), h(0.05, 3);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  const Vec3 half(h(rng), h(rng), h(rng));
  cf::internal::NodeBox b;
  for (int k = 0; k < 3; ++k) {
    b.ax[k] << R.col(k).cast<float>(), 0.0f;
  }
  b.oc << c.cast<float>(), 0.0f;
  b.oh << half.cast<float>(), 0.0f;
  const Vec3 aabb = R.cwiseAbs() * half + Vec3::Constant(aabb_grow);
  b.c << c.cast<float>(), 0.0f;
  b.h << aabb.cast<float>(), 0.0f;
  return b;
}

}  // namespace

TEST_CASE("every element is in one leaf, and every node's boxes hold it", "[bvh]") {
  // Off its frame's origin, with the boxes' centres relative to the sphere's centre.
  const Vec3 centre(100, -20, 5);
  const cf::Polyhedron m = tmod::faceted_sphere(30, 40, 50, centre, "sphere2000");
  const auto leaves = GENERATE(cf::internal::Leaves::kElements, cf::internal::Leaves::kFaceGroups);
  for (int leaf : {1, 2, 4}) {
    for (double inflate : {0.0, 0.25}) {
      CAPTURE(leaves == cf::internal::Leaves::kFaceGroups, leaf, inflate);
      const cf::internal::Bvh t(m, inflate, leaf, centre, leaves);
      const auto& nodes = t.nodes();
      REQUIRE(t.boxes().size() == nodes.size());
      const std::size_t n_elements = m.num_vertices() + m.num_edges() + m.num_faces();
      REQUIRE(t.elements().size() == n_elements);
      REQUIRE(t.element_boxes().size() == n_elements);
      // Each (kind, index) once among the leaves' elements.
      std::vector<int> seen(n_elements, 0);
      for (const cf::internal::BvhNode& n : nodes)
        if (n.leaf())
          for (int e = 0; e < n.count; ++e) {
            const cf::internal::BvhElement& x =
                t.elements()[static_cast<std::size_t>(n.element() + e)];
            const std::size_t base = x.kind == cf::ElementKind::kVertex ? 0
                                     : x.kind == cf::ElementKind::kEdge
                                         ? m.num_vertices()
                                         : m.num_vertices() + m.num_edges();
            ++seen[base + static_cast<std::size_t>(x.index)];
          }
      CHECK(std::count(seen.begin(), seen.end(), 1) == static_cast<std::ptrdiff_t>(n_elements));
      // Walk down from the root, carrying the chain of ancestors.
      std::vector<std::pair<std::int32_t, std::vector<std::int32_t>>> todo{{0, {}}};
      std::vector<Vec3> pts;
      std::size_t checked = 0, outside = 0;
      while (!todo.empty()) {
        auto [i, chain] = todo.back();
        todo.pop_back();
        chain.push_back(i);
        const cf::internal::BvhNode& n = nodes[static_cast<std::size_t>(i)];
        if (!n.leaf()) {
          todo.push_back({n.left(), chain});
          todo.push_back({n.right(), chain});
          continue;
        }
        for (int e = 0; e < n.count; ++e) {
          const auto pos = static_cast<std::size_t>(n.element() + e);
          points(m, t.elements()[pos], pts);
          // The element's own box too.
          cf::internal::NodeBox own;
          own.c = t.element_boxes()[pos].c;
          own.h = t.element_boxes()[pos].h;
          own.oc = own.c;
          own.oh = own.h;
          for (int k = 0; k < 3; ++k) {
            own.ax[k] = Eigen::Array4f::Zero();
            own.ax[k][k] = 1;
          }
          for (const Vec3& p : pts)
            if (!in_boxes(own, p - centre)) ++outside;
          for (const Vec3& p : pts)
            for (std::int32_t a : chain) {
              ++checked;
              // Inflated boxes hold the points with the inflation to spare.
              const cf::internal::NodeBox& b = t.boxes()[static_cast<std::size_t>(a)];
              if (!in_boxes(b, p - centre)) ++outside;
              if (inflate > 0) {
                cf::internal::NodeBox shrunk = b;
                shrunk.h -= static_cast<float>(inflate) * Eigen::Array4f(1, 1, 1, 0);
                shrunk.oh -= static_cast<float>(inflate) * Eigen::Array4f(1, 1, 1, 0);
                if (!in_boxes(shrunk, p - centre)) ++outside;
              }
            }
        }
      }
      CHECK(checked > 100000);
      CHECK(outside == 0);
    }
  }
}

TEST_CASE("oriented boxes of a curved surface's patches are thin along the normal", "[bvh]") {
  // A leaf pair's patch of a 50 mm sphere with 4 mm facets bulges by about 0.1 mm: the
  // oriented box's thinnest half extent is far below its axis-aligned box's.
  const cf::Polyhedron m = tmod::faceted_sphere(50, 42, 48, Vec3::Zero(), "sphere2016");
  const cf::internal::Bvh t(m, 0.0, 2);
  double thin_sum = 0, aabb_sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < t.nodes().size(); ++i) {
    const auto& b = t.boxes()[i];
    if (b.h.head<3>().maxCoeff() < 2 || b.h.head<3>().maxCoeff() > 10)
      continue;  // patches of a few facets
    thin_sum += b.oh[0];
    aabb_sum += b.h.head<3>().minCoeff();
    ++n;
  }
  REQUIRE(n > 100);
  CHECK(thin_sum < 0.25 * aabb_sum);
}

TEST_CASE("the 4-lane box test agrees with a double-precision separating-axis test", "[bvh]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> off(-6, 6), grow(0, 1);
  std::size_t apart = 0, overlap = 0, near_ties = 0;
  for (int i = 0; i < 50000; ++i) {
    // Lane s of p against the four lanes of q, both ways round.
    cf::internal::NodeBox ps[4], qs[4];
    cf::internal::Box4 p, q;
    for (int j = 0; j < 4; ++j) {
      ps[j] = random_box(rng, Vec3(off(rng), off(rng), off(rng)), grow(rng));
      qs[j] = random_box(rng, Vec3::Zero(), grow(rng));
      p.set_lane(j, ps[j]);
      q.set_lane(j, qs[j]);
    }
    const int s = i % 4;
    const unsigned got = cf::internal::overlapping_lanes(p, s, q),
                   got_back = cf::internal::overlapping_lanes(q, s, p);
    for (int j = 0; j < 4; ++j) {
      const bool ref = apart_reference(ps[s], qs[j]), ref_back = apart_reference(qs[s], ps[j]);
      // Float and double may differ within rounding of a tie: find those by nudging the box.
      const auto tie = [&](const cf::internal::NodeBox& x, const cf::internal::NodeBox& y) {
        cf::internal::NodeBox x_in = x, x_out = x;
        const Eigen::Array4f e(1e-4f, 1e-4f, 1e-4f, 0);
        x_in.h += e;
        x_in.oh += e;
        x_out.h -= e;
        x_out.oh -= e;
        return apart_reference(x_in, y) != apart_reference(x_out, y);
      };
      if (tie(ps[s], qs[j]) || tie(qs[s], ps[j])) {
        ++near_ties;
        continue;
      }
      CHECK(((got >> j) & 1u) == (ref ? 0u : 1u));
      CHECK(((got_back >> j) & 1u) == (ref_back ? 0u : 1u));
      (ref ? apart : overlap) += 1;
    }
  }
  // Both outcomes are exercised in earnest.
  CAPTURE(apart, overlap, near_ties);
  CHECK(apart > 50000);
  CHECK(overlap > 20000);
  CHECK(near_ties < 4000);
}

TEST_CASE("face-group leaves hold their element boxes on lanes, tested like one box each",
          "[bvh]") {
  const cf::Polyhedron m = tmod::faceted_sphere(30, 40, 50, Vec3::Zero(), "sphere2000");
  const cf::internal::Bvh t(m, 0.5, 1, Vec3::Zero(), cf::internal::Leaves::kFaceGroups);
  // Only face-group trees with one group per leaf carry lanes.
  CHECK(cf::internal::Bvh(m, 0.5, 1, Vec3::Zero(), cf::internal::Leaves::kElements)
            .leaf_boxes()
            .empty());
  CHECK(cf::internal::Bvh(m, 0.5, 2, Vec3::Zero(), cf::internal::Leaves::kFaceGroups)
            .leaf_boxes()
            .empty());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> off(-2.5, 2.5), half(0, 2);
  std::size_t leaves = 0, hits = 0, misses = 0;
  for (const cf::internal::BvhNode& n : t.nodes()) {
    if (!n.leaf()) continue;
    ++leaves;
    const cf::internal::LeafBoxes& L = t.leaf_boxes()[static_cast<std::size_t>(t.leaf_index(n))];
    for (int ka = 0; ka < 3; ++ka) {
      unsigned want = 0;
      for (int j = 0; j < n.count; ++j)
        if (cf::internal::kinds_can_touch(
                cf::internal::kind_bit(static_cast<cf::ElementKind>(ka)),
                cf::internal::kind_bit(
                    t.elements()[static_cast<std::size_t>(n.element() + j)].kind)))
          want |= 1u << j;
      CHECK(L.touchable_by[ka] == want);
    }
    // A few random boxes around the leaf: each lane's answer is its element's box test, and
    // lanes past the leaf's elements never overlap.
    const cf::internal::ElemBox& first = t.element_boxes()[static_cast<std::size_t>(n.element())];
    for (int r = 0; r < 4; ++r) {
      cf::internal::ElemBox p;
      p.c = first.c + Eigen::Array4f(static_cast<float>(off(rng)), static_cast<float>(off(rng)),
                                     static_cast<float>(off(rng)), 0);
      p.h = Eigen::Array4f(static_cast<float>(half(rng)), static_cast<float>(half(rng)),
                           static_cast<float>(half(rng)), 0);
      const unsigned got = cf::internal::overlapping_lanes(p, L);
      for (int j = 0; j < cf::internal::LeafBoxes::kLanes; ++j) {
        const bool lane = (got >> j) & 1u;
        const bool want =
            j < n.count && !cf::internal::boxes_apart(
                               p, t.element_boxes()[static_cast<std::size_t>(n.element() + j)]);
        CHECK(lane == want);
        (want ? hits : misses) += 1;
      }
    }
  }
  CHECK(leaves == t.leaf_boxes().size());
  // Both answers are exercised in earnest.
  CAPTURE(hits, misses);
  CHECK(hits > 5000);
  CHECK(misses > 5000);
}

TEST_CASE("the 4-wide tree holds every node once, each inner lane opening into its subtree",
          "[bvh]") {
  const cf::Polyhedron m = tmod::faceted_sphere(30, 40, 50, Vec3::Zero(), "sphere2000");
  const auto leaves = GENERATE(cf::internal::Leaves::kElements, cf::internal::Leaves::kFaceGroups);
  const cf::internal::Bvh t(m, 0.25, 1, Vec3::Zero(), leaves);
  const auto& nodes = t.nodes();
  const auto& wide = t.wide();
  REQUIRE(!wide.empty());
  CHECK(wide[0].node[0] == 0);
  CHECK(wide[0].node[1] == -1);
  // Under the root, every node is a lane of exactly one wide node or was opened into one.
  std::vector<int> as_lane(nodes.size(), 0);
  std::size_t leaf_lanes = 0;
  for (std::size_t w = 0; w < wide.size(); ++w) {
    const cf::internal::WideNode& W = wide[w];
    for (int j = 0; j < 4; ++j) {
      if (W.node[j] < 0) {
        CHECK(W.wide[j] == -1);
        for (unsigned mask = 1; mask < 8; ++mask)
          CHECK(((W.lanes_holding[mask] | W.lanes_touching[mask]) >> j & 1u) == 0);
        continue;
      }
      const cf::internal::BvhNode& n = nodes[static_cast<std::size_t>(W.node[j])];
      ++as_lane[static_cast<std::size_t>(W.node[j])];
      for (unsigned mask = 1; mask < 8; ++mask) {
        CHECK(((W.lanes_holding[mask] >> j) & 1u) == ((n.kinds & mask) ? 1u : 0u));
        CHECK(((W.lanes_touching[mask] >> j) & 1u) == ((n.touchable & mask) ? 1u : 0u));
      }
      // The lane's boxes are the node's.
      const cf::internal::NodeBox& b = t.boxes()[static_cast<std::size_t>(W.node[j])];
      for (int i = 0; i < 3; ++i) {
        CHECK(W.box.c[i][j] == b.c[i]);
        CHECK(W.box.oh[i][j] == b.oh[i]);
      }
      if (n.leaf()) {
        ++leaf_lanes;
        CHECK(W.wide[j] == -1);
        continue;
      }
      // An inner lane's wide node holds 2 to 4 of its descendants, which together hold all
      // its leaves' elements.
      REQUIRE(W.wide[j] > 0);
      const cf::internal::WideNode& C = wide[static_cast<std::size_t>(W.wide[j])];
      int count = 0, elements = 0;
      std::vector<std::int32_t> todo{W.node[j]};
      int below = 0;
      while (!todo.empty()) {
        const cf::internal::BvhNode& x = nodes[static_cast<std::size_t>(todo.back())];
        todo.pop_back();
        if (x.leaf())
          below += x.count;
        else
          todo.insert(todo.end(), {x.left(), x.right()});
      }
      for (int k = 0; k < 4; ++k) {
        if (C.node[k] < 0) continue;
        ++count;
        todo.push_back(C.node[k]);
        while (!todo.empty()) {
          const cf::internal::BvhNode& x = nodes[static_cast<std::size_t>(todo.back())];
          todo.pop_back();
          if (x.leaf())
            elements += x.count;
          else
            todo.insert(todo.end(), {x.left(), x.right()});
        }
      }
      CHECK(count >= 2);
      CHECK(elements == below);
    }
  }
  std::size_t leaves_count = 0;
  for (const auto& n : nodes) leaves_count += n.leaf() ? 1 : 0;
  CHECK(leaf_lanes == leaves_count);
  // Each leaf is a lane once; inner nodes are lanes at most once (the ones opened through
  // are not lanes).
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    CHECK(as_lane[i] <= 1);
    if (nodes[i].leaf()) CHECK(as_lane[i] == 1);
  }
}

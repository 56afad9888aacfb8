#pragma once
// The element pairs of A and B worth measuring at a pose (private to cfgen/verify): lower
// bounds on their distances, the elements near the other solid, and the pairs listed one at a
// time, with per-thread scratch buffers.

#include "cfgen/verify/analysis.hpp"
#include "cfgen/verify/touch.hpp"

#include <cf/geometry.hpp>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace cf::gen::internal {

// Lower bounds on the distance between an element of A and an element of B at one pose,
// computed before the exact distance (which locates points in faces and clamps segments: the
// bulk of verify's and contacts_at's time). From a face's plane: when every vertex of the
// other element's closure lies on one side of it, the two are at least the nearest vertex's
// height apart. From an edge's line: a vertex or an edge is at least its distance from the
// line of the other side's edge apart (most edge pairs of two models, 95% of those near
// enough to be listed, are far from crossing). From where an edge crosses a face's plane
// outside the face (crossing_gap).
class DistanceBound {
 public:
  // a_buf, b_buf: where the posed vertices go (reused storage).
  DistanceBound(const Polyhedron& A, const Polyhedron& B, const Pose& pose,
                std::vector<Vec3>& a_buf, std::vector<Vec3>& b_buf)
      : A_(A), B_(B), a_in_b_(a_buf), b_in_a_(b_buf) {
    a_in_b_.clear();
    for (const Vertex& v : A.vertices()) a_in_b_.push_back(pose.apply(v.p));
    b_in_a_.clear();
    for (const Vertex& v : B.vertices()) b_in_a_.push_back(pose.inverse_apply(v.p));
    // The line bound is compared with distances computed from the same coordinates; its own
    // rounding (a few ulps of the coordinates) is kept off by this much.
    double extent = 1.0;
    for (const Vec3& p : a_in_b_) extent = std::max(extent, p.lpNorm<Eigen::Infinity>());
    for (const Vertex& v : B.vertices()) extent = std::max(extent, v.p.lpNorm<Eigen::Infinity>());
    line_slack_ = 1e-12 * extent;
  }
  /// The slack kept off bounds computed from the posed coordinates (mm).
  double slack() const { return line_slack_; }
  /// True when element a of A and element b of B are proven farther apart than `reach`.
  bool farther(ElementKind ka, int a, ElementKind kb, int b, double reach) const {
    using K = ElementKind;
    double lb = 0;
    if (kb == K::kFace) lb = std::max(lb, side(B_.faces()[b], A_, ka, a, a_in_b_));
    if (ka == K::kFace) lb = std::max(lb, side(A_.faces()[a], B_, kb, b, b_in_a_));
    if (kb == K::kEdge && ka != K::kFace) {
      const Edge& eb = B_.edges()[b];
      const Vec3& q = B_.vertices()[eb.v0.index()].p;
      const Vec3 *p0, *p1;
      if (ka == K::kVertex) {
        p0 = p1 = &a_in_b_[static_cast<std::size_t>(a)];
      } else {
        p0 = &a_in_b_[A_.edges()[a].v0.index()];
        p1 = &a_in_b_[A_.edges()[a].v1.index()];
      }
      lb = std::max(lb, line_gap(q, eb.dir, *p0, *p1) - line_slack_);
    } else if (ka == K::kEdge && kb == K::kVertex) {
      const Vec3& p0 = a_in_b_[A_.edges()[a].v0.index()];
      const Vec3& p1 = a_in_b_[A_.edges()[a].v1.index()];
      const Vec3 u = (p1 - p0).normalized();
      const Vec3& q = B_.vertices()[static_cast<std::size_t>(b)].p;
      lb = std::max(lb, line_gap(p0, u, q, q) - line_slack_);
    }
    if (lb > reach) return true;
    // The bounds above are 0 when an edge crosses the face's plane: then from where it
    // crosses it.
    if (lb > 0) return false;
    if (ka == K::kEdge && kb == K::kFace) {
      const Edge& e = A_.edges()[a];
      return crossing_gap(B_, b, a_in_b_[e.v0.index()], a_in_b_[e.v1.index()]) - line_slack_ >
             reach;
    }
    if (ka == K::kFace && kb == K::kEdge) {
      const Edge& e = B_.edges()[b];
      return crossing_gap(A_, a, b_in_a_[e.v0.index()], b_in_a_[e.v1.index()]) - line_slack_ >
             reach;
    }
    return false;
  }

 private:
  // Distance between the line through q along unit u and the segment [p0, p1]: the segment
  // seen along u (both ends projected onto the plane through q across u) against the point
  // the line becomes.
  static double line_gap(const Vec3& q, const Vec3& u, const Vec3& p0, const Vec3& p1) {
    Vec3 x0 = p0 - q;
    x0 -= x0.dot(u) * u;
    Vec3 x1 = p1 - q;
    x1 -= x1.dot(u) * u;
    return point_segment(Vec3::Zero(), x0, x1).distance;
  }

  // For a segment [p0, p1] crossing the plane of face f of m (same frame) outside the face:
  // a point of the segment at length l from the crossing point x lies l sin(a) above the
  // plane and at most l cos(a) from x along it (a: the angle between segment and plane), so
  // its squared distance from the face is at least (l sin a)^2 + (d - l cos a)^2 while
  // l cos a <= d, where d is x's distance from the face in its plane: at least d sin(a)
  // over all l. 0 when the segment does not cross the plane or crosses it in the face.
  // One point location where the exact distance takes three and a segment distance for
  // each of the face's edges; most edges near a face's plane cross it outside the face.
  static double crossing_gap(const Polyhedron& m, int f, const Vec3& p0, const Vec3& p1) {
    const Face& F = m.faces()[f];
    const double h0 = F.normal.dot(p0) - F.offset, h1 = F.normal.dot(p1) - F.offset;
    if (!((h0 < 0 && h1 > 0) || (h0 > 0 && h1 < 0))) return 0;
    const Vec3 x = p0 + (h0 / (h0 - h1)) * (p1 - p0);
    const FaceLocation loc = locate_in_face(m, FaceId(f), Eigen::Vector2d(F.u.dot(x), F.v.dot(x)));
    if (loc.inside) return 0;
    return loc.boundary_distance * std::abs(h1 - h0) / (p1 - p0).norm();
  }

  // Smallest height of element (k, i) of m (vertices given in f's frame) over f's plane when
  // all of them are on one side, else 0.
  static double side(const Face& f, const Polyhedron& m, ElementKind k, int i,
                     const std::vector<Vec3>& pts) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto add = [&](VertexId v) {
      const double h = f.normal.dot(pts[v.index()]) - f.offset;
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    };
    if (k == ElementKind::kVertex)
      add(VertexId(i));
    else if (k == ElementKind::kEdge)
      add(m.edges()[i].v0), add(m.edges()[i].v1);
    else
      for (VertexId v : m.faces()[i].vertices) add(v);
    return lo > 0 ? lo : hi < 0 ? -hi : 0.0;
  }
  const Polyhedron& A_;
  const Polyhedron& B_;
  std::vector<Vec3>& a_in_b_;
  std::vector<Vec3>& b_in_a_;
  double line_slack_ = 0;  // mm
};

// The elements of A and of B that can come within `reach` of the other solid at `pose` (each
// element's bounding sphere against the other model's), ascending by kind: the pairs worth
// measuring, found in time linear in the models' size. Every pair left out is farther apart
// than `reach`.
struct NearElements {
  std::array<std::vector<int>, 3> a;
  std::vector<std::uint64_t> b_bits;           // B's, as one bitset in B.boxes' numbering
  std::array<std::vector<Vec3>, 3> a_centers;  // A's element sphere centres in B's frame
};

inline void near_elements(const ModelInfo& A, const ModelInfo& B, const Pose& pose, double reach,
                          NearElements& out) {
  for (auto& a : out.a) a.clear();
  const Vec3 b_in_a = pose.inverse_apply(B.bound.first);
  const Vec3 a_in_b = pose.apply(A.bound.first);
  out.b_bits.assign(static_cast<std::size_t>(B.boxes.words()), 0);
  for (int k = 0; k < 3; ++k) {
    out.a_centers[static_cast<std::size_t>(k)].resize(A.spheres[k].size());
    for (std::size_t i = 0; i < A.spheres[k].size(); ++i)
      if ((A.spheres[k][i].first - b_in_a).norm() - A.spheres[k][i].second - B.bound.second <=
          reach) {
        out.a[static_cast<std::size_t>(k)].push_back(static_cast<int>(i));
        out.a_centers[static_cast<std::size_t>(k)][i] = pose.apply(A.spheres[k][i].first);
      }
    for (std::size_t i = 0; i < B.spheres[k].size(); ++i)
      if ((B.spheres[k][i].first - a_in_b).norm() - B.spheres[k][i].second - A.bound.second <=
          reach) {
        const std::size_t bit = static_cast<std::size_t>(B.box_offset[k]) + i;
        out.b_bits[bit / 64] |= std::uint64_t{1} << (bit % 64);
      }
  }
}

// The buffers of one pair listing, kept per thread and reused: verify and contacts_at list
// the pairs of a pose hundreds of thousands of times a run, each listing a dozen vectors.
// Leased by depth, so that a listing inside another would get its own.
struct NearScratch {
  NearElements near;
  std::vector<Vec3> a_in_b, b_in_a;
  // NearPairs: per element of A (A.boxes' numbering), the elements of B whose boxes meet its
  // box, a bitset of B.boxes.words() words, valid when its stamp is the listing's.
  std::vector<std::uint64_t> a_rows;
  std::vector<std::uint64_t> a_row_stamp;
  std::uint64_t stamp = 0;
};
class ScratchLease {
 public:
  ScratchLease() {
    Pool& p = pool();
    if (p.depth == p.items.size()) p.items.push_back(std::make_unique<NearScratch>());
    s_ = p.items[p.depth++].get();
  }
  ~ScratchLease() { --pool().depth; }
  ScratchLease(const ScratchLease&) = delete;
  ScratchLease& operator=(const ScratchLease&) = delete;
  NearScratch& get() const { return *s_; }

 private:
  struct Pool {
    std::vector<std::unique_ptr<NearScratch>> items;
    std::size_t depth = 0;
  };
  static Pool& pool() {
    thread_local Pool p;
    return p;
  }
  NearScratch* s_;
};

// The element pairs (A's kind, B's kind, A's element, B's element, in that nesting order)
// not proven farther apart than `reach` at `pose`: near the other model, then by boxes (the
// index of B's boxes), then by bounding spheres, then by a face's plane or an edge's line.
// verify and contacts_at measure only these. Produced one at a time, so that a caller that
// stops at the first obstacle (verify, on most failed poses) does not pay for the rest.
struct ElementPair {
  ElementKind ka, kb;
  int a, b;
};

class NearPairs {
 public:
  NearPairs(const ModelInfo& A, const ModelInfo& B, const Pose& pose, double reach)
      : A_(A),
        B_(B),
        reach_(reach),
        near_(lease_.get().near),
        bounds_(*A.model, *B.model, pose, lease_.get().a_in_b, lease_.get().b_in_a) {
    near_elements(A, B, pose, reach, near_);
    NearScratch& sc = lease_.get();
    ++sc.stamp;
    const auto na = static_cast<std::size_t>(A.boxes.size());
    if (sc.a_row_stamp.size() != na) sc.a_row_stamp.assign(na, 0);
    sc.a_rows.resize(na * static_cast<std::size_t>(B.boxes.words()));
  }

  /// The next pair, false when there is none.
  bool next(ElementPair& out) {
    for (; kind_ < 9; ++kind_, i_ = 0) {
      const auto ia = static_cast<std::size_t>(kind_ / 3), ib = static_cast<std::size_t>(kind_ % 3);
      const std::vector<int>& as = near_.a[ia];
      for (; i_ < as.size(); ++i_) {
        const int a = as[i_];
        const auto& sa = A_.spheres[ia][static_cast<std::size_t>(a)];
        const Vec3& ca = near_.a_centers[ia][static_cast<std::size_t>(a)];
        if (!row_built_) start_row(ia, a, ib);
        // The row's elements in ascending order, lowest bit of each word first.
        for (; word_ <= last_word_; ++word_, bits_ = word_ <= last_word_ ? row_word(word_) : 0)
          while (bits_ != 0) {
            const int b = static_cast<int>(word_ * 64) + __builtin_ctzll(bits_) - B_.box_offset[ib];
            bits_ &= bits_ - 1;
            const auto& sb = B_.spheres[ib][static_cast<std::size_t>(b)];
            if ((ca - sb.first).norm() - sa.second - sb.second > reach_) continue;
            const auto ka = static_cast<ElementKind>(ia), kb = static_cast<ElementKind>(ib);
            if (bounds_.farther(ka, a, kb, b, reach_)) continue;
            out = {ka, kb, a, b};
            return true;
          }
        row_built_ = false;
      }
    }
    return false;
  }

 private:
  ScratchLease lease_;  // first: the members below live in it
  const ModelInfo& A_;
  const ModelInfo& B_;
  double reach_;
  // Starts the row of element a of kind ia against B's elements of kind ib: those near the
  // other solid whose boxes meet a's box grown by the reach (a box apart by more along an
  // axis is farther than the reach). The box query runs once per element of A and listing.
  void start_row(std::size_t ia, int a, std::size_t ib) {
    NearScratch& sc = lease_.get();
    const auto words = static_cast<std::size_t>(B_.boxes.words());
    const auto ga = static_cast<std::size_t>(A_.box_offset[ia] + a);
    row_ = sc.a_rows.data() + ga * words;
    if (sc.a_row_stamp[ga] != sc.stamp) {
      sc.a_row_stamp[ga] = sc.stamp;
      // a's box from its vertices in B's frame (the bound's own coordinates, so that the box
      // test and the distances agree within the bound's slack).
      const std::vector<Vec3>& p = sc.a_in_b;
      const Polyhedron& m = *A_.model;
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      auto add = [&](VertexId v) {
        lo = lo.cwiseMin(p[v.index()]);
        hi = hi.cwiseMax(p[v.index()]);
      };
      if (ia == 0)
        add(VertexId(a));
      else if (ia == 1)
        add(m.edges()[a].v0), add(m.edges()[a].v1);
      else
        for (VertexId v : m.faces()[a].vertices) add(v);
      const Vec3 g = Vec3::Constant(reach_ + bounds_.slack());
      B_.boxes.query(lo - g, hi + g, row_);
      for (std::size_t i = 0; i < words; ++i) row_[i] &= near_.b_bits[i];
    }
    // B's elements of kind ib are the bits [first_, end_).
    first_ = static_cast<std::size_t>(B_.box_offset[ib]);
    end_ = first_ + B_.spheres[ib].size();
    word_ = first_ / 64;
    last_word_ = end_ == first_ ? 0 : (end_ - 1) / 64;
    bits_ = end_ == first_ ? 0 : row_word(word_);
    if (end_ == first_) word_ = 1;  // an empty range: past last_word_
    row_built_ = true;
  }
  // Word w of the row, bits outside [first_, end_) cleared.
  std::uint64_t row_word(std::size_t w) const {
    std::uint64_t x = row_[w];
    if (w == first_ / 64) x &= ~std::uint64_t{0} << (first_ % 64);
    if (w == (end_ - 1) / 64 && end_ % 64 != 0) x &= ~(~std::uint64_t{0} << (end_ % 64));
    return x;
  }

  NearElements& near_;
  std::uint64_t* row_ = nullptr;  // the current row (in the scratch's a_rows)
  DistanceBound bounds_;
  int kind_ = 0;  // A's kind * 3 + B's kind
  std::size_t i_ = 0, word_ = 0, last_word_ = 0, first_ = 0, end_ = 0;
  std::uint64_t bits_ = 0;  // the row's current word, the elements already listed cleared
  bool row_built_ = false;
};

}  // namespace cf::gen::internal

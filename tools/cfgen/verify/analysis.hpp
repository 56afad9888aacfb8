#pragma once
// Per-model facts the generator needs again and again: vertex tangent cones, edge wedges,
// convex partitions of faces, coplanar face groups, and a point-in-solid test.

#include "cfgen/verify/cgal_support.hpp"
#include "cfgen/verify/lp.hpp"

#include <cf/polyhedron.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cf::gen {

struct VertexCone {
  std::vector<Vec3> rays;  // unit, model frame, along each incident edge away from the vertex
  bool pointed = false;    // the solid's tangent cone lies in an open half-space (v-f / f-v able)
  Vec3 center = Vec3::Zero();  // unit m maximising min_i m . ray_i: points into the solid
  double center_margin = 0;    // that minimum (cosine)
};

struct EdgeWedge {
  Vec3 into_left, into_right;    // unit, perpendicular to the edge, in each face, pointing into it
  Vec3 bisector = Vec3::Zero();  // unit bisector of the two outward normals (convex edges)
};

/// The axis-aligned boxes of a set of elements, indexed so that the elements whose box meets
/// a query box come out as a bitset in time O(log n + n / 64): per axis, the elements whose
/// lower end is at most the query's upper end are a prefix of the elements sorted by lower
/// end, and those whose upper end is at least the query's lower end a suffix of the elements
/// sorted by upper end; each prefix and suffix is stored as a bitset. The prefix and suffix
/// lengths come from a table of buckets over each sorted list (a search within one bucket,
/// most of them holding an end or none), as verify asks hundreds of times a pose.
class BoxIndex {
 public:
  BoxIndex() = default;
  /// lo[i], hi[i]: element i's box (mm).
  BoxIndex(const std::vector<Vec3>& lo, const std::vector<Vec3>& hi);
  int size() const { return n_; }
  /// 64-bit words of a bitset over the elements.
  int words() const { return words_; }
  /// Writes to out[0, words()) the elements whose closed box meets [q_lo, q_hi].
  void query(const Vec3& q_lo, const Vec3& q_hi, std::uint64_t* out) const;

 private:
  // Ends sorted along one axis, with buckets over their range: an end x falls in bucket
  // bucket(x), a monotone function of x, so the ends of the buckets before bucket(q) are below
  // or at q and those of the buckets after it above or at q: a search for q runs within
  // bucket(q) alone, exactly.
  struct SortedEnds {
    std::vector<double> x;
    std::vector<int> first;  // first[b]: index of the first end in bucket b or after; buckets + 1
    double origin = 0, per_mm = 0;
    int buckets = 1;
    void build(std::vector<double> sorted);
    int bucket(double q) const {
      // Monotone in q (subtraction, a positive factor and the clamp all are, in floating
      // point): what the exactness of the search rests on.
      const double v = (q - origin) * per_mm;
      if (!(v > 0)) return 0;  // also NaN
      if (v >= buckets - 1) return buckets - 1;
      return static_cast<int>(v);
    }
    std::size_t upper_bound(double q) const {  // ends <= q
      const auto b = static_cast<std::size_t>(bucket(q));
      return static_cast<std::size_t>(
          std::upper_bound(x.begin() + first[b], x.begin() + first[b + 1], q) - x.begin());
    }
    std::size_t lower_bound(double q) const {  // ends < q
      const auto b = static_cast<std::size_t>(bucket(q));
      return static_cast<std::size_t>(
          std::lower_bound(x.begin() + first[b], x.begin() + first[b + 1], q) - x.begin());
    }
  };
  int n_ = 0, words_ = 0;
  std::array<SortedEnds, 3> lo_sorted_, hi_sorted_;
  // (n + 1) bitsets each: lo_prefix_[a][r] holds the r elements of smallest lower end on axis
  // a; hi_suffix_[a][r] the elements from the r-th smallest upper end on.
  std::array<std::vector<std::uint64_t>, 3> lo_prefix_, hi_suffix_;
};

struct ModelInfo {
  const Polyhedron* model = nullptr;
  std::vector<VertexCone> cones;
  std::vector<EdgeWedge> wedges;
  std::vector<std::vector<ConvexPiece>> pieces;  // per face, largest piece first
  std::vector<int> face_plane;  // faces lying in one plane (same orientation) share an id
  // Bounding spheres (center in the model frame, radius, mm) of every element, indexed by
  // kind (vertex, edge, face) then element, for cheap distance lower bounds.
  std::vector<std::pair<Vec3, double>> spheres[3];
  // The axis-aligned boxes (model frame) of all elements, indexed for box queries: vertices,
  // then edges, then faces; element i of kind k is box_offset[k] + i.
  BoxIndex boxes;
  int box_offset[3] = {0, 0, 0};
  std::pair<Vec3, double> bound{Vec3::Zero(), 0.0};  // bounding sphere of the whole model
  /// mm: how closely the model holds the geometry its file gave (the larger of the loader's
  /// precision_mm and deviation_mm, tools/mesh/model_loader.hpp); 0 for an exact model. An
  /// edge's direction and a face's normal hold to about precision_mm over their extent.
  double precision_mm = 0;
  /// mm: each edge's length and each face's width (the least extent of its vertices across
  /// one of its sides), indexed by kind then element; none for vertices.
  std::vector<double> extent[3];
};

/// The facts above of `m`, which holds its file's geometry to `precision_mm` (mm; 0: exact).
/// @throws cf::Error when the model has a face that cannot be partitioned.
ModelInfo analyse_model(const Polyhedron& m, double precision_mm = 0);

/// True when p lies strictly inside the solid (ray casting; directions that graze an edge or
/// vertex are retried). Points within `boundary_tol` of the boundary count as outside.
bool point_inside(const Polyhedron& m, const Vec3& p, double boundary_tol);

/// Vertices of an element's closure (model frame, mm).
std::vector<Vec3> closure_points(const Polyhedron& m, ElementKind k, int i);
/// Vertices of the closure of the points of an element at least `margin` (mm) inside it:
/// an edge's points that far from both ends; a convex face's points whose in-plane disc of
/// that radius lies in the face (sides moved inwards). A vertex, a face with reflex corners
/// or holes, or an element too small to hold such a point keeps its whole closure, which
/// still contains every such point.
std::vector<Vec3> inset_closure_points(const Polyhedron& m, ElementKind k, int i, double margin);
/// Unit directions of the edges in an element's closure (none for a vertex).
std::vector<Vec3> closure_directions(const Polyhedron& m, ElementKind k, int i);

/// Minimal rotation taking unit vector x to unit vector y.
Mat3 align(const Vec3& x, const Vec3& y);
/// Rotation by angle (rad) about a unit axis.
Mat3 axis_angle(const Vec3& axis, double angle);

}  // namespace cf::gen

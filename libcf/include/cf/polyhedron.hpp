#pragma once
/// @file
/// A featured polyhedron: the faces, edges and vertices of section 3 of docs/spec.md with their
/// adjacency, planes and mass properties. CGAL-free; built by the tools from a mesh or read
/// from the `models.A` / `models.B` objects of a graph file.

#include <cf/pc.hpp>
#include <cf/types.hpp>

#include <array>
#include <string>
#include <vector>

namespace cf {

/// A vertex of the feature structure: a point where non-collinear edges meet.
struct Vertex {
  Vec3 p;                     ///< mm, model frame
  std::vector<EdgeId> edges;  ///< edges that end here, ascending
  std::vector<FaceId> faces;  ///< faces whose boundary passes through here, ascending
};

/// A maximal straight segment where two different faces meet.
struct Edge {
  VertexId v0, v1;      ///< end points, v0 < v1
  FaceId left;          ///< the face whose loop runs v0 -> v1 (seen from outside)
  FaceId right;         ///< the face whose loop runs v1 -> v0
  bool convex = true;   ///< interior dihedral angle below pi
  double dihedral = 0;  ///< rad, interior dihedral angle (measured inside the solid), in (0, 2 pi)
  Vec3 dir;             ///< unit, from v0 to v1
  double length = 0;    ///< mm
};

/// A maximal connected region of coplanar facets: a polygon, possibly non-convex, possibly
/// with holes.
struct Face {
  Vec3 normal;    ///< unit, outward
  double offset;  ///< mm; the plane is { x : normal . x == offset }
  /// loops[0] is the outer boundary, counter-clockwise seen from outside (against the
  /// normal); loops[1..] are the holes, clockwise seen from outside. Every loop starts at
  /// its smallest vertex index.
  std::vector<std::vector<VertexId>> loops;
  std::vector<EdgeId> edges;       ///< edges that bound this face, ascending
  std::vector<VertexId> vertices;  ///< vertices on its boundary, ascending
  Vec3 u, v;                       ///< unit tangent axes, u x v = normal (2D frame below)
  std::vector<std::vector<Eigen::Vector2d>> loops_2d;  ///< mm, loops in the (u, v) frame
  Vec3 centroid;                                       ///< mm, area centroid of the region
  double area = 0;                                     ///< mm^2, holes excluded
};

/// An immutable featured polyhedron.
class Polyhedron {
 public:
  Polyhedron() = default;

  /// Builds the feature structure from the model arrays of docs/spec.md, section 5, and derives
  /// everything else (edge-face incidence, convexity, planes, adjacency, mass properties).
  /// @param name       the model's display name.
  /// @param vertices   feature vertices, mm.
  /// @param edges      pairs of vertex indices.
  /// @param face_loops per face, its loops of vertex indices (outer first, holes after).
  /// @throws cf::Error naming the element and the reason when the arrays do not describe a
  ///   closed, oriented polyhedron: indices out of range, a loop with fewer than 3 vertices,
  ///   a loop side that is not an edge, an edge not bounded by exactly two faces in opposite
  ///   directions, a face that is not planar, an inward orientation (negative volume).
  static Polyhedron from_features(std::string name, std::vector<Vec3> vertices,
                                  const std::vector<std::array<int, 2>>& edges,
                                  const std::vector<std::vector<std::vector<int>>>& face_loops);

  /// The same name, edges and face loops at other vertex coordinates (a moved or reshaped
  /// copy), everything else derived again as from_features does.
  /// @param vertices one per vertex of this polyhedron, mm, in its order.
  /// @throws cf::Error as from_features (a face no longer planar, an inward orientation), or
  ///   when the count differs from num_vertices().
  Polyhedron with_vertices(std::vector<Vec3> vertices) const;

  const std::string& name() const { return name_; }
  const std::vector<Vertex>& vertices() const { return vertices_; }
  const std::vector<Edge>& edges() const { return edges_; }
  const std::vector<Face>& faces() const { return faces_; }
  const Vertex& vertex(VertexId id) const { return vertices_[id.index()]; }
  const Edge& edge(EdgeId id) const { return edges_[id.index()]; }
  const Face& face(FaceId id) const { return faces_[id.index()]; }
  std::size_t num_vertices() const { return vertices_.size(); }
  std::size_t num_edges() const { return edges_.size(); }
  std::size_t num_faces() const { return faces_.size(); }
  /// The number of elements of a kind: num_vertices(), num_edges() or num_faces().
  std::size_t num_elements(ElementKind kind) const {
    return kind == ElementKind::kVertex ? vertices_.size()
           : kind == ElementKind::kEdge ? edges_.size()
                                        : faces_.size();
  }

  /// mm, the end point of an edge.
  const Vec3& edge_point(EdgeId e, int end) const {
    return vertices_[(end == 0 ? edges_[e.index()].v0 : edges_[e.index()].v1).index()].p;
  }

  /// mm, centroid as the paper defines it (section 3.1): the mean of the feature vertices.
  const Vec3& vertex_centroid() const { return vertex_centroid_; }
  /// mm, the centroid of the solid of uniform density.
  const Vec3& volume_centroid() const { return volume_centroid_; }
  /// mm^3, enclosed volume (positive for an outward-oriented model).
  double volume() const { return volume_; }
  /// mm, diagonal of the axis-aligned bounding box: the scale for relative tolerances.
  double size() const { return size_; }
  const Vec3& bbox_min() const { return bbox_min_; }
  const Vec3& bbox_max() const { return bbox_max_; }

  /// True when edge e is one of the edges on face f's boundary.
  bool edge_bounds_face(EdgeId e, FaceId f) const;
  /// True when vertex v is an end point of edge e.
  bool vertex_ends_edge(VertexId v, EdgeId e) const;
  /// True when vertex v lies on face f's boundary.
  bool vertex_on_face(VertexId v, FaceId f) const;

  /// mm, signed distance, within the face's plane, from the projection of p onto that plane
  /// to the face's boundary: positive inside the open face region, negative outside.
  double face_inset(FaceId f, const Vec3& p) const;
  /// Same as face_inset for a point already given in the face's (u, v) frame.
  double face_inset_2d(FaceId f, const Eigen::Vector2d& q) const;
  /// The (u, v) coordinates of p's projection onto face f's plane.
  Eigen::Vector2d face_coords(FaceId f, const Vec3& p) const {
    const Face& F = faces_[f.index()];
    return {F.u.dot(p), F.v.dot(p)};
  }

 private:
  std::string name_;
  std::vector<Vertex> vertices_;
  std::vector<Edge> edges_;
  std::vector<Face> faces_;
  Vec3 vertex_centroid_ = Vec3::Zero();
  Vec3 volume_centroid_ = Vec3::Zero();
  double volume_ = 0;
  double size_ = 0;
  Vec3 bbox_min_ = Vec3::Zero();
  Vec3 bbox_max_ = Vec3::Zero();
};

/// Serialises the model in the form of section 5 of docs/spec.md (`models.A`), plus derived
/// fields that readers may ignore (face planes, edge convexity, mass properties).
/// @param indent  spaces per level; -1 writes one line.
std::string to_json(const Polyhedron& model, int indent = 2);

/// Reads a model object (the form written by to_json, or `models.A` of a graph file).
/// @param text    the JSON text of one model object.
/// @param source  where the text came from, for error messages (a file name).
/// @throws cf::Error naming the source, the JSON pointer and the reason on malformed input.
Polyhedron polyhedron_from_json(const std::string& text, const std::string& source);

}  // namespace cf

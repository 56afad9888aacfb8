#pragma once
// Independent test oracle: a featured polyhedron (vertices, edges, faces with loops) rebuilt
// from the three arrays of a graph model (docs/graph-format.md, "Models"). Everything else
// (normals, planes, in-face directions, convexity, vertex corners) is derived here from those
// arrays alone; no code is shared with tools/ or libcf/.

#include <Eigen/Dense>

#include <array>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace oracle {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;
using Mat3 = Eigen::Matrix3d;

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Box3 {
  Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void add(const Box3& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  // Distance between two boxes (0 when they overlap).
  double dist(const Box3& b) const {
    Vec3 g = (b.lo - hi).cwiseMax(lo - b.hi).cwiseMax(Vec3::Zero());
    return g.norm();
  }
  double diag() const { return (hi - lo).norm(); }
};

/// The corner of face `face` at a vertex: the open planar sector of directions from the vertex
/// into the face, from r1 (towards the next loop vertex) counter-clockwise about the face
/// normal to r2 (towards the previous one), `span` in (0, 2 pi).
struct Corner {
  int face = -1;
  Vec3 r1, r2;
  double span = 0;
  int e_next = -1, e_prev = -1;  // edges along r1 and r2
};

struct Vertex {
  Vec3 p;
  std::vector<int> edges;
  std::vector<Corner> corners;
};

/// Edge v0 -> v1 (v0 < v1 as in the file). face[0] runs it v0 -> v1, face[1] runs it v1 -> v0.
/// m[k]: unit direction in face[k], perpendicular to the edge, pointing into that face.
struct Edge {
  int v0 = -1, v1 = -1;
  int face[2] = {-1, -1};
  Vec3 dir;  // unit, v0 -> v1
  double len = 0;
  Vec3 m[2];
  bool convex = true;
};

struct Face {
  std::vector<std::vector<int>> loops;  // outer first (CCW seen from outside), holes after
  Vec3 n;                               // outward unit normal
  double d = 0;                         // plane n.x = d
  Vec3 o, u, w;                         // 2D frame: x2 = ((x-o).u, (x-o).w), u x w = n
  std::vector<std::vector<Vec2>> loops2;
  std::vector<int> edges;  // boundary edges
  std::vector<int> verts;  // boundary vertices (unique)
  double area = 0, perimeter = 0;
  Vec3 centroid;
  Box3 box;
  Vec2 to2(const Vec3& x) const { return Vec2((x - o).dot(u), (x - o).dot(w)); }
  Vec3 to3(const Vec2& p) const { return o + p.x() * u + p.y() * w; }
};

struct Poly {
  std::string name;
  std::vector<Vertex> V;
  std::vector<Edge> E;
  std::vector<Face> F;
  Box3 box;
  double diag = 0;
  double min_edge = 0;
  std::map<std::pair<int, int>, int> edge_of;  // (min, max) vertex pair -> edge

  int edge_index(int a, int b) const;
  bool vertex_on_edge(int v, int e) const { return E[e].v0 == v || E[e].v1 == v; }
  bool vertex_on_face(int v, int f) const;
  bool edge_on_face(int e, int f) const { return E[e].face[0] == f || E[e].face[1] == f; }
  /// True when element (ka, a) is element (kb, b) or lies on its boundary (kinds: 0 vertex,
  /// 1 edge, 2 face).
  bool in_closure(int ka, int a, int kb, int b) const;
  double volume() const;
  double surface_area() const;
};

/// Builds the featured polyhedron from the graph arrays; throws std::runtime_error naming the
/// problem when they do not describe a closed, consistently oriented polyhedron.
Poly build_poly(const std::vector<Vec3>& verts, const std::vector<std::array<int, 2>>& edges,
                const std::vector<std::vector<std::vector<int>>>& faces, const std::string& name);

// ---- small geometry helpers shared by the oracle ----

/// Counter-clockwise angle from a to b about n, in [0, 2 pi) (a, b need not be unit or exactly
/// perpendicular to n; they are projected).
double ccw_angle(const Vec3& a, const Vec3& b, const Vec3& n);
/// Any unit vector perpendicular to n.
Vec3 any_perp(const Vec3& n);
/// Even-odd point-in-polygon over all loops.
bool inside_loops(const std::vector<std::vector<Vec2>>& loops, const Vec2& p);
/// Distance from p to the boundary of the loops.
double dist_to_loops(const std::vector<std::vector<Vec2>>& loops, const Vec2& p);
double point_seg_dist(const Vec3& p, const Vec3& a, const Vec3& b, double* s = nullptr);
/// Closest points of segments [p0,p1], [q0,q1]: returns the distance, parameters in [0,1].
double seg_seg_dist(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double* s,
                    double* t);
/// Distance from a point (in the face's frame) to the closed face polygon.
double point_face_dist(const Poly& P, const Face& f, const Vec3& x);

}  // namespace oracle

#include <cf/polyhedron.hpp>

#include "tolerances.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

namespace cf {
namespace {

// Planarity tolerance relative to the model's bounding-box diagonal: loose enough for
// coordinates written with 6 decimals, far tighter than any feature of a sensible model.
constexpr double kPlanarityRelTol = 1e-6;

[[noreturn]] void fail(const std::string& model, const std::string& what) {
  throw Error("model '" + model + "': " + what);
}

double signed_area_2d(const std::vector<Eigen::Vector2d>& loop) {
  double a = 0;
  for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
    const auto& p = loop[i];
    const auto& q = loop[(i + 1) % n];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

using EdgeIndex = std::map<std::pair<int, int>, int>;  // an edge by its sorted end points

void check_counts(const std::string& nm, const std::vector<Vec3>& vertices, std::size_t n_faces) {
  const int nv = static_cast<int>(vertices.size());
  if (nv < 4) fail(nm, "has " + std::to_string(nv) + " vertices; a solid needs at least 4");
  if (n_faces < 4) fail(nm, "has " + std::to_string(n_faces) + " faces; a solid needs at least 4");
  for (int i = 0; i < nv; ++i)
    if (!vertices[i].allFinite()) fail(nm, "vertex " + std::to_string(i) + " is not finite");
}

// The edges: their ends, direction and length; returns the index of each by its end points.
EdgeIndex build_edges(const std::string& nm, const std::vector<Vec3>& vertices,
                      const std::vector<std::array<int, 2>>& edges, std::vector<Edge>& out) {
  const int nv = static_cast<int>(vertices.size());
  EdgeIndex edge_of;
  out.resize(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    int a = edges[e][0], b = edges[e][1];
    const std::string where = "edge " + std::to_string(e);
    if (a < 0 || a >= nv || b < 0 || b >= nv)
      fail(nm, where + " has a vertex index out of range [0, " + std::to_string(nv) + ")");
    if (a == b) fail(nm, where + " starts and ends at vertex " + std::to_string(a));
    if (a > b) std::swap(a, b);
    if (!edge_of.emplace(std::make_pair(a, b), static_cast<int>(e)).second)
      fail(nm, where + " repeats edge " + std::to_string(edge_of[{a, b}]));
    Edge& E = out[e];
    E.v0 = VertexId(a);
    E.v1 = VertexId(b);
    const Vec3 d = vertices[b] - vertices[a];
    E.length = d.norm();
    if (!(E.length > 0)) fail(nm, where + " has zero length");
    E.dir = d / E.length;
  }
  return edge_of;
}

// Face f's loops (F.loops, F.edges, F.vertices), and f as the face on the left or right of
// each edge its loops run along (once per direction: a manifold, consistently oriented).
void run_loops(const std::string& nm, int nv, std::size_t f,
               const std::vector<std::vector<int>>& loops, const EdgeIndex& edge_of,
               std::vector<Edge>& edges, Face& F) {
  const std::string where = "face " + std::to_string(f);
  if (loops.empty()) fail(nm, where + " has no loop");
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const auto& loop = loops[l];
    const std::string lw = where + " loop " + std::to_string(l);
    if (loop.size() < 3) fail(nm, lw + " has fewer than 3 vertices");
    std::vector<VertexId> ids;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k], b = loop[(k + 1) % loop.size()];
      if (a < 0 || a >= nv)
        fail(nm, lw + " has vertex index " + std::to_string(a) + " out of range");
      if (b < 0 || b >= nv)
        fail(nm, lw + " has vertex index " + std::to_string(b) + " out of range");
      auto it = edge_of.find({std::min(a, b), std::max(a, b)});
      if (it == edge_of.end())
        fail(nm, lw + " side " + std::to_string(a) + "-" + std::to_string(b) + " is not an edge");
      Edge& E = edges[static_cast<std::size_t>(it->second)];
      FaceId& slot = (E.v0.value() == a) ? E.left : E.right;
      if (slot.valid())
        fail(nm, "edge " + std::to_string(it->second) + " is run in the same direction by faces " +
                     std::to_string(slot.value()) + " and " + std::to_string(f) +
                     " (non-manifold edge or inconsistent orientation)");
      slot = FaceId(static_cast<int>(f));
      F.edges.push_back(EdgeId(it->second));
      ids.push_back(VertexId(a));
      F.vertices.push_back(VertexId(a));
    }
    F.loops.push_back(std::move(ids));
  }
}

// F's plane: the Newell normal of its outer loop and the mean offset of its vertices, which
// must all lie within plane_tol of it.
void face_plane(const std::string& nm, const std::string& where, const std::vector<Vec3>& vertices,
                double plane_tol, Face& F) {
  Vec3 n = Vec3::Zero();
  const auto& outer = F.loops[0];
  for (std::size_t k = 0; k < outer.size(); ++k) {
    const Vec3& p = vertices[outer[k].index()];
    const Vec3& q = vertices[outer[(k + 1) % outer.size()].index()];
    n += p.cross(q);  // Newell: the sum is twice the loop's area vector
  }
  if (!(n.norm() > 0)) fail(nm, where + " has a degenerate outer loop (zero area)");
  F.normal = n.normalized();
  double off = 0;
  for (VertexId v : F.vertices) off += F.normal.dot(vertices[v.index()]);
  F.offset = off / static_cast<double>(F.vertices.size());
  for (VertexId v : F.vertices) {
    const double dev = std::abs(F.normal.dot(vertices[v.index()]) - F.offset);
    if (dev > plane_tol) {
      std::ostringstream os;
      os << where << " is not planar: vertex " << v.value() << " lies " << dev
         << " mm off its plane (tolerance " << plane_tol << " mm)";
      fail(nm, os.str());
    }
  }
}

// F's tangent frame (u from the world axis least aligned with the normal), its loops in that
// frame, its area and centroid; then its edges and vertices sorted (vertices once each).
void face_area(const std::string& nm, const std::string& where, const std::vector<Vec3>& vertices,
               Face& F) {
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(F.normal[i]) < std::abs(F.normal[axis])) axis = i;
  const Vec3 a = Vec3::Unit(axis);
  F.u = (a - a.dot(F.normal) * F.normal).normalized();
  F.v = F.normal.cross(F.u);
  double area = 0, cx = 0, cy = 0;
  for (std::size_t l = 0; l < F.loops.size(); ++l) {
    std::vector<Eigen::Vector2d> pts;
    for (VertexId v : F.loops[l]) {
      const Vec3& p = vertices[v.index()];
      pts.emplace_back(F.u.dot(p), F.v.dot(p));
    }
    const double sa = signed_area_2d(pts);
    // The normal comes from the outer loop itself, so only holes can disagree with it;
    // an inward outer loop shows up as a negative volume.
    if (l > 0 && !(sa < 0))
      fail(nm, where + " hole loop " + std::to_string(l) + " is not clockwise seen from outside");
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const auto& p = pts[k];
      const auto& q = pts[(k + 1) % pts.size()];
      const double c = p.x() * q.y() - q.x() * p.y();
      cx += (p.x() + q.x()) * c;
      cy += (p.y() + q.y()) * c;
    }
    area += sa;
    F.loops_2d.push_back(std::move(pts));
  }
  if (!(area > 0)) fail(nm, where + " has non-positive area");
  F.area = area;
  cx /= 6 * area;
  cy /= 6 * area;
  F.centroid = cx * F.u + cy * F.v + F.offset * F.normal;
  std::sort(F.edges.begin(), F.edges.end());
  std::sort(F.vertices.begin(), F.vertices.end());
  F.vertices.erase(std::unique(F.vertices.begin(), F.vertices.end()), F.vertices.end());
}

// Each edge between two distinct, non-coplanar faces: its convexity and dihedral angle; and
// the edges and faces at each vertex, of which a solid's corner has at least 3 edges.
void link_edges(const std::string& nm, const std::vector<Face>& faces, std::vector<Edge>& edges,
                std::vector<Vertex>& verts) {
  for (std::size_t e = 0; e < edges.size(); ++e) {
    Edge& E = edges[e];
    const std::string where = "edge " + std::to_string(e);
    if (!E.left.valid() || !E.right.valid())
      fail(nm, where + " is bounded by fewer than two faces (open boundary)");
    if (E.left == E.right) fail(nm, where + " has the same face on both sides");
    const Vec3& nl = faces[E.left.index()].normal;
    const Vec3& nr = faces[E.right.index()].normal;
    const double s = nl.cross(nr).dot(E.dir);
    const double c = std::clamp(nl.dot(nr), -1.0, 1.0);
    if (std::abs(s) < internal::kRelativeRounding)  // a sine of unit normals
      fail(nm, where + " separates two coplanar faces");
    E.convex = s > 0;
    const double theta = std::acos(c);  // angle between the outward normals
    E.dihedral = E.convex ? M_PI - theta : M_PI + theta;
    verts[E.v0.index()].edges.push_back(EdgeId(static_cast<int>(e)));
    verts[E.v1.index()].edges.push_back(EdgeId(static_cast<int>(e)));
  }
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (VertexId v : faces[f].vertices)
      verts[v.index()].faces.push_back(FaceId(static_cast<int>(f)));
  for (std::size_t i = 0; i < verts.size(); ++i) {
    if (verts[i].edges.size() < 3)
      fail(nm, "vertex " + std::to_string(i) + " ends " + std::to_string(verts[i].edges.size()) +
                   " edges; a corner of a solid ends at least 3");
  }
}

// Volume and volume centroid: signed tetrahedra from the origin over a fan of every loop.
void mass_properties(const std::vector<Face>& faces, const std::vector<Vec3>& vertices,
                     double& volume, Vec3& centroid) {
  double vol = 0;
  Vec3 moment = Vec3::Zero();
  for (const Face& F : faces) {
    const Vec3 c = F.offset * F.normal;  // a point of the face's plane
    for (const auto& loop : F.loops)
      for (std::size_t k = 0; k < loop.size(); ++k) {
        const Vec3& p = vertices[loop[k].index()];
        const Vec3& q = vertices[loop[(k + 1) % loop.size()].index()];
        const double v6 = c.dot(p.cross(q));
        vol += v6;
        moment += v6 * (c + p + q);  // tetra centroid is (0 + c + p + q) / 4
      }
  }
  volume = vol / 6.0;
  centroid = moment / (4.0 * vol);
}

}  // namespace

Polyhedron Polyhedron::with_vertices(std::vector<Vec3> vertices) const {
  if (vertices.size() != vertices_.size())
    fail(name_, "with_vertices: " + std::to_string(vertices.size()) + " vertices given for " +
                    std::to_string(vertices_.size()));
  std::vector<std::array<int, 2>> edges;
  edges.reserve(edges_.size());
  for (const Edge& e : edges_) edges.push_back({e.v0.value(), e.v1.value()});
  std::vector<std::vector<std::vector<int>>> loops(faces_.size());
  for (std::size_t f = 0; f < faces_.size(); ++f)
    for (const auto& loop : faces_[f].loops) {
      loops[f].emplace_back();
      for (VertexId u : loop) loops[f].back().push_back(u.value());
    }
  return from_features(name_, std::move(vertices), edges, loops);
}

Polyhedron Polyhedron::from_features(std::string name, std::vector<Vec3> vertices,
                                     const std::vector<std::array<int, 2>>& edges,
                                     const std::vector<std::vector<std::vector<int>>>& face_loops) {
  Polyhedron m;
  m.name_ = std::move(name);
  const std::string& nm = m.name_;
  const int nv = static_cast<int>(vertices.size());
  check_counts(nm, vertices, face_loops.size());

  m.bbox_min_ = m.bbox_max_ = vertices[0];
  for (const Vec3& p : vertices) {
    m.bbox_min_ = m.bbox_min_.cwiseMin(p);
    m.bbox_max_ = m.bbox_max_.cwiseMax(p);
  }
  m.size_ = (m.bbox_max_ - m.bbox_min_).norm();
  m.vertices_.resize(vertices.size());
  for (int i = 0; i < nv; ++i) m.vertices_[i].p = vertices[i];

  const EdgeIndex edge_of = build_edges(nm, vertices, edges, m.edges_);
  m.faces_.resize(face_loops.size());
  const double plane_tol = kPlanarityRelTol * m.size_;
  for (std::size_t f = 0; f < face_loops.size(); ++f) {
    Face& F = m.faces_[f];
    const std::string where = "face " + std::to_string(f);
    run_loops(nm, nv, f, face_loops[f], edge_of, m.edges_, F);
    face_plane(nm, where, vertices, plane_tol, F);
    face_area(nm, where, vertices, F);
  }
  link_edges(nm, m.faces_, m.edges_, m.vertices_);

  mass_properties(m.faces_, vertices, m.volume_, m.volume_centroid_);
  if (!(m.volume_ > 0)) fail(nm, "encloses a non-positive volume: faces are oriented inward");
  Vec3 sum = Vec3::Zero();
  for (const Vec3& p : vertices) sum += p;
  m.vertex_centroid_ = sum / nv;
  return m;
}

bool Polyhedron::edge_bounds_face(EdgeId e, FaceId f) const {
  const Edge& E = edges_[e.index()];
  return E.left == f || E.right == f;
}

bool Polyhedron::vertex_ends_edge(VertexId v, EdgeId e) const {
  const Edge& E = edges_[e.index()];
  return E.v0 == v || E.v1 == v;
}

bool Polyhedron::vertex_on_face(VertexId v, FaceId f) const {
  const auto& vs = faces_[f.index()].vertices;
  return std::binary_search(vs.begin(), vs.end(), v);
}

double Polyhedron::face_inset_2d(FaceId f, const Eigen::Vector2d& q) const {
  return locate_in_face(*this, f, q).inset();
}

double Polyhedron::face_inset(FaceId f, const Vec3& p) const {
  return face_inset_2d(f, face_coords(f, p));
}

}  // namespace cf

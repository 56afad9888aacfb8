// The one CGAL translation unit of the tools: file reading (CGAL::IO) and the
// self-intersection test (Polygon_mesh_processing). Everything else is in mesh_features.cpp.

#include "mesh_detail.hpp"

#include <cf/file_io.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Projection_traits_xy_3.h>
#include <CGAL/Projection_traits_xz_3.h>
#include <CGAL/Projection_traits_yz_3.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <unordered_map>

namespace cf::tools {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Vector = K::Vector_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace fs = std::filesystem;
using detail::fail;

// Records, for every triangle of the triangulated mesh, the input facet it came from.
struct FacetOrigin : PMP::Triangulate_faces::Default_visitor<Mesh> {
  std::vector<int>* origin;
  int current = -1;
  explicit FacetOrigin(std::vector<int>* o) : origin(o) {}
  void before_subface_creations(Mesh::Face_index f) { current = (*origin)[f]; }
  void after_subface_created(Mesh::Face_index f) {
    if (origin->size() <= f) origin->resize(f + 1, -1);
    (*origin)[f] = current;
  }
};

// A polygon's plane, exactly: the corner at its lexicographically smallest vertex (a strictly
// convex corner of a simple polygon, so its three points span the plane and give the
// polygon's orientation in it), and whether every vertex lies in that plane.
struct PolygonPlane {
  std::array<std::size_t, 3> corner{};
  bool planar = false;  // and simple: the polygons merged
};

// Whether a loop of points in one plane is a simple polygon (O(n log n), exact: the points are
// projected along the axis of the plane's normal's largest component).
bool simple_in_plane(const std::vector<Point>& points, const std::vector<std::size_t>& loop,
                     const PolygonPlane& plane) {
  const Point& a = points[plane.corner[0]];
  const Vector n = CGAL::normal(a, points[plane.corner[1]], points[plane.corner[2]]);
  const double ax = std::abs(n.x()), ay = std::abs(n.y()), az = std::abs(n.z());
  std::vector<Point> ring;
  ring.reserve(loop.size());
  for (std::size_t v : loop) ring.push_back(points[v]);
  if (az >= ax && az >= ay)
    return CGAL::is_simple_2(ring.begin(), ring.end(), CGAL::Projection_traits_xy_3<K>());
  if (ay >= ax)
    return CGAL::is_simple_2(ring.begin(), ring.end(), CGAL::Projection_traits_xz_3<K>());
  return CGAL::is_simple_2(ring.begin(), ring.end(), CGAL::Projection_traits_yz_3<K>());
}

PolygonPlane polygon_plane(const std::vector<Point>& points, const std::vector<std::size_t>& poly) {
  PolygonPlane out;
  std::size_t m = 0;
  for (std::size_t i = 1; i < poly.size(); ++i)
    if (points[poly[i]] < points[poly[m]]) m = i;
  out.corner = {poly[(m + poly.size() - 1) % poly.size()], poly[m], poly[(m + 1) % poly.size()]};
  const Point& a = points[out.corner[0]];
  const Point& b = points[out.corner[1]];
  const Point& c = points[out.corner[2]];
  if (CGAL::collinear(a, b, c)) return out;
  out.planar = std::all_of(poly.begin(), poly.end(),
                           [&](std::size_t v) { return CGAL::coplanar(a, b, c, points[v]); });
  // A polygon that crosses itself is left to the test (merged, its crossing could cancel).
  if (out.planar && poly.size() > 3) out.planar = simple_in_plane(points, poly, out);
  return out;
}

// Whether two exactly planar polygons lie in one plane with one orientation.
bool same_plane(const std::vector<Point>& points, const PolygonPlane& p, const PolygonPlane& q) {
  const auto at = [&](const PolygonPlane& x, int i) -> const Point& { return points[x.corner[i]]; };
  for (int i = 0; i < 3; ++i)
    if (!CGAL::coplanar(at(p, 0), at(p, 1), at(p, 2), at(q, i))) return false;
  // Coherent within one plane (CGAL's guarantee for the three-point form).
  return CGAL::coplanar_orientation(at(p, 0), at(p, 1), at(p, 2)) ==
         CGAL::coplanar_orientation(at(q, 0), at(q, 1), at(q, 2));
}

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// The boundary of a group of polygons as one loop, in order; empty when it is not one loop
// (a hole, or a vertex the boundary passes twice).
std::vector<std::size_t> group_loop(const std::vector<std::vector<std::size_t>>& polygons,
                                    const std::vector<std::size_t>& group) {
  std::map<std::pair<std::size_t, std::size_t>, int> edges;  // directed, counted
  for (std::size_t k : group)
    for (std::size_t i = 0; i < polygons[k].size(); ++i)
      ++edges[{polygons[k][i], polygons[k][(i + 1) % polygons[k].size()]}];
  std::map<std::size_t, std::size_t> next;
  for (const auto& [e, n] : edges)
    if (!edges.count({e.second, e.first}) && !next.emplace(e.first, e.second).second) return {};
  if (next.empty()) return {};
  std::vector<std::size_t> loop{next.begin()->first};
  for (std::size_t v = next.at(loop[0]); v != loop[0]; v = next.at(v)) {
    if (loop.size() == next.size() || !next.count(v)) return {};
    loop.push_back(v);
  }
  if (loop.size() != next.size()) return {};
  return loop;
}

// Merges each set of adjacent polygons that lie exactly in one plane with one orientation
// into one polygon, its boundary (a face written as many facets: an STL's triangles, the
// strips along a prism's side), where that boundary is one simple loop. The polygons cover
// the same points, so the test of self-intersection gives the same answer, but the facets
// of a finely divided face, and the slivers a polygon with thousands of sides triangulates
// into, have boxes that nearly all meet, which makes the test quadratic. facet[k]: the first
// input facet of polygon k.
void merge_flat_neighbours(const std::vector<Point>& points,
                           std::vector<std::vector<std::size_t>>& polygons,
                           std::vector<int>& facet) {
  const std::size_t n = polygons.size();
  std::vector<PolygonPlane> planes(n);
  for (std::size_t k = 0; k < n; ++k) planes[k] = polygon_plane(points, polygons[k]);
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> owner;  // directed edge
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t i = 0; i < polygons[k].size(); ++i)
      owner[{polygons[k][i], polygons[k][(i + 1) % polygons[k].size()]}] = k;
  std::vector<std::size_t> parent(n);
  for (std::size_t k = 0; k < n; ++k) parent[k] = k;
  for (const auto& [e, k] : owner) {
    const auto it = owner.find({e.second, e.first});
    if (it == owner.end() || it->second <= k || !planes[k].planar || !planes[it->second].planar)
      continue;
    if (same_plane(points, planes[k], planes[it->second]))
      parent[find_root(parent, it->second)] = find_root(parent, k);
  }
  std::map<std::size_t, std::vector<std::size_t>> groups;  // by root, members ascending
  for (std::size_t k = 0; k < n; ++k) groups[find_root(parent, k)].push_back(k);
  std::vector<std::vector<std::size_t>> out;
  std::vector<int> out_facet;
  for (const auto& [root, group] : groups) {
    std::vector<std::size_t> loop;
    if (group.size() > 1) loop = group_loop(polygons, group);
    if (loop.size() >= 3 && simple_in_plane(points, loop, planes[group[0]])) {
      out.push_back(std::move(loop));
      out_facet.push_back(static_cast<int>(group[0]));
      continue;
    }
    for (std::size_t k : group) {
      out.push_back(polygons[k]);
      out_facet.push_back(static_cast<int>(k));
    }
  }
  polygons.swap(out);
  facet.swap(out_facet);
}

// Removes from every polygon the vertices that lie strictly inside the segment between their
// two neighbours, in every polygon that holds them and with the same neighbours there (a
// run of vertices along a straight edge, as CAD exports write the edges of a face that meets
// a tessellated one). The polygons cover the same points, and each pair of polygons still
// shares its edges, so the test of self-intersection gives the same answer; but a polygon
// with thousands of such vertices triangulates into slivers whose boxes all meet, which
// makes the test quadratic. Exact predicates; nothing is removed if a polygon would be left
// with fewer than 3 vertices.
void drop_straight_vertices(const std::vector<Point>& points,
                            std::vector<std::vector<std::size_t>>& polygons) {
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  // Per vertex: its neighbours (smaller index first) where first met; cleared (kNone) when a
  // polygon turns at it or meets it with other neighbours.
  std::vector<std::array<std::size_t, 2>> along(points.size(), {kNone, kNone});
  std::vector<char> seen(points.size(), 0), straight(points.size(), 1);
  for (const auto& poly : polygons)
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const std::size_t u = poly[(i + poly.size() - 1) % poly.size()], v = poly[i],
                        w = poly[(i + 1) % poly.size()];
      const std::array<std::size_t, 2> pair{std::min(u, w), std::max(u, w)};
      const bool between =
          CGAL::collinear(points[u], points[v], points[w]) &&
          CGAL::collinear_are_strictly_ordered_along_line(points[u], points[v], points[w]);
      if (!between || (seen[v] && along[v] != pair)) straight[v] = 0;
      seen[v] = 1;
      along[v] = pair;
    }
  std::vector<std::vector<std::size_t>> out(polygons.size());
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    for (std::size_t v : polygons[k])
      if (!straight[v]) out[k].push_back(v);
    if (out[k].size() < 3) return;
  }
  polygons.swap(out);
}

// Whether the polygons form a closed, consistently oriented 2-manifold: every directed edge
// once, its reverse once, and the polygons around each vertex one fan (walked corner to
// corner across edges). Time linear in the polygons' total size.
bool closed_manifold(const std::vector<std::vector<std::size_t>>& polygons, std::size_t points) {
  // Directed edge (a, b) -> the polygon and corner of a.
  std::unordered_map<std::uint64_t, std::pair<std::size_t, std::size_t>> edge;
  const auto key = [&](std::size_t a, std::size_t b) { return a * points + b; };
  std::vector<std::size_t> corners(points, 0);
  for (std::size_t k = 0; k < polygons.size(); ++k)
    for (std::size_t i = 0; i < polygons[k].size(); ++i) {
      const std::size_t a = polygons[k][i], b = polygons[k][(i + 1) % polygons[k].size()];
      if (a == b || !edge.emplace(key(a, b), std::pair{k, i}).second) return false;
      ++corners[a];
    }
  std::vector<char> done(points, 0);
  for (const auto& [e, at] : edge) {
    if (!edge.count(key(e % points, e / points))) return false;  // an edge with one side
    const std::size_t v = e / points;
    if (done[v]) continue;
    done[v] = 1;
    // Around v: from corner (k, i), whose polygon runs v -> w, to the polygon running w -> v.
    std::size_t walked = 0;
    auto [k, i] = at;
    do {
      const std::size_t w = polygons[k][(i + 1) % polygons[k].size()];
      const auto& [g, j] = edge.at(key(w, v));
      k = g;
      i = (j + 1) % polygons[g].size();
    } while (++walked <= corners[v] && !(k == at.first && i == at.second));
    if (walked != corners[v]) return false;
  }
  return true;
}

void check_self_intersection(const PolygonSoup& s, const std::string& src) {
  std::vector<Point> points;
  points.reserve(s.points.size());
  for (const Vec3& p : s.points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(s.polygons.size());
  for (const auto& poly : s.polygons) polygons.emplace_back(poly.begin(), poly.end());
  std::vector<int> facet;  // the first input facet of each polygon
  merge_flat_neighbours(points, polygons, facet);
  drop_straight_vertices(points, polygons);
  // check_soup has established a closed, consistently oriented 2-manifold, which the two
  // steps above keep; this is a guard (PMP's own takes time quadratic in a polygon's size).
  if (!closed_manifold(polygons, points.size()))
    fail(src, "the facets do not form a 2-manifold polygon mesh");
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  // Faces are created in soup order, so face i is polygon i until triangulation.
  std::vector<int> origin = facet;
  FacetOrigin visitor(&origin);
  if (!PMP::triangulate_faces(mesh, CGAL::parameters::visitor(visitor)))
    fail(src, "degenerate facet: a polygonal facet cannot be triangulated");
  if (!PMP::does_self_intersect(mesh)) return;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(mesh, std::back_inserter(pairs));
  int a = -1, b = -1;
  if (!pairs.empty()) {
    a = origin[pairs.front().first];
    b = origin[pairs.front().second];
    if (a > b) std::swap(a, b);
  }
  fail(src, "self-intersection: facets " + std::to_string(a) + " and " + std::to_string(b) +
                " intersect (" + std::to_string(pairs.size()) + " intersecting triangle pairs)");
}

// Refuses an option outside [lo, hi] (or NaN), `format` saying which with the value and range.
void check_option(double v, double lo, double hi, const char* format, const std::string& source) {
  if (v >= lo && v <= hi) return;
  char buf[160];
  std::snprintf(buf, sizeof buf, format, v, lo, hi);
  fail(source, buf);
}

}  // namespace

MeasuredModel measured_model_from_soup(const PolygonSoup& soup, const std::string& source,
                                       const LoadOptions& options) {
  check_option(options.coplanar_rel_tol, kMinCoplanarTol, kMaxCoplanarTol,
               "coplanarity tolerance %g is outside [%g, %g]", source);
  check_option(options.crease_angle_deg, kMinCreaseAngle, kMaxCreaseAngle,
               "crease angle %g degrees is outside [%g, %g]", source);
  for (std::size_t i = 0; i < soup.points.size(); ++i) {
    const Vec3& p = soup.points[i];
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(p[k]) || std::abs(p[k]) > kMaxCoordinateMm) {
        char buf[200];
        std::snprintf(
            buf, sizeof buf,
            "vertex %zu has the coordinate %g mm, beyond the largest accepted (|x| <= %g mm)", i,
            p[k], kMaxCoordinateMm);
        fail(source, buf);
      }
  }
  detail::check_soup(soup, source, options);
  if (options.check_self_intersection) check_self_intersection(soup, source);
  const std::string name = options.name.empty() ? fs::path(source).stem().string() : options.name;
  detail::FeatureMeasures measures;
  cf::Polyhedron model = detail::extract_features(soup, source, name, options, &measures);
  const double precision = std::max(measures.off_plane, model_precision(model));
  // The soup's points as given (load_measured_model measures them before scaling to mm).
  return {std::move(model), precision, coordinate_rounding(soup.points), measures.deviation};
}

cf::Polyhedron model_from_soup(const PolygonSoup& soup, const std::string& source,
                               const LoadOptions& options) {
  return measured_model_from_soup(soup, source, options).model;
}

std::string size_warning(const cf::Polyhedron& model, const std::string& which,
                         const std::string& unit_option, double epsilon_mm) {
  std::string w = cf::size_warning(model, which, epsilon_mm);
  if (!w.empty())
    w += "; if the file is not in mm, give its unit with " + unit_option + " (mm, cm, m or in)";
  return w;
}

double mm_per_unit(const std::string& unit) {
  if (unit == "mm") return 1;
  if (unit == "cm") return 10;
  if (unit == "m") return 1000;
  if (unit == "in") return 25.4;
  return 0;
}

MeasuredModel load_measured_model(const std::string& path, const LoadOptions& options) {
  const double scale = mm_per_unit(options.units);
  if (!(scale > 0)) fail(path, "unknown unit '" + options.units + "' (expected mm, cm, m or in)");
  PolygonSoup soup = read_polygon_soup(path);
  // How the file wrote its numbers, before they are scaled to mm.
  const double rounding = coordinate_rounding(soup.points) * scale;
  if (scale != 1)
    for (Vec3& p : soup.points) p *= scale;
  MeasuredModel out = measured_model_from_soup(soup, path, options);
  out.rounding_mm = rounding;
  return out;
}

cf::Polyhedron load_model(const std::string& path, const LoadOptions& options) {
  return load_measured_model(path, options).model;
}

}  // namespace cf::tools

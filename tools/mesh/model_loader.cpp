// The one CGAL translation unit of the tools: file reading (CGAL::IO) and the
// self-intersection test (Polygon_mesh_processing). Everything else is in mesh_features.cpp.

#include "mesh_detail.hpp"

#include <cf/file_io.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace cf::tools {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
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

void check_self_intersection(const PolygonSoup& s, const std::string& src) {
  std::vector<Point> points;
  points.reserve(s.points.size());
  for (const Vec3& p : s.points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(s.polygons.size());
  for (const auto& poly : s.polygons) polygons.emplace_back(poly.begin(), poly.end());
  // check_soup has established a closed, consistently oriented 2-manifold; this is a guard.
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons))
    fail(src, "the facets do not form a 2-manifold polygon mesh");
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  // Faces are created in soup order, so face i is input facet i until triangulation.
  std::vector<int> origin(mesh.number_of_faces());
  for (std::size_t i = 0; i < origin.size(); ++i) origin[i] = static_cast<int>(i);
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

}  // namespace

MeasuredModel measured_model_from_soup(const PolygonSoup& soup, const std::string& source,
                                       const LoadOptions& options) {
  if (!(options.coplanar_rel_tol >= kMinCoplanarTol &&
        options.coplanar_rel_tol <= kMaxCoplanarTol)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "coplanarity tolerance %g is outside [%g, %g]",
                  options.coplanar_rel_tol, kMinCoplanarTol, kMaxCoplanarTol);
    fail(source, buf);
  }
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
  double off_plane = 0;
  cf::Polyhedron model = detail::extract_features(soup, source, name, options, &off_plane);
  const double precision = std::max(off_plane, model_precision(model));
  return {std::move(model), precision};
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
  if (scale != 1)
    for (Vec3& p : soup.points) p *= scale;
  return measured_model_from_soup(soup, path, options);
}

cf::Polyhedron load_model(const std::string& path, const LoadOptions& options) {
  return load_measured_model(path, options).model;
}

}  // namespace cf::tools

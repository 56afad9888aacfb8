// The one CGAL translation unit of the tools: file reading (CGAL::IO) and the
// self-intersection test (Polygon_mesh_processing). Everything else is in mesh_features.cpp.

#include "mesh_detail.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OBJ.h>
#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>

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

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

PolygonSoup read_polygon_soup(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "cannot open file: no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "cannot open file: not a regular file");
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext != ".off" && ext != ".obj" && ext != ".stl" && ext != ".ply")
    fail(path, "unknown file extension '" + fs::path(path).extension().string() +
                   "' (expected .off, .obj, .stl or .ply)");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) fail(path, "cannot open file: not readable");
    if (probe.peek() == std::ifstream::traits_type::eof()) fail(path, "the file is empty");
  }

  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  const auto np = CGAL::parameters::verbose(false);
  bool ok = false;
  std::string format;
  if (ext == ".off") {
    format = "OFF";
    ok = CGAL::IO::read_OFF(path, points, polygons, np);
  } else if (ext == ".obj") {
    format = "OBJ";
    ok = CGAL::IO::read_OBJ(path, points, polygons, np);
  } else if (ext == ".stl") {
    format = "STL";
    std::vector<std::array<std::size_t, 3>> triangles;
    ok = CGAL::IO::read_STL(path, points, triangles, np);
    for (const auto& t : triangles) polygons.emplace_back(t.begin(), t.end());
  } else {
    format = "PLY";
    ok = CGAL::IO::read_PLY(path, points, polygons, np);
  }
  if (!ok) fail(path, "parse error: not a readable " + format + " file");
  if (points.empty() || polygons.empty()) {
    // CGAL's STL reader gives up silently (no facets) on text that is neither ascii nor
    // binary STL; only a blank file is truly without facets.
    std::ifstream in(path, std::ios::binary);
    char c;
    bool blank = true;
    while (blank && in.get(c)) blank = std::isspace(static_cast<unsigned char>(c)) != 0;
    if (format == "STL" && !blank) fail(path, "parse error: not a readable STL file");
    fail(path, "the file contains no facets");
  }

  // Merge points with identical coordinates into the first occurrence. Every point keeps its
  // input index (duplicates are left unused), so messages and index rules use file order.
  PolygonSoup soup;
  soup.points.reserve(points.size());
  std::vector<int> remap(points.size());
  std::map<std::array<double, 3>, int> first;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::array<double, 3> c{points[i].x(), points[i].y(), points[i].z()};
    soup.points.emplace_back(c[0], c[1], c[2]);
    remap[i] = first.emplace(c, static_cast<int>(i)).first->second;
  }
  soup.polygons.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    std::vector<int> poly;
    poly.reserve(polygons[f].size());
    for (std::size_t i : polygons[f]) {
      if (i >= points.size())
        fail(path, "parse error: facet " + std::to_string(f) + " refers to vertex " +
                       std::to_string(i) + " but the file has " + std::to_string(points.size()) +
                       " vertices");
      poly.push_back(remap[i]);
    }
    soup.polygons.push_back(std::move(poly));
  }
  return soup;
}

cf::Polyhedron model_from_soup(const PolygonSoup& soup, const std::string& source,
                               const LoadOptions& options) {
  if (!(options.coplanar_rel_tol > 0 && options.coplanar_rel_tol < 0.1))
    fail(source, "coplanarity tolerance " + std::to_string(options.coplanar_rel_tol) +
                     " is outside (0, 0.1)");
  detail::check_soup(soup, source, options);
  if (options.check_self_intersection) check_self_intersection(soup, source);
  const std::string name =
      options.name.empty() ? fs::path(source).stem().string() : options.name;
  return detail::extract_features(soup, source, name, options);
}

cf::Polyhedron load_model(const std::string& path, const LoadOptions& options) {
  return model_from_soup(read_polygon_soup(path), path, options);
}

}  // namespace cf::tools

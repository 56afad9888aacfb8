#pragma once
/// @file
/// Reading a polyhedral model from a mesh file (OFF, OBJ, STL, PLY), validating it and
/// extracting its features (SPEC section 3). CGAL-free interface: CGAL stays inside
/// model_loader.cpp. Definitions, tolerances and index rules: docs/features.md.

#include <cf/polyhedron.hpp>

#include <string>
#include <vector>

namespace cf::tools {

/// Options for load_model and model_from_soup.
struct LoadOptions {
  /// Display name of the model; empty means the file name without directory and extension.
  std::string name;
  /// Coplanarity / collinearity tolerance relative to the bounding-box diagonal: facets whose
  /// vertices all lie within coplanar_rel_tol * diagonal of a face's plane join that face, and
  /// a mesh vertex within that distance of the straight line through its two boundary
  /// neighbours is not a feature vertex. Default 1e-5: 100x above single-precision (STL)
  /// rounding, far below any intended feature of a model.
  double coplanar_rel_tol = 1e-5;
  /// Run the (slowest) self-intersection check.
  bool check_self_intersection = true;
};

/// A polygon soup as read from a file: points (mm) and facets as indices into them.
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<std::vector<int>> polygons;
};

/// Reads the raw polygon soup of a mesh file; the format comes from the extension (.off, .obj,
/// .stl, .ply, any case). Points with identical coordinates are merged into the first one
/// (STL stores every corner separately), and facet indices are rewritten accordingly.
/// @throws cf::Error naming the file: missing or unreadable, empty, unknown extension,
///   parse error.
PolygonSoup read_polygon_soup(const std::string& path);

/// Validates a soup as a closed, outward-oriented, 2-manifold, non-self-intersecting single
/// solid and extracts its features.
/// @param source where the soup came from, for messages (a file name).
/// @throws cf::Error "loading '<source>': <problem>" for every rejected input (open boundary,
///   non-manifold edge or vertex, inconsistent or inward orientation, degenerate or
///   non-planar facet, several solids, self-intersection).
cf::Polyhedron model_from_soup(const PolygonSoup& soup, const std::string& source,
                               const LoadOptions& options = {});

/// read_polygon_soup then model_from_soup.
/// @throws cf::Error with a one-line message that names the file and the problem.
cf::Polyhedron load_model(const std::string& path, const LoadOptions& options = {});

}  // namespace cf::tools

#pragma once
// Private to cftools_mesh: the CGAL-free halves of model_from_soup (mesh_features.cpp), so
// that the one CGAL translation unit (model_loader.cpp) stays small.

#include "model_loader.hpp"

#include <string>

namespace cf::tools::detail {

/// "loading '<source>': <what>"
[[noreturn]] void fail(const std::string& source, const std::string& what);

/// Topological and geometric checks that need no CGAL: facet sizes and indices, repeated
/// vertices, edge manifoldness, open boundary, orientation consistency, vertex manifoldness,
/// zero-area and non-planar facets, several solids, negative volume. Throws cf::Error.
void check_soup(const PolygonSoup& soup, const std::string& source, const LoadOptions& options);

/// How far the features are from the soup they were extracted from.
struct FeatureMeasures {
  /// mm: the largest distance of a feature vertex from the fitted plane of one of its faces
  /// as read (before the snap): the file's precision as its data show it.
  double off_plane = 0;
  /// mm: the largest distance of a vertex of the soup from the final plane of a face its
  /// facets are part of, or of a feature vertex from where the soup had it: how far the file's
  /// facets are from the polyhedron's faces (faces merged at a coarse tolerance, rounding).
  double deviation = 0;
};

/// Faces, edges and vertices of section 3 of docs/spec.md from a soup that passed check_soup.
/// measures, when given: how far they are from the soup.
cf::Polyhedron extract_features(const PolygonSoup& soup, const std::string& source,
                                const std::string& name, const LoadOptions& options,
                                FeatureMeasures* measures = nullptr);

}  // namespace cf::tools::detail

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

/// Faces, edges and vertices of section 3 of docs/spec.md from a soup that passed check_soup.
/// off_plane, when given: mm, the largest distance of a feature vertex from the fitted plane
/// of one of its faces as read (before the snap): the file's precision as its data show it.
cf::Polyhedron extract_features(const PolygonSoup& soup, const std::string& source,
                                const std::string& name, const LoadOptions& options,
                                double* off_plane = nullptr);

}  // namespace cf::tools::detail

#pragma once
/// @file
/// Reading a polyhedral model from a mesh file (OFF, OBJ, STL, PLY), validating it and
/// extracting its features (docs/spec.md, section 3). CGAL-free interface: CGAL stays inside
/// model_loader.cpp. Definitions, tolerances and index rules: docs/features.md.

#include <cf/polyhedron.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace cf::tools {

/// Coplanarity tolerances accepted (LoadOptions::coplanar_rel_tol, cfgen --coplanar-tol).
constexpr double kMinCoplanarTol = 1e-12;
constexpr double kMaxCoplanarTol = 0.1;
/// Crease angles accepted, degrees (LoadOptions::crease_angle_deg, cfgen --crease-angle).
constexpr double kMinCreaseAngle = 0;
constexpr double kMaxCreaseAngle = 180;
/// Largest |coordinate| of a model, in mm after the unit conversion (1000 km): beyond it
/// areas and volumes lose all precision, and no haptic scene is that large.
constexpr double kMaxCoordinateMm = 1e9;

/// Millimetres per unit of a model file's unit name (docs/spec.md, section 2: mm, cm, m, in);
/// 0 for an unknown name.
double mm_per_unit(const std::string& unit);

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
  /// Degrees: a facet joins a face only when its normal is within this angle of the face's
  /// normal so far, so a face merged at a coarse coplanar_rel_tol never spans more than twice
  /// it (a finely tessellated cylinder becomes a prism, not one face). The default is above
  /// the normal noise of thin facets written as float32 and below the bends of curved parts
  /// (docs/features.md, "Creases").
  double crease_angle_deg = 10;
  /// Run the (slowest) self-intersection check.
  bool check_self_intersection = true;
  /// The length unit of the file's coordinates: "mm" (the default), "cm", "m" or "in".
  /// load_model converts the points to mm.
  std::string units = "mm";
};

/// A polygon soup as read from a file: points (mm) and facets as indices into them.
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<std::vector<int>> polygons;
};

/// The mesh file formats.
enum class MeshFormat { kOff, kObj, kStl, kPly };

/// The format of a file from its extension (.off, .obj, .stl, .ply, any case).
/// @throws cf::Error "loading '<path>': unknown file extension ..."
MeshFormat mesh_format_of(const std::string& path);

/// Parses a mesh file's bytes (mesh_read.cpp; no CGAL). Points with identical coordinates
/// are merged into the first one (STL stores every corner separately), and facet indices
/// are rewritten accordingly. Counts in headers are checked against the bytes that follow
/// before anything is allocated; indices against their range; numbers must be finite.
/// @throws cf::Error "loading '<source>': ..." (empty, parse error with the line, no facets).
PolygonSoup parse_polygon_soup(std::string_view bytes, MeshFormat format,
                               const std::string& source);

/// Reads the raw polygon soup of a mesh file (the format from the extension), without
/// blocking on a FIFO or reading anything that is not a regular file.
/// @throws cf::Error naming the file: missing or unreadable, not a regular file, empty,
///   unknown extension, parse error.
PolygonSoup read_polygon_soup(const std::string& path);

/// Validates a soup as a closed, outward-oriented, 2-manifold, non-self-intersecting single
/// solid and extracts its features.
/// @param source where the soup came from, for messages (a file name).
/// @throws cf::Error "loading '<source>': <problem>" for every rejected input (open boundary,
///   non-manifold edge or vertex, inconsistent or inward orientation, degenerate or
///   non-planar facet, several solids, self-intersection).
cf::Polyhedron model_from_soup(const PolygonSoup& soup, const std::string& source,
                               const LoadOptions& options = {});

/// Units of rounding (the machine epsilon times the largest coordinate) a model is taken to
/// be exact to at best: a pose applied to a point far from the origin rounds by about that
/// much (docs/features.md, "Precision").
constexpr double kPrecisionRoundings = 4;

/// mm: how closely a model's geometry holds as it stands: the largest distance of a face's
/// vertex from the face's plane, and at least kPrecisionRoundings units of rounding of its
/// largest coordinate (a model far from its origin).
double model_precision(const cf::Polyhedron& model);

/// The most a coordinate of `points` can be from the value it stands for, by how it was
/// written (in the points' unit): half a unit in the last place of float32 when every
/// coordinate is a float32 value (binary STL and PLY, or text printed from floats), else half
/// a unit of the writer's last significant digit at the largest coordinate (the digits: the
/// most that any coordinate needs to read back exactly, over a deterministic sample of at
/// most kRoundingSample coordinates, the largest included), and at least a double's own
/// rounding. A value written with few digits may be exact, so this is an upper bound
/// (docs/features.md, "Precision").
double coordinate_rounding(const std::vector<Vec3>& points);

/// Coordinates coordinate_rounding() reads the digits of (each is a few conversions).
constexpr std::size_t kRoundingSample = 4096;

/// A model and how closely its file holds it (docs/features.md, "Precision").
struct MeasuredModel {
  cf::Polyhedron model;
  /// mm: the larger of model_precision(model) and the largest distance of a feature vertex
  /// from the fitted plane of one of its faces as the file gave it (before the vertex was
  /// moved onto its planes): about the rounding of the file's coordinates (float32, or the
  /// digits written). The generator's touch tolerance is at least a multiple of it
  /// (tools/cfgen/generate.hpp).
  double precision_mm = 0;
  /// mm: coordinate_rounding() of the file's points, in mm. The generator's symmetry
  /// tolerance is a multiple of it, within bounds (tools/cfgen/generate.hpp).
  double rounding_mm = 0;
  /// mm: how far the file's facets are from the model's faces: the largest distance of a
  /// vertex of the file from the plane of a face its facets became part of, or of a corner
  /// from where the file had it. Facets merged at a coarse coplanar_rel_tol make it up to
  /// about that tolerance; otherwise it is the file's rounding (docs/features.md, "Creases").
  double deviation_mm = 0;
};

/// Empty when `model` is a reasonable size against the contact threshold `epsilon_mm` (the
/// paper's 1 mm by default), else a warning naming the sizes and `unit_option`, the option
/// that gives the file's unit (docs/spec.md, section 2).
std::string size_warning(const cf::Polyhedron& model, const std::string& which,
                         const std::string& unit_option, double epsilon_mm = 1.0);

/// read_polygon_soup, the points converted from options.units to mm, then model_from_soup.
/// @throws cf::Error with a one-line message that names the file and the problem.
cf::Polyhedron load_model(const std::string& path, const LoadOptions& options = {});

/// model_from_soup, with the model's precision.
/// @throws as model_from_soup.
MeasuredModel measured_model_from_soup(const PolygonSoup& soup, const std::string& source,
                                       const LoadOptions& options = {});

/// load_model, with the model's precision.
/// @throws as load_model.
MeasuredModel load_measured_model(const std::string& path, const LoadOptions& options = {});

}  // namespace cf::tools

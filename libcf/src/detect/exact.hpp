#pragma once
// The exact pair tests of detection (docs/runtime.md, "Tests per type"): one free function
// per PC type. Each returns, by value, the contact it found or, when it turns the pair
// away, a certificate of how far A may move and turn from this pose before the pair could
// pass (the pairs kept between ticks skip a pair while it holds). What the tests read of
// the model pair is built once (PairTables); the pose and A's vertices posed at it are per
// call (PosedA); their scratch is the caller's (ExactScratch). Nothing allocates.

#include <cf/contact.hpp>
#include <cf/params.hpp>
#include <cf/polyhedron.hpp>

#include "polygon_clipping.hpp"
#include "tolerances.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace cf::internal {

/// Flattened 2D loops of every face of a model, in each face's own (u, v) frame.
struct FlatFaces {
  std::vector<Vec2> pts;
  std::vector<int> loop_begin;  ///< per loop, plus a sentinel
  std::vector<int> face_first;  ///< per face, its first loop index, plus a sentinel
  std::vector<char> convex;     ///< per face, internal::is_convex
  int max_face_points = 0;

  explicit FlatFaces(const Polyhedron& m);
  FlatFaces() = default;
  Poly2 poly(int f) const {
    const int l0 = face_first[static_cast<std::size_t>(f)];
    const int l1 = face_first[static_cast<std::size_t>(f) + 1];
    return {pts.data(), loop_begin.data() + l0, l1 - l0};
  }
};

/// Per edge, the unit in-face directions perpendicular to it pointing into its left and
/// right faces (model frame): how the solid continues away from the edge.
struct EdgeWings {
  Vec3 left, right;
};

/// A pair turned away stays turned away while A's points move less than `lin` (the motion
/// bound of ContactDetector) or A turns less than `rot` (|R1 - R0|_F, which bounds how far
/// any unit vector of A, or of B seen from A, turns) from the pose it was turned away at.
/// <= 0: no certificate. Each keeps the geometric tolerance in hand for rounding.
struct Cert {
  double lin = 0;  ///< mm
  double rot = 0;  ///< Frobenius norm of the change of R_BA
};

/// What an exact test found: the contact, or none and a certificate (possibly empty).
struct PairOutcome {
  std::optional<ContactPc> contact;
  Cert cert;
};

/// The model pair and the tolerances, as the tests (and the cheap rejections) read them.
struct PairTables {
  /// `origin_A` (mm, A's frame): the point A's motion is bounded about (the tree's origin).
  /// @throws cf::Error naming a parameter out of range.
  PairTables(const Polyhedron& a, const Polyhedron& b, const Params& params, const Vec3& origin_A);

  const Polyhedron* a;
  const Polyhedron* b;
  DetectionParams prm;
  double eps = 1;       ///< mm, Params::epsilon_mm
  double depth = 1;     ///< mm, deepest_contact_mm
  double in_plane = 1;  ///< mm, in_plane_tolerance_mm or epsilon
  /// mm per mm of the models' size: boundaries this close coincide in 2D (far below any
  /// feature, far above rounding).
  static constexpr double kGeoTolPerMm = 1e-9;
  /// mm^2 per mm^2: an overlap this small (relative to the size squared) is none.
  static constexpr double kAreaTolPerMm2 = 1e-12;
  /// mm per mm of the reach: a rotation rounded to float leaves |(R^T R - I) o_A| within
  /// 1e-7 of it; ten times that is allowed.
  static constexpr double kOrthAllowPerMm = 1e-5;
  double geo_tol =
      0;  ///< mm, coincidence of boundaries in 2D: far below any feature, above rounding
  double area_tol = 0;  ///< mm^2
  FlatFaces flat_a, flat_b;
  std::vector<EdgeWings> wings_a, wings_b;
  /// sin of the angular tolerance of each face (from its extent) and edge (from its length).
  std::vector<double> sin_tol_face_a, sin_tol_face_b, sin_tol_edge_a, sin_tol_edge_b;
  double sin_max_tol = 0, cos_max_tol = 1;
  Vec3 origin_A = Vec3::Zero();  ///< mm, A's frame
  double r_a = 0;                ///< mm, A's furthest vertex from origin_A
  double reach = 0;              ///< mm, bounds every coordinate of B and A's size
  /// mm: how far |(R^T R - I) o_A| may be at a pose whose certificates count (a rotation
  /// rounded to float is well within it).
  double orth_allow = 0;

  /// rad: the largest angular tolerance any pair can get.
  double max_tol() const { return prm.largest_angular_tolerance_rad(); }
  /// rad: the angular tolerance of a contact region of this extent (mm).
  double tol_for(double extent) const {
    if (prm.angular_tolerance_rad > 0) return prm.angular_tolerance_rad;
    const double t = std::atan(eps / std::max(extent, internal::kRelativeRounding * eps));
    return std::clamp(t, prm.min_angular_tolerance_rad, prm.max_angular_tolerance_rad);
  }
  bool in_band(double d) const { return d <= eps && d >= -depth; }
  /// A contact read beside its element (in-plane gap > 0: a vertex beside a face, an edge
  /// beside a face or past the end of an edge) at distance d measures two points hypot(d, gap)
  /// apart: they must be within the band too, at most epsilon apart when d >= 0 and at most
  /// deepest_contact_mm when d < 0 (docs/runtime.md, "Tests per type"). In the element
  /// (gap 0) this is in_band(d).
  bool within_band_beside(double d, double gap) const {
    const double lim = d >= 0 ? eps : depth;
    return d * d + gap * gap <= lim * lim;
  }
  /// The certificate of a distance `gap` of B's point(s), at most `reach_mm` from A's
  /// posed origin, as A sees them.
  double seen_from_a(double gap, double reach_mm) const {
    return (gap - 2 * orth_allow) / std::max(1.0, reach_mm / r_a) - geo_tol;
  }
};

/// One detect call's pose, and A's vertices posed at it (each on first use).
struct PosedA {
  explicit PosedA(const Polyhedron& a) : aw(a.num_vertices()), aw_stamp(a.num_vertices(), 0) {}
  Pose pose;
  Vec3 origin_posed = Vec3::Zero();  ///< mm, PairTables::origin_A posed, B's frame
  std::uint64_t stamp = 0;           ///< one per pose: the caches need no reset
  /// The certificates are used (kept pairs are being recorded or served): the tests that
  /// cost extra to certify do so only then.
  bool certifying = false;
  std::vector<Vec3> aw;  ///< mm, B's frame
  std::vector<std::uint64_t> aw_stamp;

  const Vec3& world(const Polyhedron& a, VertexId v) {
    const std::size_t i = v.index();
    if (aw_stamp[i] != stamp) {
      aw[i] = pose.apply(a.vertex(v).p);
      aw_stamp[i] = stamp;
    }
    return aw[i];
  }
};

/// Scratch of the tests, sized once for the model pair.
struct ExactScratch {
  explicit ExactScratch(const PairTables& t);
  std::vector<Vec2> q_pts;
  std::vector<int> q_lb;
  std::vector<double> params;
  std::vector<Vec2> clip_buf;  ///< 2 * clip_cap points
  int clip_cap = 0;
};

PairOutcome vertex_face(const PairTables& t, PosedA& p, int v, int fb);
PairOutcome face_vertex(const PairTables& t, PosedA& p, int fa, int v);
PairOutcome edge_face(const PairTables& t, PosedA& p, ExactScratch& s, int e, int fb);
PairOutcome face_edge(const PairTables& t, PosedA& p, ExactScratch& s, int fa, int e);
PairOutcome face_face(const PairTables& t, PosedA& p, ExactScratch& s, int fa, int fb);
PairOutcome edge_edge(const PairTables& t, PosedA& p, int ea, int eb);

/// The test of the pair's types (A's element kind ka, B's kb); an empty outcome for kinds
/// that form no PC. Inline: the servo loop's detection calls it for every pair that passes
/// the cheap rejections.
inline PairOutcome exact_test(const PairTables& t, PosedA& p, ExactScratch& s, ElementKind ka,
                              int ia, ElementKind kb, int ib) {
  switch (ka) {
    case ElementKind::kVertex:
      if (kb == ElementKind::kFace) return vertex_face(t, p, ia, ib);
      break;
    case ElementKind::kEdge:
      if (kb == ElementKind::kFace) return edge_face(t, p, s, ia, ib);
      if (kb == ElementKind::kEdge) return edge_edge(t, p, ia, ib);
      break;
    case ElementKind::kFace:
      if (kb == ElementKind::kFace) return face_face(t, p, s, ia, ib);
      if (kb == ElementKind::kEdge) return face_edge(t, p, s, ia, ib);
      return face_vertex(t, p, ia, ib);
  }
  return {};
}

}  // namespace cf::internal

#pragma once
// The symmetries of a model pair: rigid maps of A onto A and of B onto B. When pose X
// realises a CF of A against B, the pose g X h^-1 realises the CF whose PCs are the images
// (h of A's element, g of B's element), so the graph is a union of such orbits: the search
// needs one member of each, and every member's witness follows from one.

#include "cfgen/decide/cell_search.hpp"
#include "cfgen/verify/analysis.hpp"

#include <cf/pc.hpp>

#include <vector>

namespace cf::gen {

/// Vertices within this fraction of the larger model's size match under a symmetry: far below
/// the touch tolerance (2e-11 D by default), so an image witness verifies as the witness did.
constexpr double kSymmetryTol = 1e-13;
/// A file rounded coarser than kSymmetryTol (float32, few digits) is symmetric only to its
/// rounding: maps to within this many times its rounding (symmetrized) make it symmetric.
constexpr double kSymmetryRoundings = 16;

/// A map x -> R (x - c) + c that takes a model onto itself, as permutations of its elements.
struct Symmetry {
  Mat3 R = Mat3::Identity();  // orthogonal; det -1 for a reflection
  Vec3 c = Vec3::Zero();      // mm, model frame: the centroid of the vertices, which it fixes
  std::vector<int> vertex, edge, face;  // image of each element, by index
  const std::vector<int>& of(ElementKind k) const {
    return k == ElementKind::kVertex ? vertex : k == ElementKind::kEdge ? edge : face;
  }
};

/// Every symmetry of `m`, the identity first: the orthogonal maps about the vertices'
/// centroid that take each vertex to a vertex within `tol` (mm), each edge to an edge and
/// each face to a face with the image normal. Only the identity when the maps found are not closed
/// under composition (a model symmetric only to about `tol`). Deterministic.
std::vector<Symmetry> symmetries(const Polyhedron& m, double tol);

/// A model read from a file rounded coarser than kSymmetryTol (float32, a few digits) and
/// symmetric to within `loose_tol` (mm, a multiple of its rounding): the same model with every
/// vertex replaced by the mean of its preimages under those maps, twice, so that it is
/// symmetric to within `strict_tol` (mm) as an exact file is, and its maps are found there. `m`
/// itself when it has no more maps at loose_tol than at strict_tol, or when the mean does not
/// give them all at strict_tol. moved: mm, how far a vertex moved (0 for `m` itself).
Polyhedron symmetrized(const Polyhedron& m, double loose_tol, double strict_tol, double* moved);

/// The pairs (h of A, g of B) of like handedness (both rotations, or both reflections, whose
/// product with the pose is again a rotation), the identity pair first.
class PairSymmetries {
 public:
  /// Only the identity when `enabled` is false. tol (mm): the maps' tolerance (symmetries()).
  PairSymmetries(const Polyhedron& A, const Polyhedron& B, double tol, bool enabled);
  std::size_t size() const { return pairs_.size(); }
  std::size_t size_a() const { return a_.size(); }
  std::size_t size_b() const { return b_.size(); }
  /// The image of one PC, and of a set, under pair k.
  Pc image(const Pc& pc, std::size_t k) const;
  PcSet image(const PcSet& s, std::size_t k) const;
  /// g X h^-1: the pose that realises image(s, k) when `pose` realises s.
  Pose image(const Pose& pose, std::size_t k) const;
  /// The smallest image of s (PCs compared in order): one set per orbit.
  PcSet canonical(const PcSet& s) const;
  /// The maps of pair k: of A, and of B.
  const Symmetry& map_a(std::size_t k) const;
  const Symmetry& map_b(std::size_t k) const;
  /// How far the maps miss, at most, over every pair: the image of a vertex from the vertex
  /// it is taken to (A's and B's added), and the image of an edge's direction or a face's
  /// normal from the image element's.
  const MapError& error() const { return error_; }

 private:
  std::vector<Symmetry> a_, b_;
  std::vector<std::pair<int, int>> pairs_;  // (map of A, map of B), by map of A
  std::vector<std::size_t> a_first_;        // pairs_[a_first_[i], a_first_[i + 1]): h = a_[i]
  MapError error_;
};

/// Lexicographic order of PC sets of one size (then by size).
bool pcset_less(const PcSet& x, const PcSet& y);

}  // namespace cf::gen

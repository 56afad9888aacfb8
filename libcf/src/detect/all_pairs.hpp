#pragma once
// The reference detection, beside the culled one (as CHAI3D keeps CCollisionBrute beside
// CCollisionAABB): every element pair of the two models straight to the exact tests, with
// no trees, no cheap rejections and no kept pairs (DetectionParams::use_bvh = false). For
// checking the culling (tests/libcf/detector_test.cpp) and for comparison only.

#include "exact.hpp"

#include <cstddef>

namespace cf::internal {

/// Pushes every contact at `p.pose` into `out` (unsorted, unfinished); returns the number
/// of pairs tested.
inline std::size_t detect_all_pairs(const PairTables& t, PosedA& p, ExactScratch& s,
                                    ContactSet& out) {
  const auto count = [](const Polyhedron& m, ElementKind k) {
    return static_cast<int>(k == ElementKind::kVertex ? m.num_vertices()
                            : k == ElementKind::kEdge ? m.num_edges()
                                                      : m.num_faces());
  };
  constexpr ElementKind kKinds[] = {ElementKind::kVertex, ElementKind::kEdge, ElementKind::kFace};
  std::size_t pairs = 0;
  for (const ElementKind ka : kKinds)
    for (int ia = 0, na = count(*t.a, ka); ia < na; ++ia)
      for (const ElementKind kb : kKinds)
        for (int ib = 0, nb = count(*t.b, kb); ib < nb; ++ib) {
          ++pairs;
          PairOutcome o = exact_test(t, p, s, ka, ia, kb, ib);
          if (o.contact) out.push(*o.contact);
        }
  return pairs;
}

}  // namespace cf::internal

#include "cfgen/decide/cell_search.hpp"

#include "cfgen/decide/rotation_family.hpp"

#include <algorithm>

namespace cf::gen {
namespace {

// Rotations near R_c that meet the set's rotational conditions: where the relaxation is
// tried exactly, so that a set it cannot refute is recognised before the cells get small.
std::vector<Mat3> projections(const RotConstraints& c, const Mat3& R_c) {
  if (!c.align.empty()) return internal::align_family(c, {R_c}, 0);
  Mat3 R = R_c;
  if (!c.perp.empty() && !internal::project_perp(c, R)) return {};
  return {R};
}

}  // namespace

CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits, std::vector<CellEvidence>* evidence) {
  const CellRelaxation relaxation(a, b, pcs);
  const RotConstraints conditions = rotation_constraints(pcs, *a.model, *b.model);
  CellSearchResult out;
  out.smallest_half = whole_rotation_space().half;
  std::vector<RotationCell> stack{whole_rotation_space()};
  while (!stack.empty()) {
    const RotationCell cell = stack.back();
    stack.pop_back();
    if (++out.cells > limits.max_cells) {
      out.outcome = CellSearchResult::Outcome::kUndecided;
      return out;
    }
    out.smallest_half = std::min(out.smallest_half, cell.half);
    if (outside_rotation_ball(cell)) {
      if (evidence) evidence->push_back({cell, {}, true});
      continue;
    }
    CellRelaxation::Refutation r = relaxation.refute(cell, evidence != nullptr);
    if (r.verdict != CellRelaxation::Verdict::kOpen) {
      if (evidence) evidence->push_back({cell, std::move(r), false});
      continue;
    }
    for (const Mat3& R : projections(conditions, rotation_at(cell.centre)))
      if (relaxation.holds_at(R)) {
        out.outcome = CellSearchResult::Outcome::kRealised;
        return out;
      }
    if (cell.half < limits.resolution) {
      out.outcome = CellSearchResult::Outcome::kUndecided;
      return out;
    }
    for (const RotationCell& c : split(cell)) stack.push_back(c);
  }
  out.outcome = CellSearchResult::Outcome::kRefuted;
  return out;
}

}  // namespace cf::gen

#include "cfgen/decide/cell_search.hpp"

#include "cfgen/decide/deep_points.hpp"
#include "cfgen/decide/rotation_family.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <algorithm>
#include <cmath>

namespace cf::gen {
namespace {

struct PoseBox {
  RotationCell rot;
  Vec3 t_lo, t_hi;
};

// Rotations near R_c that meet the set's rotational conditions, where a witness is tried.
std::vector<Mat3> projections(const RotConstraints& c, const Mat3& R_c) {
  if (!c.align.empty()) return internal::align_family(c, {R_c}, 0);
  Mat3 R = R_c;
  if (!c.perp.empty() && !internal::project_perp(c, R)) return {};
  return {R};
}

// How far A's points can move over the cell: its farthest vertex from the pivot.
double reach_of(const Polyhedron& A, const Vec3& pivot) {
  double r = 0;
  for (const Vertex& v : A.vertices()) r = std::max(r, (v.p - pivot).norm());
  return r;
}

// Splits the rotation cell when rotation moves A's points more than the box's spread, else
// the box along its longest side.
void split_into(const PoseBox& c, double reach, std::vector<PoseBox>& stack) {
  const Vec3 ext = c.t_hi - c.t_lo;
  if (turn_bound(c.rot) * reach >= 0.5 * ext.norm()) {
    for (const RotationCell& r : split(c.rot)) stack.push_back({r, c.t_lo, c.t_hi});
    return;
  }
  int k = 0;
  ext.maxCoeff(&k);
  const double mid = 0.5 * (c.t_lo[k] + c.t_hi[k]);
  PoseBox low = c, high = c;
  low.t_hi[k] = mid;
  high.t_lo[k] = mid;
  stack.push_back(low);
  stack.push_back(high);
}

}  // namespace

CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits, const WitnessSearch* search,
                              std::vector<CellEvidence>* evidence) {
  const CellRelaxation relaxation(a, b, pcs, limits.touch_tol, limits.margin);
  const DeepPoints deep(a, b);
  const RotConstraints conditions = rotation_constraints(pcs, *a.model, *b.model);
  const double size = std::max((a.model->bbox_max() - a.model->bbox_min()).norm(),
                               (b.model->bbox_max() - b.model->bbox_min()).norm());
  const double reach = reach_of(*a.model, relaxation.pivot());
  CellSearchResult out;
  out.smallest_half = whole_rotation_space().half;
  std::vector<PoseBox> stack{{whole_rotation_space(), relaxation.t_lo(), relaxation.t_hi()}};
  double searched_half = HUGE_VAL;  // the rotation half-width of the last cell searched
  while (!stack.empty()) {
    PoseBox c = stack.back();
    stack.pop_back();
    if (++out.cells > limits.max_cells) return out;  // kUndecided
    out.smallest_half = std::min(out.smallest_half, c.rot.half);
    CellEvidence e{c.rot, c.t_lo, c.t_hi, {}, false, true, -1};
    if (outside_rotation_ball(c.rot)) {
      e.outside_ball = true;
      if (evidence) evidence->push_back(std::move(e));
      continue;
    }
    e.refutation = relaxation.refute(c.rot, c.t_lo, c.t_hi, evidence != nullptr);
    if (e.refutation.verdict == CellRelaxation::Verdict::kOpen) {
      const Mat3 R_c = rotation_at(c.rot.centre);
      if (const auto hit =
              deep.find({R_c, turn_bound(c.rot), relaxation.pivot(), c.t_lo, c.t_hi})) {
        e.refutation.verdict = CellRelaxation::Verdict::kDeep;
        e.deep_of_a = hit->of_a;
        e.deep_point = hit->index;
      }
    }
    if (e.refutation.verdict != CellRelaxation::Verdict::kOpen) {
      if (evidence) evidence->push_back(std::move(e));
      continue;
    }
    // A search near the centre's rotation, once a rotation cell (its first translation box)
    // is small enough that its rotations are near one another.
    if (search && c.rot.half <= limits.search_below && c.rot.half < searched_half) {
      const Witness w = search->find(pcs, projections(conditions, rotation_at(c.rot.centre)), true);
      if (w.found) {
        out.outcome = CellSearchResult::Outcome::kWitness;
        out.witness = w.pose;
        return out;
      }
    }
    searched_half = c.rot.half;
    if (c.rot.half < limits.resolution &&
        (c.t_hi - c.t_lo).maxCoeff() < 2 * limits.resolution * size)
      return out;  // kUndecided
    split_into(c, reach, stack);
  }
  out.outcome = CellSearchResult::Outcome::kRefuted;
  return out;
}

}  // namespace cf::gen

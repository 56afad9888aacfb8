#include "cfgen/decide/cell_search.hpp"

#include "cfgen/decide/deep_points.hpp"
#include "cfgen/decide/rotation_family.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace cf::gen {
namespace {

// A cell of poses: rotations (a cube of rotation space, or an arc of an f-f's circle) and
// the translations of A's pivot.
struct PoseBox {
  RotationCell rot;
  Arc arc;
  Vec3 t_lo, t_hi;
};

// The rotations of an f-f's circle, R0 Rot(n_A, theta) with R0 n_A = -n_B.
struct Circle {
  bool on = false;
  Vec3 axis = Vec3::Zero();  // A's face normal
  Mat3 R0 = Mat3::Identity();
  Mat3 at(double theta) const { return R0 * Eigen::AngleAxisd(theta, axis).toRotationMatrix(); }
};

Circle circle_of(const PcSet& pcs, const Polyhedron& A, const Polyhedron& B) {
  Circle c;
  for (const Pc& pc : pcs)
    if (pc.type == PcType::kFF) {
      c.on = true;
      c.axis = A.face(FaceId(pc.a)).normal;
      c.R0 = Eigen::Quaterniond::FromTwoVectors(c.axis, -B.face(FaceId(pc.b)).normal)
                 .toRotationMatrix();
      break;
    }
  return c;
}

// A witness meets the f-f's alignment to 10 kRotTol: its rotation is within that angle of
// the circle (a turn by a moves a unit vector by at most a); twice it for rounding.
constexpr double kOffCircle = 20 * kRotTol;

Mat3 centre_of(const PoseBox& c, const Circle& circle) {
  return circle.on ? circle.at(c.arc.centre) : rotation_at(c.rot.centre);
}

TurnBound turn_of(const PoseBox& c, const Circle& circle) {
  if (circle.on) return {kOffCircle, c.arc.half, circle.axis};
  return {turn_bound(c.rot)};
}

double half_of(const PoseBox& c, const Circle& circle) {
  return circle.on ? c.arc.half : c.rot.half;
}

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

// Splits the rotations when they move A's points more than the box's spread, else the box
// along its longest side.
void split_into(const PoseBox& c, const Circle& circle, double reach, std::vector<PoseBox>& stack) {
  const Vec3 ext = c.t_hi - c.t_lo;
  if (turn_of(c, circle).unit() * reach >= 0.5 * ext.norm()) {
    if (circle.on) {
      const double h = 0.5 * c.arc.half;
      for (double side : {-1.0, 1.0})
        stack.push_back({c.rot, {c.arc.centre + side * h, h}, c.t_lo, c.t_hi});
      return;
    }
    for (const RotationCell& r : split(c.rot)) stack.push_back({r, c.arc, c.t_lo, c.t_hi});
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
  const CellRelaxation relaxation(a, b, pcs, limits.touch_tol, limits.margin, limits.local_slack);
  const DeepPoints deep(a, b);
  const RotConstraints conditions = rotation_constraints(pcs, *a.model, *b.model);
  const double size = std::max((a.model->bbox_max() - a.model->bbox_min()).norm(),
                               (b.model->bbox_max() - b.model->bbox_min()).norm());
  const double reach = reach_of(*a.model, relaxation.pivot());
  const Circle circle = circle_of(pcs, *a.model, *b.model);
  CellSearchResult out;
  out.smallest_half = whole_rotation_space().half;
  std::vector<PoseBox> stack{
      {whole_rotation_space(), {0.0, M_PI}, relaxation.t_lo(), relaxation.t_hi()}};
  double searched_half = HUGE_VAL;  // the rotation half-width of the last cell searched
  while (!stack.empty()) {
    PoseBox c = stack.back();
    stack.pop_back();
    if (++out.cells > limits.max_cells) return out;  // kUndecided
    const double half = half_of(c, circle);
    out.smallest_half = std::min(out.smallest_half, half);
    const Mat3 R_c = centre_of(c, circle);
    const TurnBound turn = turn_of(c, circle);
    CellEvidence e{c.rot, circle.on ? c.arc : Arc{}, R_c, turn, c.t_lo, c.t_hi, {}, false, true,
                   -1};
    if (!circle.on && outside_rotation_ball(c.rot)) {
      e.outside_ball = true;
      if (evidence) evidence->push_back(std::move(e));
      continue;
    }
    e.refutation = relaxation.refute(R_c, turn, c.t_lo, c.t_hi, evidence != nullptr);
    if (e.refutation.verdict == CellRelaxation::Verdict::kOpen) {
      if (const auto hit = deep.find({R_c, turn.unit(), relaxation.pivot(), c.t_lo, c.t_hi})) {
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
    if (search && half <= limits.search_below && half < searched_half) {
      const Witness w = search->find(pcs, projections(conditions, R_c), true);
      if (w.found) {
        out.outcome = CellSearchResult::Outcome::kWitness;
        out.witness = w;
        return out;
      }
    }
    searched_half = half;
    if (half < limits.resolution && (c.t_hi - c.t_lo).maxCoeff() < 2 * limits.resolution * size)
      return out;  // kUndecided
    split_into(c, circle, reach, stack);
  }
  out.outcome = CellSearchResult::Outcome::kRefuted;
  return out;
}

}  // namespace cf::gen

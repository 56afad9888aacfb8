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
  int parent = -1;  // its parent's index in the tree, when one is kept
};

// The rotations of an f-f's circle, R0 Rot(n_A, theta) with R0 n_A = -n_B.
struct Circle {
  bool on = false;
  int pc = -1;               // the f-f PC's index in the set
  Vec3 axis = Vec3::Zero();  // A's face normal
  Mat3 R0 = Mat3::Identity();
  Mat3 at(double theta) const { return R0 * Eigen::AngleAxisd(theta, axis).toRotationMatrix(); }
};

Circle circle_of(const PcSet& pcs, const Polyhedron& A, const Polyhedron& B) {
  Circle c;
  for (int k = 0; k < pcs.size(); ++k)
    if (const Pc& pc = pcs[k]; pc.type == PcType::kFF) {
      c.on = true;
      c.pc = k;
      c.axis = A.face(FaceId(pc.a)).normal;
      c.R0 = Eigen::Quaterniond::FromTwoVectors(c.axis, -B.face(FaceId(pc.b)).normal)
                 .toRotationMatrix();
      break;
    }
  return c;
}

Mat3 centre_of(const PoseBox& c, const Circle& circle) {
  return circle.on ? circle.at(c.arc.centre) : rotation_at(c.rot.centre);
}

TurnBound turn_of(const PoseBox& c, const Circle& circle, double rot_tol) {
  if (circle.on) return {off_circle(rot_tol), c.arc.half, circle.axis};
  return {turn_bound(c.rot)};
}

double half_of(const PoseBox& c, const Circle& circle) {
  return circle.on ? c.arc.half : c.rot.half;
}

// How far A's points can move over the cell: its farthest vertex from the pivot.
double reach_of(const Polyhedron& A, const Vec3& pivot) {
  double r = 0;
  for (const Vertex& v : A.vertices()) r = std::max(r, (v.p - pivot).norm());
  return r;
}

// Splits the rotations when the local margin is unsettled over them (CellRelaxation's
// Refutation::unsettled: the slack decides there, and the box's halves would each be split
// over their rotations again) or
// they move A's points more than the box's spread, else the box along its longest side; the
// children's parent is `node`. The kind of split made.
CellNode::Kind split_into(const PoseBox& c, const Circle& circle, const TurnBound& turn,
                          double reach, int node, std::vector<PoseBox>& stack, int& axis,
                          double& at, bool unsettled) {
  const Vec3 ext = c.t_hi - c.t_lo;
  if (unsettled || turn.unit() * reach >= 0.5 * ext.norm()) {
    if (circle.on) {
      const double h = 0.5 * c.arc.half;
      for (double side : {-1.0, 1.0})
        stack.push_back({c.rot, {c.arc.centre + side * h, h}, c.t_lo, c.t_hi, node});
    } else {
      for (const RotationCell& r : split(c.rot)) stack.push_back({r, c.arc, c.t_lo, c.t_hi, node});
    }
    return CellNode::Kind::kSplitRotation;
  }
  ext.maxCoeff(&axis);
  at = 0.5 * (c.t_lo[axis] + c.t_hi[axis]);
  PoseBox low = c, high = c;
  low.t_hi[axis] = at;
  high.t_lo[axis] = at;
  low.parent = high.parent = node;
  stack.push_back(low);
  stack.push_back(high);
  return CellNode::Kind::kSplitTranslation;
}

// Records a narrowing in the tree: `node` (the box given) becomes kNarrow, with the slabs cut
// off as leaves and the narrowed box as a new node, whose index is returned.
int record_narrowing(CellTree& tree, int node, const Vec3& t_lo, const Vec3& t_hi,
                     std::vector<CellRelaxation::Slab>&& slabs) {
  const CellNode parent = tree.nodes[static_cast<std::size_t>(node)];
  tree.nodes[static_cast<std::size_t>(node)].kind = CellNode::Kind::kNarrow;
  for (CellRelaxation::Slab& slab : slabs) {
    CellNode leaf = parent;
    leaf.parent = node;
    leaf.t_lo = slab.lo;
    leaf.t_hi = slab.hi;
    leaf.kind = CellNode::Kind::kRefuted;  // narrow() cuts off proven slabs only
    leaf.refutation = {};
    leaf.refutation.verdict = CellRelaxation::Verdict::kProgram;
    leaf.refutation.certificates = std::move(slab.proofs);
    tree.nodes.push_back(std::move(leaf));
  }
  CellNode inner = parent;
  inner.parent = node;
  inner.t_lo = t_lo;
  inner.t_hi = t_hi;
  tree.nodes.push_back(std::move(inner));
  return static_cast<int>(tree.nodes.size()) - 1;
}

}  // namespace

CellSearchLimits decision_limits(const WitnessSearch& search, std::size_t max_cells,
                                 double resolution) {
  CellSearchLimits limits;
  limits.max_cells = max_cells;
  limits.resolution = resolution;
  limits.scale = search.scale();
  limits.touch_tol = search.params().touch_tol;
  limits.margin = thin_params(search.params()).min_margin;
  limits.local_slack = search.verified_local_slack();
  limits.rot_tol = max_condition_tol(search.a(), search.b());
  return limits;
}

CellSearchLimits loosened(CellSearchLimits limits, const MapError& e) {
  if (e.length == 0 && e.angle == 0) return limits;
  limits.touch_tol += e.length;
  limits.margin = std::max(0.0, limits.margin - e.length);
  limits.rot_tol += e.angle;
  // An e-e's normal N / |N| turns by at most 2 angle / |N|, |N| >= local_slack at a witness.
  if (limits.local_slack > 0)
    limits.local_slack =
        std::max(0.0, limits.local_slack - 2 * e.angle * (1 + 1 / limits.local_slack));
  limits.deep_extra = std::max(limits.deep_extra, e.length);
  return limits;
}

CellSearchResult search_cells(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                              const CellSearchLimits& limits, const WitnessSearch* search,
                              CellTree* tree) {
  const CellRelaxation relaxation(a, b, pcs, limits.touch_tol, limits.margin, limits.local_slack,
                                  limits.rot_tol);
  const DeepPoints deep(a, b);
  const RotConstraints conditions = rotation_constraints(pcs, a, b);
  const double size = limits.scale > 0
                          ? limits.scale
                          : std::max((a.model->bbox_max() - a.model->bbox_min()).norm(),
                                     (b.model->bbox_max() - b.model->bbox_min()).norm());
  const double reach = reach_of(*a.model, relaxation.pivot());
  const Circle circle = circle_of(pcs, *a.model, *b.model);
  if (tree) *tree = {relaxation.pivot(), circle.pc, circle.R0, circle.axis, {}};
  CellSearchResult out;
  out.smallest_half = whole_rotation_space().half;
  std::vector<PoseBox> stack{
      {whole_rotation_space(), {0.0, M_PI}, relaxation.t_lo(), relaxation.t_hi(), -1}};
  double searched_half = HUGE_VAL;  // the rotation half-width of the last cell searched
  while (!stack.empty()) {
    PoseBox c = stack.back();
    stack.pop_back();
    // A cube outside the ball of rotations costs no program: it is not counted.
    const bool outside = !circle.on && outside_rotation_ball(c.rot);
    if (!outside && ++out.cells > limits.max_cells) return out;  // kUndecided
    const double half = half_of(c, circle);
    out.smallest_half = std::min(out.smallest_half, half);
    const Mat3 R_c = centre_of(c, circle);
    const TurnBound turn = turn_of(c, circle, limits.rot_tol);
    int node = -1;
    if (tree) {
      CellNode n;
      n.parent = c.parent;
      n.cell = c.rot;
      n.arc = circle.on ? c.arc : Arc{};
      n.R_c = R_c;
      n.turn = turn;
      n.t_lo = c.t_lo;
      n.t_hi = c.t_hi;
      tree->nodes.push_back(std::move(n));
      node = static_cast<int>(tree->nodes.size()) - 1;
    }
    auto leaf = [&]() -> CellNode& { return tree->nodes[static_cast<std::size_t>(node)]; };
    if (outside) {
      if (tree) leaf().kind = CellNode::Kind::kOutsideBall;
      continue;
    }
    // A cell whose local margin is unsettled is split over its rotations whatever its box
    // (above the resolution): narrowing the box would cost twelve programs and change nothing.
    CellRelaxation::Refutation r = relaxation.refute(R_c, turn, c.t_lo, c.t_hi, tree != nullptr,
                                                     4096, half >= limits.resolution);
    if (tree && !r.slabs.empty())
      node = record_narrowing(*tree, node, c.t_lo, c.t_hi, std::move(r.slabs));
    if (r.verdict == CellRelaxation::Verdict::kOpen) {
      if (const auto hit = deep.find(
              {R_c, turn.unit(), relaxation.pivot(), c.t_lo, c.t_hi, limits.deep_extra})) {
        r.verdict = CellRelaxation::Verdict::kDeep;
        if (tree) {
          leaf().deep_of_a = hit->of_a;
          leaf().deep_point = hit->index;
        }
      }
    }
    if (r.verdict != CellRelaxation::Verdict::kOpen) {
      if (tree) leaf().refutation = std::move(r);
      continue;
    }
    // A search near the centre's rotation, once a rotation cell (its first translation box)
    // is small enough that its rotations are near one another.
    if (search && half <= limits.search_below && half < searched_half) {
      const Witness w = search->find(pcs, internal::project_onto(conditions, R_c), true);
      if (w.found) {
        out.outcome = CellSearchResult::Outcome::kWitness;
        out.witness = w;
        return out;
      }
    }
    searched_half = half;
    if (half < limits.resolution && (c.t_hi - c.t_lo).maxCoeff() < 2 * limits.resolution * size)
      return out;  // kUndecided
    int axis = -1;
    double at = 0;
    const CellNode::Kind kind =
        split_into(c, circle, turn, reach, node, stack, axis, at, r.unsettled);
    if (tree) {
      leaf().kind = kind;
      leaf().axis = axis;
      leaf().at = at;
    }
  }
  out.outcome = CellSearchResult::Outcome::kRefuted;
  return out;
}

}  // namespace cf::gen

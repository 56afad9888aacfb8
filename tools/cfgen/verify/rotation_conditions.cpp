#include "cfgen/verify/rotation_conditions.hpp"

#include <algorithm>

namespace cf::gen {
namespace {

// rad: how far the direction of element (k, i) of `m` may be from its file's, over 2.
double tilt(const ModelInfo& m, ElementKind k, int i) {
  const auto& ext = m.extent[static_cast<int>(k)];
  if (m.precision_mm <= 0 || static_cast<std::size_t>(i) >= ext.size()) return 0;
  return m.precision_mm / std::max(ext[i], 1e-300);
}

// rad: the largest tilt of an edge or a face of `m`.
double max_tilt(const ModelInfo& m) {
  double t = 0;
  for (ElementKind k : {ElementKind::kEdge, ElementKind::kFace})
    for (std::size_t i = 0; i < m.extent[static_cast<int>(k)].size(); ++i)
      t = std::max(t, tilt(m, k, static_cast<int>(i)));
  return t;
}

}  // namespace

double RotConstraints::max_tol() const {
  double t = kRotAccepted;
  for (double x : align_tol) t = std::max(t, x);
  for (double x : perp_tol) t = std::max(t, x);
  return t;
}

double condition_tol(const ModelInfo& a, ElementKind ka, int ia, const ModelInfo& b, ElementKind kb,
                     int ib) {
  return std::max(kRotAccepted, kRotPerPrecision * (tilt(a, ka, ia) + tilt(b, kb, ib)));
}

double max_condition_tol(const ModelInfo& a, const ModelInfo& b) {
  return std::max(kRotAccepted, kRotPerPrecision * (max_tilt(a) + max_tilt(b)));
}

double direction_tol(const ModelInfo& a, const ModelInfo& b) {
  return std::max(1e-9, max_condition_tol(a, b) - kRotAccepted);
}

double tilt_allowance(const ModelInfo& a, const ModelInfo& b, const Pc& pc) {
  constexpr ElementKind kE = ElementKind::kEdge, kF = ElementKind::kFace;
  switch (pc.type) {
    case PcType::kFF:
      return (condition_tol(a, kF, pc.a, b, kF, pc.b) - kRotAccepted) * 2 *
             a.spheres[static_cast<int>(kF)][pc.a].second;
    case PcType::kEF:
      return (condition_tol(a, kE, pc.a, b, kF, pc.b) - kRotAccepted) * a.extent[1][pc.a];
    case PcType::kFE:
      return (condition_tol(a, kF, pc.a, b, kE, pc.b) - kRotAccepted) * b.extent[1][pc.b];
    default:
      return 0;
  }
}

RotConstraints rotation_constraints(const PcSet& pcs, const ModelInfo& a, const ModelInfo& b) {
  const Polyhedron& A = *a.model;
  const Polyhedron& B = *b.model;
  constexpr ElementKind kE = ElementKind::kEdge, kF = ElementKind::kFace;
  RotConstraints c;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kFF:
        c.align.push_back({A.faces()[pc.a].normal, -B.faces()[pc.b].normal});
        c.align_tol.push_back(condition_tol(a, kF, pc.a, b, kF, pc.b));
        break;
      case PcType::kEF:
        c.perp.push_back({A.edges()[pc.a].dir, B.faces()[pc.b].normal});
        c.perp_tol.push_back(condition_tol(a, kE, pc.a, b, kF, pc.b));
        break;
      case PcType::kFE:
        c.perp.push_back({A.faces()[pc.a].normal, B.edges()[pc.b].dir});
        c.perp_tol.push_back(condition_tol(a, kF, pc.a, b, kE, pc.b));
        break;
      default:
        break;
    }
  }
  return c;
}

}  // namespace cf::gen

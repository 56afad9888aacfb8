#include "cfgen/verify/rotation_conditions.hpp"

namespace cf::gen {

RotConstraints rotation_constraints(const PcSet& pcs, const Polyhedron& A, const Polyhedron& B) {
  RotConstraints c;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kFF:
        c.align.push_back({A.faces()[pc.a].normal, -B.faces()[pc.b].normal});
        break;
      case PcType::kEF:
        c.perp.push_back({A.edges()[pc.a].dir, B.faces()[pc.b].normal});
        break;
      case PcType::kFE:
        c.perp.push_back({A.faces()[pc.a].normal, B.edges()[pc.b].dir});
        break;
      default:
        break;
    }
  }
  return c;
}

}  // namespace cf::gen

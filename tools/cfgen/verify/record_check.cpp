#include "cfgen/verify/record_check.hpp"

#include <cf/types.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <utility>

namespace cf::gen {

namespace {

std::string shortest(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace

std::string check_record(const Verifier& v, const CfRecord& r) {
  // Bounding spheres apart: no PC can touch. Checked before the distances, which a witness
  // 1e308 mm away would overflow.
  const auto& [ca, ra] = v.a().bound;
  const auto& [cb, rb] = v.b().bound;
  const double gap = (r.witness.apply(ca) - cb).stableNorm() - ra - rb;
  if (!(gap <= v.params().touch_tol))
    return "witness puts A " + shortest(gap) + " mm beyond touching B";
  std::string why;
  if (v.verify(r.pcs, r.witness, &why) < 0) return "witness refused by verify: " + why;
  CfRecord at;
  v.freedoms(r.pcs, r.witness, at);
  auto differs = [](const char* field, int stored, int computed) {
    return std::string(field) + " = " + std::to_string(stored) + ", but " +
           std::to_string(computed) + " at the witness";
  };
  if (r.dof >= 0 && r.dof != at.dof) return differs("dof", r.dof, at.dof);
  if (r.translation_dof >= 0 && r.translation_dof != at.translation_dof)
    return differs("translation_dof", r.translation_dof, at.translation_dof);
  // pure_rotation is stored with dof (the reader leaves it false when dof is absent).
  if (r.dof >= 0 && r.pure_rotation != at.pure_rotation)
    return differs("pure_rotation", r.pure_rotation, at.pure_rotation);
  return "";
}

SearchParams recorded_params(const CfGraph& g, SearchParams p) {
  const auto meta = nlohmann::json::parse(g.metadata_json());
  const auto it = meta.find("parameters");
  if (it == meta.end() || !it->is_object()) return p;
  const std::pair<const char*, double*> members[] = {{"touch_tol_mm", &p.touch_tol},
                                                     {"min_clearance_mm", &p.min_clearance},
                                                     {"good_clearance_mm", &p.good_clearance},
                                                     {"min_margin_mm", &p.min_margin},
                                                     {"angle_margin_rad", &p.angle_margin}};
  for (const auto& [name, value] : members) {
    const auto m = it->find(name);
    if (m == it->end()) continue;
    if (!m->is_number() || !(m->get<double>() > 0) || !std::isfinite(m->get<double>()))
      throw Error("reading the generator's parameters: /parameters/" + std::string(name) + " = " +
                  m->dump() + " is not a positive finite number");
    *value = m->get<double>();
  }
  return p;
}

double recorded_precision(const CfGraph& g, const char* model) {
  const auto meta = nlohmann::json::parse(g.metadata_json());
  const auto it = meta.find("parameters");
  if (it == meta.end() || !it->is_object()) return 0;
  const auto p = it->find("precision_mm");
  if (p == it->end() || !p->is_object() || !p->contains(model)) return 0;
  const auto& m = (*p)[model];
  if (!m.is_number() || !(m.get<double>() >= 0) || !std::isfinite(m.get<double>()))
    throw Error("reading the generator's parameters: /parameters/precision_mm/" +
                std::string(model) + " = " + m.dump() + " is not a finite number >= 0");
  return m.get<double>();
}

namespace {

SearchParams check_params(const CfGraph& g, const SearchParams& defaults) {
  SearchParams p = recorded_params(g, defaults);
  // verify measures the pairs nearer than good_clearance to report a witness's clearance;
  // its verdict depends only on those nearer than min_clearance, all a check needs.
  p.good_clearance = p.min_clearance;
  return p;
}

}  // namespace

RecordCheck::RecordCheck(const CfGraph& g, const SearchParams& defaults)
    : a_(analyse_model(g.model_a(), recorded_precision(g, "A"))),
      b_(analyse_model(g.model_b(), recorded_precision(g, "B"))),
      verifier_(a_, b_, check_params(g, defaults)) {}

std::string RecordCheck::check(const CfRecord& r) const { return check_record(verifier_, r); }

}  // namespace cf::gen

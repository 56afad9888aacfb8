#include "replay_run.hpp"

namespace cf::replay {

Row make_row(const HapticResult& r) {
  Row row;
  row.t = r.t_s;
  row.cf = r.cf.valid() ? r.cf.value() : -1;
  if (!r.pcs.empty()) {
    row.pcs = to_string(r.pcs);
  } else if (r.force != nullptr) {
    // No CF fits: list the contacts that were rendered conservatively.
    for (int k = 0; k < r.force->num_pcs; ++k)
      row.pcs += (k ? ";" : "") + to_string(r.force->pcs[k].pc);
  }
  row.motion = to_string(r.motion);
  row.F_W = r.F_W;
  row.M_W = r.M_W;
  row.F_A = r.F_A;
  row.M_A = r.M_A;
  row.status = to_string(r.status);
  row.X_WP = r.X_WP;
  row.Fc_W = r.F_contact_W;
  row.Mc_W = r.M_contact_W;
  if (r.force != nullptr) {
    for (int k = 0; k < r.force->num_pcs; ++k)
      row.regimes += (k ? ";" : "") + std::string(to_string(r.force->pcs[k].regime));
    // Approaching contacts (eq. (1) only) follow, named, as they are not among the pcs.
    for (int k = r.force->num_pcs; k < r.force->num_pcs + r.force->num_approaching; ++k)
      row.regimes += (k ? ";" : "") + std::string("approaching:") + to_string(r.force->pcs[k].pc);
    row.discontinuities = discontinuities_string(r.force->discontinuities);
  }
  return row;
}

std::vector<Row> run(const CfGraph& graph, const std::vector<Sample>& samples, const Params& params,
                     const std::function<void(const Sample&, const HapticResult&)>& each) {
  HapticRenderer renderer(graph, params);
  std::vector<Row> rows;
  rows.reserve(samples.size());
  for (const Sample& s : samples) {
    const HapticResult& r = renderer.step(s.pose, s.t);
    if (each) each(s, r);
    rows.push_back(make_row(r));
  }
  return rows;
}

}  // namespace cf::replay

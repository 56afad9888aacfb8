// Interim identification for the renderer on top of ContactDetector: prefer the previous CF,
// then the best non-dominated contact per contact plane, then a graph neighbour of the
// previous CF (SPEC section 6's order, simplified). To be replaced by CfIdentifier.

#include "renderer_ident.hpp"

#include <limits>

namespace cf::detail {

namespace {
DetectionParams detection_params(const Params& p) {
  DetectionParams d;
  d.epsilon = p.epsilon_mm;
  return d;
}
}  // namespace

Identification::Identification(const CfGraph& graph, const Params& params)
    : graph_(&graph),
      detector_(graph.model_a(), graph.model_b(), detection_params(params)),
      contacts_(std::make_unique<ContactSet>()) {}

void Identification::reset() { prev_ = CfId(); }

bool Identification::all_detected(CfId id, double* misfit) {
  const PcSet& pcs = graph_->cf(id).pcs;
  double sum = 0;
  for (int i = 0; i < pcs.size(); ++i) {
    bool found = false;
    for (const ContactPc& c : *contacts_) {
      if (c.pc == pcs[i]) {
        chosen_[static_cast<std::size_t>(i)] = c;
        sum += c.misfit;
        found = true;
        break;
      }
    }
    if (!found) return false;
  }
  if (misfit != nullptr) *misfit = sum;
  return true;
}

IdentView Identification::step(const Pose& pose) {
  detector_.detect(pose, *contacts_);
  IdentView v;
  v.detected = contacts_->begin();
  v.n_detected = contacts_->size();
  if (contacts_->empty()) {
    prev_ = CfId();
    v.status = "no_contact";
    return v;
  }
  auto choose = [&](CfId id, const char* why) {
    all_detected(id, nullptr);  // fills chosen_
    v.cf = id;
    v.cf_pcs = chosen_.data();
    v.n_cf = graph_->cf(id).pcs.size();
    v.status = why;
    prev_ = id;
    return v;
  };
  if (prev_.valid()) {
    // The previous CF when its PCs are all still detected, unless a graph neighbour with
    // more PCs is (a gained PC); otherwise the best-fitting detected neighbour.
    CfId best_id;
    int best_size = 0;
    double best_misfit = std::numeric_limits<double>::infinity();
    double mf = 0;
    if (all_detected(prev_, &mf)) {
      best_id = prev_;
      best_size = graph_->cf(prev_).pcs.size();
      best_misfit = -1;  // ties keep the previous CF
    }
    for (const Transition& tr : graph_->out_transitions(prev_)) {
      const int size = graph_->cf(tr.to).pcs.size();
      if (size < best_size) continue;
      if (all_detected(tr.to, &mf) && (size > best_size || mf < best_misfit)) {
        best_size = size;
        best_misfit = mf;
        best_id = tr.to;
      }
    }
    if (best_id.valid()) return choose(best_id, best_id == prev_ ? "previous" : "neighbour");
  }
  // Best fit: the least-misfit non-dominated contact of each contact plane.
  std::array<int, 8> best;
  best.fill(-1);
  bool too_many = contacts_->num_planes() > PcSet::kMaxPcs;
  for (int i = 0; i < contacts_->size() && !too_many; ++i) {
    const ContactPc& c = (*contacts_)[i];
    if (c.dominated || c.plane < 0) continue;
    if (c.plane >= static_cast<int>(best.size())) {
      too_many = true;
      break;
    }
    int& b = best[static_cast<std::size_t>(c.plane)];
    if (b < 0 || c.misfit < (*contacts_)[b].misfit) b = i;
  }
  if (!too_many) {
    PcSet set;
    for (int b : best)
      if (b >= 0) set.insert((*contacts_)[b].pc);
    if (!set.empty()) {
      if (auto id = graph_->find(set)) return choose(*id, "best_fit");
    }
  }
  prev_ = CfId();
  v.status = "no_fitting_cf";
  return v;
}

}  // namespace cf::detail

// The servo loop: detection, identification, prior motion, force (SPEC section 6).

#include <cf/renderer.hpp>

#include <algorithm>
#include <array>

namespace cf {

const char* to_string(RenderStatus status) {
  switch (status) {
    case RenderStatus::kNoContact: return "no_contact";
    case RenderStatus::kOk: return "ok";
    case RenderStatus::kNoFittingCf: return "no_fitting_cf";
    case RenderStatus::kUnlistedTransition: return "unlisted_transition";
  }
  return "ok";
}

struct HapticRenderer::Impl {
  Impl(const CfGraph& g, const Params& p)
      : graph(&g),
        params(p),
        force(g.model_a(), g.model_b(), p),
        ident(g, p) {}

  const CfGraph* graph;
  Params params;
  ForceModel force;
  CfIdentifier ident;
  CfId prev_cf;
  PcSet prev_pcs;
  std::array<ContactPc, PcSet::kMaxPcs> ordered{};
  HapticResult result;
};

HapticRenderer::HapticRenderer(const CfGraph& graph, const Params& params)
    : impl_(std::make_unique<Impl>(graph, params)) {}
HapticRenderer::~HapticRenderer() = default;
HapticRenderer::HapticRenderer(HapticRenderer&&) noexcept = default;
HapticRenderer& HapticRenderer::operator=(HapticRenderer&&) noexcept = default;

const HapticResult& HapticRenderer::result() const { return impl_->result; }
const CfGraph& HapticRenderer::graph() const { return *impl_->graph; }
const Params& HapticRenderer::params() const { return impl_->params; }

void HapticRenderer::reset() {
  impl_->force.reset();
  impl_->ident.reset();
  impl_->prev_cf = CfId();
  impl_->prev_pcs = PcSet();
  impl_->result = HapticResult();
}

const HapticResult& HapticRenderer::step(const Pose& pose, double t_s) {
  return step_identified(pose, t_s, impl_->ident.step(pose));
}

const HapticResult& HapticRenderer::step_identified(const Pose& pose, double t_s, const Identification& id) {
  const CfId cf = id.cf;
  const ContactPc* cf_pcs = id.cf_pcs.data();
  const int n_cf = id.has_cf() ? id.num_cf_pcs : 0;
  const ContactPc* detected = id.contacts.begin();
  const int n_detected = id.contacts.size();
  const char* identification = to_string(id.status);
  const ContactPc* approaching = id.approaching.data();
  const int n_approaching = id.has_cf() ? id.num_approaching : 0;
  Impl& m = *impl_;
  HapticResult& r = m.result;
  r.t_s = t_s;
  r.identification = identification != nullptr ? identification : "";
  r.num_detected = n_detected;
  r.pcs = PcSet();
  r.cf = CfId();

  const ForceResult* fr = nullptr;
  if (cf.valid() && n_cf > 0) {
    // Canonical order, so that PriorMotion::gained indexes the rendered array.
    const int n = std::min(n_cf, PcSet::kMaxPcs);
    for (int i = 0; i < n; ++i) m.ordered[static_cast<std::size_t>(i)] = cf_pcs[i];
    std::sort(m.ordered.begin(), m.ordered.begin() + n,
              [](const ContactPc& a, const ContactPc& b) { return a.pc < b.pc; });
    PcSet cur;
    for (int i = 0; i < n; ++i) cur.insert(m.ordered[static_cast<std::size_t>(i)].pc);
    const PriorMotion pm = classify_prior_motion(m.prev_pcs, cur, m.graph, m.prev_cf, cf);
    r.cf = cf;
    r.pcs = cur;
    if (pm.transition_in_graph) {
      r.status = RenderStatus::kOk;
      fr = &m.force.step(pose, t_s, m.ordered.data(), n, pm, false, approaching, n_approaching);
    } else {
      r.status = RenderStatus::kUnlistedTransition;
      const bool have_detected = n_detected > 0 && detected != nullptr;
      fr = &m.force.step(pose, t_s, have_detected ? detected : m.ordered.data(), have_detected ? n_detected : n, pm,
                         true);
    }
    m.prev_cf = cf;
    m.prev_pcs = cur;
  } else if (n_detected > 0 && detected != nullptr) {
    r.status = RenderStatus::kNoFittingCf;
    fr = &m.force.step(pose, t_s, detected, n_detected, PriorMotion(), true);
    // The previous CF is kept, as CfIdentifier keeps preferring it: coming back to it is
    // MT2, moving on to a neighbour MT3-MT5.
  } else {
    r.status = RenderStatus::kNoContact;
    fr = &m.force.step(pose, t_s, nullptr, 0, PriorMotion(), false);
    m.prev_cf = CfId();
    m.prev_pcs = PcSet();
  }
  r.motion = fr->motion;
  r.F_W = fr->F_W;
  r.M_W = fr->M_W;
  r.F_A = fr->F_A;
  r.M_A = fr->M_A;
  r.force = fr;
  return r;
}

}  // namespace cf

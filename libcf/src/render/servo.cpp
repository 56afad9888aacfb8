// The servo tick as stages over an immutable model and a per-thread state (docs/spec.md,
// section 6), and the two objects that hold a model and a state: HapticRenderer and
// CfIdentifier.

#include <cf/identifier.hpp>
#include <cf/renderer.hpp>
#include <cf/servo.hpp>

#include "servo_impl.hpp"

#include "../force/force_step.hpp"

#include "../check.hpp"

#include <algorithm>
#include <array>
#include <optional>

namespace cf {

const char* to_string(RenderStatus status) {
  switch (status) {
    case RenderStatus::kNoContact:
      return "no_contact";
    case RenderStatus::kOk:
      return "ok";
    case RenderStatus::kNoFittingCf:
      return "no_fitting_cf";
    case RenderStatus::kUnlistedTransition:
      return "unlisted_transition";
  }
  return "ok";
}

// ---- CfModel, CfState ----

CfModel::Impl::Impl(const CfGraph& g, const Params& p)
    : graph(&g),
      params(p),
      detect(internal::make_detect_model(g.model_a(), g.model_b(), p)),
      proxy(g.model_a(), g.model_b(), p),
      force(g.model_a(), g.model_b(), p) {
  validate(p);
}

CfModel::CfModel(const CfGraph& graph, const Params& params)
    : impl_(std::make_unique<const Impl>(graph, params)) {}
CfModel::~CfModel() = default;
CfModel::CfModel(CfModel&&) noexcept = default;
CfModel& CfModel::operator=(CfModel&&) noexcept = default;
const CfGraph& CfModel::graph() const { return *impl_->graph; }
const Params& CfModel::params() const { return impl_->params; }
const Polyhedron& CfModel::model_a() const { return impl_->graph->model_a(); }
const Polyhedron& CfModel::model_b() const { return impl_->graph->model_b(); }

CfState::Impl::Impl(const CfModel::Impl& m)
    : model(&m),
      detect(internal::make_detect_state(*m.detect)),
      identify(internal::make_identify_scratch()) {
  detected.out = &id.contacts;
  internal::init_proxy_state(m.proxy, proxy);
}

CfState::CfState(const CfModel& model)
    : impl_(std::make_unique<Impl>(internal::Access::get(model))) {}
CfState::~CfState() = default;
CfState::CfState(CfState&&) noexcept = default;
CfState& CfState::operator=(CfState&&) noexcept = default;

void CfState::reset() {
  impl_->force = ForceState();
  impl_->proxy.has_prev = false;
  impl_->proxy.num_sliding = 0;
  impl_->proxy.num_warm = 0;
  impl_->previous = CfId();
  impl_->result = HapticResult();
}
CfId CfState::previous() const { return impl_->previous; }
const ContactSet& CfState::contacts() const { return impl_->id.contacts; }
const Identification& CfState::identification() const { return impl_->id; }
const HapticResult& CfState::result() const { return impl_->result; }
std::size_t CfState::last_pairs_tested() const { return internal::pairs_tested(*impl_->detect); }
bool CfState::last_reused_pairs() const { return internal::reused_pairs(*impl_->detect); }

// ---- the stages ----

namespace {

// The state's own part, checked to belong to the model (a comparison: stays on in Release).
CfState::Impl& state_of(const CfModel::Impl& m, CfState& state, const char* stage) {
  CfState::Impl& s = internal::Access::get(state);
  CF_REQUIRE(s.model == &m,
             std::string("cf::") + stage + ": the CfState was made for another CfModel");
  return s;
}

}  // namespace

const ProxyResult& move_proxy(const CfModel& model, CfState& state, const Pose& X_WD, double t_s) {
  const CfModel::Impl& m = internal::Access::get(model);
  CfState::Impl& s = state_of(m, state, "move_proxy");
  internal::advance_proxy(m.proxy, *m.detect, *s.detect, s.detected, s.proxy, X_WD, t_s);
  return s.proxy.result;
}

const ContactSet& detect(const CfModel& model, CfState& state, const Pose& X_WA) {
  const CfModel::Impl& m = internal::Access::get(model);
  CfState::Impl& s = state_of(m, state, "detect");
  return internal::detect_at(*m.detect, *s.detect, X_WA, s.detected);
}

const Identification& identify(const CfModel& model, CfState& state, const ContactSet& contacts) {
  const CfModel::Impl& m = internal::Access::get(model);
  CfState::Impl& s = state_of(m, state, "identify");
  if (&contacts != &s.id.contacts) {
    s.id.contacts = contacts;
    s.detected.valid = false;  // no longer the contacts of the last detection
  }
  internal::identify(*m.graph, m.params.identification, m.params.epsilon_mm, s.previous,
                     *s.identify, s.id);
  return s.id;
}

PriorMotion classify_motion(const CfModel& model, CfState& state, const Identification& id) {
  const CfModel::Impl& m = internal::Access::get(model);
  CfState::Impl& s = state_of(m, state, "classify_motion");
  PriorMotion pm;
  if (id.has_cf() && id.num_cf_pcs > 0) {
    PcSet cur;
    for (int i = 0; i < std::min(id.num_cf_pcs, PcSet::kMaxPcs); ++i)
      cur.insert(id.cf_pcs[static_cast<std::size_t>(i)].pc);
    const PcSet prev = s.previous.valid() ? m.graph->cf(s.previous).pcs : PcSet();
    pm = classify_prior_motion(prev, cur, m.graph, s.previous, id.cf);
  }
  s.previous = internal::next_previous(s.previous, id);
  return pm;
}

const HapticResult& compute_force(const CfModel& model, CfState& state, const Pose& X_WA,
                                  double t_s, const Identification& id, const PriorMotion& motion) {
  const CfModel::Impl& m = internal::Access::get(model);
  CfState::Impl& s = state_of(m, state, "compute_force");
  HapticResult& r = s.result;
  const ContactPc* detected = id.contacts.begin();
  const int n_detected = id.contacts.size();
  r.t_s = t_s;
  r.identification = to_string(id.status);
  r.num_detected = n_detected;
  r.pcs = PcSet();
  r.cf = CfId();
  const ForceResult* fr = nullptr;
  if (id.has_cf() && id.num_cf_pcs > 0) {
    // Canonical order, so that PriorMotion::gained indexes the rendered array.
    const int n = std::min(id.num_cf_pcs, PcSet::kMaxPcs);
    std::copy(id.cf_pcs.begin(), id.cf_pcs.begin() + n, s.ordered.begin());
    std::sort(s.ordered.begin(), s.ordered.begin() + n,
              [](const ContactPc& a, const ContactPc& b) { return a.pc < b.pc; });
    r.cf = id.cf;
    for (int i = 0; i < n; ++i) r.pcs.insert(s.ordered[static_cast<std::size_t>(i)].pc);
    if (motion.transition_in_graph) {
      r.status = RenderStatus::kOk;
      fr = &internal::step_force(m.force, s.force, X_WA, t_s, s.ordered.data(), n, motion, false,
                                 id.approaching.data(), id.num_approaching);
    } else {
      r.status = RenderStatus::kUnlistedTransition;
      const bool have_detected = n_detected > 0;
      fr = &internal::step_force(m.force, s.force, X_WA, t_s,
                                 have_detected ? detected : s.ordered.data(),
                                 have_detected ? n_detected : n, motion, true, nullptr, 0);
    }
  } else if (n_detected > 0) {
    r.status = RenderStatus::kNoFittingCf;
    fr = &internal::step_force(m.force, s.force, X_WA, t_s, detected, n_detected, PriorMotion(),
                               true, nullptr, 0);
  } else {
    r.status = RenderStatus::kNoContact;
    fr = &internal::step_force(m.force, s.force, X_WA, t_s, nullptr, 0, PriorMotion(), false,
                               nullptr, 0);
  }
  r.motion = fr->motion;
  r.F_W = fr->F_W;
  r.M_W = fr->M_W;
  r.F_A = fr->F_A;
  r.M_A = fr->M_A;
  r.X_WD = X_WA;
  r.X_WP = X_WA;
  r.F_contact_W = fr->F_contact_W;
  r.M_contact_W = fr->M_contact_W;
  r.constraint_load_N.fill(0);
  r.force = fr;
  r.proxy = nullptr;
  return r;
}

namespace {

// With the proxy: the rendered wrench gains the coupling, the contact wrench the proxy's
// constraint forces, and each rendered PC the normal load of its point constraints.
void add_proxy(const CfModel::Impl& m, CfState::Impl& s) {
  HapticResult& r = s.result;
  const ProxyResult& p = s.proxy.result;
  const ForceResult& fr = *r.force;
  const Vec3 ref = fr.reference_W;
  const Vec3& g_A = m.params.proxy.grip_point_A;
  const Vec3 g_D = p.X_WD.apply(g_A), g_P = p.X_WP.apply(g_A);
  r.X_WD = p.X_WD;
  r.X_WP = p.X_WP;
  r.F_W += p.F_coupling_W;
  r.M_W += p.M_coupling_W + (g_D - ref).cross(p.F_coupling_W);
  r.F_A = p.X_WP.R_BA.transpose() * r.F_W;
  r.M_A = p.X_WP.R_BA.transpose() * r.M_W;
  r.F_contact_W += p.F_constraint_W;
  r.M_contact_W += p.M_constraint_W + (g_P - ref).cross(p.F_constraint_W);
  r.proxy = &p;
  const Polyhedron& A = m.graph->model_a();
  const Polyhedron& B = m.graph->model_b();
  for (int i = 0; i < fr.num_pcs; ++i) {
    const PcForce& f = fr.pcs[static_cast<std::size_t>(i)];
    double& load = r.constraint_load_N[static_cast<std::size_t>(i)];
    load = 0;
    for (int j = 0; j < p.num_contacts; ++j) {
      const Pc& c = p.contacts[static_cast<std::size_t>(j)].pc;
      if (c == f.pc || dominates(A, B, f.pc, c))  // a corner of this PC's region
        load += p.contacts[static_cast<std::size_t>(j)].normal_load_N;
    }
  }
}

}  // namespace

const HapticResult& step(const CfModel& model, CfState& state, const Pose& X_WD, double t_s) {
  const CfModel::Impl& m = internal::Access::get(model);
  const bool proxy = m.params.proxy.enabled;
  const Pose& X_WA = proxy ? move_proxy(model, state, X_WD, t_s).X_WP : X_WD;
  const ContactSet& contacts = detect(model, state, X_WA);
  const Identification& id = identify(model, state, contacts);
  const PriorMotion motion = classify_motion(model, state, id);
  const HapticResult& r = compute_force(model, state, X_WA, t_s, id, motion);
  if (proxy) add_proxy(m, internal::Access::get(state));
  return r;
}

// ---- HapticRenderer ----

struct HapticRenderer::Impl {
  Impl(const CfGraph& g, const Params& p) : own(std::in_place, g, p), model(&*own), state(*model) {}
  explicit Impl(const CfModel& m) : model(&m), state(m) {}
  std::optional<CfModel> own;  // when the renderer built its model
  const CfModel* model;
  CfState state;
};

HapticRenderer::HapticRenderer(const CfGraph& graph, const Params& params)
    : impl_(std::make_unique<Impl>(graph, params)) {}
HapticRenderer::HapticRenderer(const CfModel& model) : impl_(std::make_unique<Impl>(model)) {}
HapticRenderer::~HapticRenderer() = default;
HapticRenderer::HapticRenderer(HapticRenderer&&) noexcept = default;
HapticRenderer& HapticRenderer::operator=(HapticRenderer&&) noexcept = default;

const HapticResult& HapticRenderer::step(const Pose& pose, double t_s) {
  return cf::step(*impl_->model, impl_->state, pose, t_s);
}
const HapticResult& HapticRenderer::step_identified(const Pose& pose, double t_s,
                                                    const Identification& id) {
  const PriorMotion motion = classify_motion(*impl_->model, impl_->state, id);
  return compute_force(*impl_->model, impl_->state, pose, t_s, id, motion);
}
void HapticRenderer::reset() { impl_->state.reset(); }
const HapticResult& HapticRenderer::result() const { return impl_->state.result(); }
const CfGraph& HapticRenderer::graph() const { return impl_->model->graph(); }
const Params& HapticRenderer::params() const { return impl_->model->params(); }
const CfModel& HapticRenderer::model() const { return *impl_->model; }
const CfState& HapticRenderer::state() const { return impl_->state; }

// ---- CfIdentifier ----

struct CfIdentifier::Impl {
  Impl(const CfGraph& g, const Params& p) : model(g, p), state(model) {}
  CfModel model;
  CfState state;
};

CfIdentifier::CfIdentifier(const CfGraph& graph, const Params& params)
    : impl_(std::make_unique<Impl>(graph, params)) {}
CfIdentifier::~CfIdentifier() = default;
CfIdentifier::CfIdentifier(CfIdentifier&&) noexcept = default;
CfIdentifier& CfIdentifier::operator=(CfIdentifier&&) noexcept = default;

const Identification& CfIdentifier::step(const Pose& pose) {
  const Identification& id =
      identify(impl_->model, impl_->state, detect(impl_->model, impl_->state, pose));
  CfState::Impl& s = internal::Access::get(impl_->state);
  s.previous = internal::next_previous(s.previous, id);
  return id;
}
void CfIdentifier::reset() { internal::Access::get(impl_->state).previous = CfId(); }
CfId CfIdentifier::previous() const { return impl_->state.previous(); }
const Identification& CfIdentifier::last() const { return impl_->state.identification(); }
const CfGraph& CfIdentifier::graph() const { return impl_->model.graph(); }

}  // namespace cf

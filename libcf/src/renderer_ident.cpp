// The renderer's view of cf::CfIdentifier.

#include "renderer_ident.hpp"

namespace cf::detail {

namespace {
IdentificationParams identification_params(const Params& p) {
  IdentificationParams ip;
  ip.detection.epsilon = p.epsilon_mm;
  return ip;
}
}  // namespace

IdentAdapter::IdentAdapter(const CfGraph& graph, const Params& params)
    : ident_(graph, identification_params(params)) {}

IdentView IdentAdapter::step(const Pose& pose) {
  const Identification& id = ident_.step(pose);
  IdentView v;
  v.cf = id.cf;
  v.cf_pcs = id.cf_pcs.data();
  v.n_cf = id.has_cf() ? id.num_cf_pcs : 0;
  v.detected = id.contacts.begin();
  v.n_detected = id.contacts.size();
  v.status = to_string(id.status);
  v.approaching = id.approaching.data();
  v.n_approaching = id.has_cf() ? id.num_approaching : 0;
  return v;
}

}  // namespace cf::detail

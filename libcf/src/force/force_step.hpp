#pragma once
// One tick of the force model over its fixed part and its state: ForceModel::step, and the
// servo's compute_force stage (whose CfModel holds the fixed part and CfState the state).

#include <cf/force.hpp>

namespace cf::internal {

/// ForceModel::step's tick (its arguments are documented there) on `model` and `state`.
const ForceResult& step_force(const ForceModel::Fixed& model, ForceState& state, const Pose& pose,
                              double t_s, const ContactPc* pcs, int n, const PriorMotion& prior,
                              bool conservative, const ContactPc* approaching, int n_approaching);

}  // namespace cf::internal

#pragma once
// What CfModel and CfState hold, for the stages (servo.cpp) and nothing else.

#include <cf/force.hpp>
#include <cf/model.hpp>
#include <cf/servo.hpp>
#include <cf/state.hpp>

#include "../detect/detect.hpp"
#include "../identify/identify.hpp"
#include "../proxy/proxy.hpp"

#include <array>

namespace cf {

struct CfModel::Impl {
  Impl(const CfGraph& g, const Params& p);
  const CfGraph* graph;
  Params params;
  internal::DetectModelPtr detect;  // trees and tables (detect/detector.cpp)
  internal::ProxyModel proxy;       // A's metric about the grip point (proxy/proxy.cpp)
  ForceModel::Fixed force;          // the force model's models, parameters, A's mass centre
};

struct CfState::Impl {
  explicit Impl(const CfModel::Impl& m);
  const CfModel::Impl* model;  // the model it was sized for: the stages check it
  internal::DetectStatePtr detect;
  internal::IdentifyScratchPtr identify;
  Identification id;              // detect() writes id.contacts, identify() the rest
  internal::DetectedAt detected;  // the pose id.contacts are of (the proxy detects there too)
  CfId previous;                  // written by classify_motion only (internal::next_previous)
  ForceState force;               // stick anchors, held loads, filters
  internal::ProxyState proxy;     // the proxy pose and its history
  std::array<ContactPc, PcSet::kMaxPcs> ordered{};  // the CF's PCs in canonical order
  HapticResult result;
};

namespace internal {
struct Access {
  static const CfModel::Impl& get(const CfModel& m) { return *m.impl_; }
  static CfState::Impl& get(CfState& s) { return *s.impl_; }
};
}  // namespace internal

}  // namespace cf

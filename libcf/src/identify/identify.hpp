#pragma once
// Identification's per-thread scratch (the planes' members, the memo of the graph's PC
// lookups) and the identification itself, as a function of the graph, the parameters, the
// previous CF and the detected contacts. Opaque here; identifier.cpp holds it.

#include <cf/graph.hpp>
#include <cf/identifier.hpp>
#include <cf/params.hpp>

#include <memory>

namespace cf::internal {

struct IdentifyScratch;
struct IdentifyScratchDelete {
  void operator()(IdentifyScratch* s) const;
};
using IdentifyScratchPtr = std::unique_ptr<IdentifyScratch, IdentifyScratchDelete>;
IdentifyScratchPtr make_identify_scratch();

/// Identifies the CF among `id.contacts` (as detected: canonical order, planes set),
/// preferring `previous` and its neighbours; fills the rest of `id`. No heap allocation.
void identify(const CfGraph& graph, const IdentificationParams& params, double epsilon_mm,
              CfId previous, IdentifyScratch& s, Identification& id);

/// The CF preferred at the next tick after `id`: its CF; none after a tick without contact;
/// the same as before when the contacts fit no CF.
inline CfId next_previous(CfId previous, const Identification& id) {
  if (id.has_cf()) return id.cf;
  return id.contacts.empty() ? CfId() : previous;
}

}  // namespace cf::internal

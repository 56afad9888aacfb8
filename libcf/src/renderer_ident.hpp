#pragma once
// Identification as the renderer uses it: the chosen CF, its PCs and every detected contact,
// from cf::CfIdentifier (SPEC section 6's preference: previous CF, neighbour, best fit).

#include <cf/contact.hpp>
#include <cf/graph.hpp>
#include <cf/identifier.hpp>
#include <cf/params.hpp>

namespace cf::detail {

struct IdentView {
  CfId cf;
  const ContactPc* cf_pcs = nullptr;
  int n_cf = 0;
  const ContactPc* detected = nullptr;
  int n_detected = 0;
  const char* status = "";
  const ContactPc* approaching = nullptr;
  int n_approaching = 0;
};

class IdentAdapter {
 public:
  IdentAdapter(const CfGraph& graph, const Params& params);
  void reset() { ident_.reset(); }
  /// No heap allocation.
  IdentView step(const Pose& pose);

 private:
  CfIdentifier ident_;
};

}  // namespace cf::detail

#pragma once
// Identification as the renderer uses it: the chosen CF, its PCs and every detected contact.
// A thin adapter so that the renderer does not depend on how identification is done.

#include <cf/contact.hpp>
#include <cf/detector.hpp>
#include <cf/graph.hpp>
#include <cf/params.hpp>

#include <array>
#include <memory>

namespace cf::detail {

struct IdentView {
  CfId cf;
  const ContactPc* cf_pcs = nullptr;
  int n_cf = 0;
  const ContactPc* detected = nullptr;
  int n_detected = 0;
  const char* status = "";
};

class Identification {
 public:
  Identification(const CfGraph& graph, const Params& params);
  void reset();
  /// No heap allocation.
  IdentView step(const Pose& pose);

 private:
  bool all_detected(CfId id, double* misfit);
  const CfGraph* graph_;
  ContactDetector detector_;
  std::unique_ptr<ContactSet> contacts_;
  std::array<ContactPc, PcSet::kMaxPcs> chosen_{};
  CfId prev_;
};

}  // namespace cf::detail

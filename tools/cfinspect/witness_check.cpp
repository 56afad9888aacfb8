#include "witness_check.hpp"

#include "cfgen/execute/parallel.hpp"
#include "cfgen/generate.hpp"  // scaled_search: cfgen's defaults
#include "cfgen/verify/record_check.hpp"

#include <vector>

namespace cf::inspect {

WitnessCheck check_witnesses(const CfGraph& g, int threads) {
  const gen::RecordCheck check(g, tools::scaled_search(g.model_a(), g.model_b(), {}));
  std::vector<std::string> why(g.num_cfs());
  gen::parallel_for(g.num_cfs(), gen::resolve_threads(threads),
                    [&](std::size_t i) { why[i] = check.check(g.cf(CfId(static_cast<int>(i)))); });
  WitnessCheck out;
  out.available = true;
  out.checked = g.num_cfs();
  for (std::size_t i = 0; i < why.size(); ++i) {
    if (why[i].empty()) continue;
    if (out.failed++ == 0) {
      out.first_bad = static_cast<long long>(i);
      out.why = why[i];
    }
  }
  return out;
}

}  // namespace cf::inspect

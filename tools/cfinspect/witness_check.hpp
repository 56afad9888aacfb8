// cfinspect's witness check (--verify, part of the default full check): every CF's witness
// re-checked with the generator's own verify (cfgen/verify/record_check.hpp).
#pragma once

#include <cf/graph.hpp>

#include <cstddef>
#include <string>

namespace cf::inspect {

struct WitnessCheck {
  bool available = false;    // false: cfinspect was built without the generator (no CGAL)
  std::size_t checked = 0;   // CFs whose record was checked
  std::size_t failed = 0;    // of them, those that do not hold
  long long first_bad = -1;  // the smallest id of a CF that does not hold
  std::string why;           // why that CF does not hold
};

/// Checks every CF of `g` on `threads` threads (0: the hardware's count) with the
/// verification tolerances the graph records (its "parameters"; cfgen's defaults for those
/// missing). Returns available == false, checking nothing, when built without CGAL.
/// @throws cf::Error when the recorded parameters are not positive finite numbers, or a
/// model cannot be analysed (a face that cannot be partitioned).
WitnessCheck check_witnesses(const CfGraph& g, int threads);

}  // namespace cf::inspect

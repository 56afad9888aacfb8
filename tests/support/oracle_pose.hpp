#pragma once
// Poses and PC sets between the project's types and the independent oracle's (tests/oracle),
// for the tests that link both the code under test and the oracle (cf_oracle). The oracle's
// pose is the same map (x_B = R x_A + t), and its PCs the same triples (type named as in the
// graph file, element indices), held in its own types so that it shares no code.

#include "classify.hpp"

#include <cf/pc.hpp>
#include <cf/types.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace cf::test {

inline oracle::Pose to_oracle(const cf::Pose& X) {
  oracle::Pose P;
  P.R = X.R_BA;
  P.t = X.t_BA;
  return P;
}

inline cf::Pose to_cf(const oracle::Pose& P) {
  cf::Pose X;
  X.R_BA = P.R;
  X.t_BA = P.t;
  return X;
}

/// The project's PC of one of the oracle's non-degenerate PCs; throws std::logic_error for a
/// degenerate type (v-v, v-e, e-v, collinear e-e), which has none.
inline cf::Pc to_cf(const oracle::Pc& p) {
  const auto type = cf::pc_type_from_string(oracle::type_name(p.type));
  if (!type) throw std::logic_error(std::string("no PC type ") + oracle::type_name(p.type));
  return cf::Pc{*type, p.a, p.b};
}

/// The project's PC set of the oracle's PCs (at most three, all non-degenerate).
inline cf::PcSet to_cf(const oracle::CfKey& key) {
  std::vector<cf::Pc> pcs;
  for (const oracle::Pc& p : key) pcs.push_back(to_cf(p));
  return cf::PcSet(pcs);
}

/// The oracle's PCs (sorted) of the project's PC set.
inline oracle::CfKey to_oracle(const cf::PcSet& set) {
  oracle::CfKey key;
  for (const cf::Pc& p : set) {
    oracle::PcType type;
    if (!oracle::parse_type(cf::to_string(p.type), &type))
      throw std::logic_error(std::string("no oracle PC type ") + cf::to_string(p.type));
    key.push_back(oracle::Pc{type, p.a, p.b});
  }
  std::sort(key.begin(), key.end());
  return key;
}

}  // namespace cf::test

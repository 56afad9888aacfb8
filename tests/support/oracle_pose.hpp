#pragma once
// Poses between the project's frames and the independent oracle's (tests/oracle), for the
// tests that link both the code under test and the oracle (cf_oracle). The oracle's pose is
// the same map (x_B = R x_A + t), held in its own type so that it shares no code.

#include "classify.hpp"

#include <cf/types.hpp>

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

}  // namespace cf::test

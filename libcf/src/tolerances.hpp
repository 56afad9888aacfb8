#pragma once
// The numerical allowances libcf's computations share (issue: every literal tolerance named).
// Tolerances a user sets (epsilon, the angular tolerances, the proxy's) are parameters
// (cf/params.hpp); the geometric tolerances of detection are derived from epsilon and the
// models' size (detect/exact.hpp, DetectionTables). What is here is rounding: how far a value
// computed in double or float may be from the exact one, far below any tolerance set. A
// length is round-off below kRelativeRounding times the length scale it is computed at:
// epsilon, for what detection and the force model measure (it has no direction, and nothing
// divides by it).

namespace cf::internal {

/// Dimensionless: the rounding allowance of a ratio, a segment parameter, a sine or a cosine
/// computed in double from a few lengths or unit vectors. A double's unit is 1.1e-16 and a few
/// operations stay within 1e-14; every tolerance a user or a model sets is above 1e-9.
constexpr double kRelativeRounding = 1e-12;

/// Dimensionless: the rounding of a float (single precision) coordinate, 2^-24 relative, taken
/// up: a box's centre rounded to float errs by less than this times its magnitude.
constexpr double kFloatRounding = 1.2e-7;

/// A float box's half extent is grown by this factor after the rounding it was computed with
/// (3e-7 relative, more than the float operations' own rounding).
constexpr float kFloatGrowth = 1.0000003f;

}  // namespace cf::internal

#pragma once
// n-gon pegs and holes written in code (the scale pairs of docs/spec.md, section 7): an n-gon
// prism, and a block (an n-gon tube) with an n-gon through-hole.

#include "scratch.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <utility>

namespace cf::test {

/// OFF text of an n-gon prism of circumradius r along y in [y0, y1]; with r_in > 0, a tube
/// with an n-gon hole of circumradius r_in (its rings' quads are merged into one face with a
/// hole by the loader). Faces counter-clockwise seen from outside.
inline std::string ngon_off(int n, double r, double r_in, double y0, double y1) {
  std::ostringstream os;
  os.precision(17);
  const bool tube = r_in > 0;
  os << "OFF\n" << (tube ? 4 * n : 2 * n) << ' ' << (tube ? 4 * n : n + 2) << " 0\n";
  // Rings: outer bottom, outer top, then (a tube) inner bottom, inner top; n vertices each.
  for (int ring = 0; ring < (tube ? 4 : 2); ++ring) {
    const double rad = ring < 2 ? r : r_in, y = ring % 2 == 0 ? y0 : y1;
    for (int i = 0; i < n; ++i)
      os << rad * std::cos(2 * M_PI * i / n) << ' ' << y << ' ' << rad * std::sin(2 * M_PI * i / n)
         << '\n';
  }
  for (int i = 0, j = 1; i < n; ++i, j = (i + 1) % n)
    os << "4 " << i << ' ' << n + i << ' ' << n + j << ' ' << j << '\n';
  if (!tube) {
    os << n;
    for (int i = 0; i < n; ++i) os << ' ' << i;
    os << '\n' << n;
    for (int i = n - 1; i >= 0; --i) os << ' ' << n + i;
    os << '\n';
    return os.str();
  }
  for (int i = 0, j = 1; i < n; ++i, j = (i + 1) % n) {
    os << "4 " << 2 * n + i << ' ' << 2 * n + j << ' ' << 3 * n + j << ' ' << 3 * n + i << '\n';
    os << "4 " << i << ' ' << j << ' ' << 2 * n + j << ' ' << 2 * n + i << '\n';
    os << "4 " << n + i << ' ' << 3 * n + i << ' ' << 3 * n + j << ' ' << n + j << '\n';
  }
  return os.str();
}

/// The files of the n-gon peg (circumradius 10 mm, 40 mm long) and of the block whose hole
/// is 5% wider (outer radius 25 mm, 20 mm high) in the scratch directory, named by `prefix`.
inline std::pair<std::string, std::string> ngon_peg_and_hole(int n, const std::string& prefix) {
  return {write_file(prefix + "_peg.off", ngon_off(n, 10, 0, -20, 20)),
          write_file(prefix + "_hole.off", ngon_off(n, 25, 10.5, 0, 20))};
}

}  // namespace cf::test

#include "cfgen/decide/rotation_cells.hpp"

#include <algorithm>
#include <cmath>

namespace cf::gen {

RotationCell whole_rotation_space() { return {Vec3::Zero(), M_PI}; }

Mat3 rotation_at(const Vec3& r) {
  const double a = r.norm();
  if (a == 0) return Mat3::Identity();
  const Vec3 k = r / a;
  Mat3 K;
  K << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Mat3::Identity() + std::sin(a) * K + (1 - std::cos(a)) * K * K;
}

double turn_bound(const RotationCell& cell) {
  // No two unit vectors are more than 2 apart.
  return std::min(std::sqrt(3.0) * cell.half, 2.0);
}

bool outside_rotation_ball(const RotationCell& cell) {
  // The cell's point nearest the origin: each coordinate clamped to the cube.
  Vec3 nearest;
  for (int k = 0; k < 3; ++k)
    nearest[k] = std::clamp(0.0, cell.centre[k] - cell.half, cell.centre[k] + cell.half);
  return nearest.norm() > M_PI;
}

std::array<RotationCell, 8> split(const RotationCell& cell) {
  std::array<RotationCell, 8> out;
  const double h = cell.half / 2;
  for (int i = 0; i < 8; ++i) {
    const Vec3 sign((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
    out[static_cast<std::size_t>(i)] = {cell.centre + h * sign, h};
  }
  return out;
}

}  // namespace cf::gen

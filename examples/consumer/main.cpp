// Builds a 10 mm cube from its features with the installed libcf and checks its volume.
// Exit status 0 when the volume is 1000 mm^3.
#include <cf/polyhedron.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

int main() {
  const double s = 10.0;  // mm, edge length
  std::vector<cf::Vec3> vertices = {
      {0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0},  // bottom, z = 0
      {0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s},  // top, z = s
  };
  const std::vector<std::array<int, 2>> edges = {
      {0, 1}, {1, 2}, {2, 3}, {0, 3},  // bottom
      {4, 5}, {5, 6}, {6, 7}, {4, 7},  // top
      {0, 4}, {1, 5}, {2, 6}, {3, 7},  // vertical
  };
  // One outer loop per face, counter-clockwise seen from outside.
  const std::vector<std::vector<std::vector<int>>> faces = {
      {{0, 3, 2, 1}},  // z = 0
      {{4, 5, 6, 7}},  // z = s
      {{0, 1, 5, 4}},  // y = 0
      {{2, 3, 7, 6}},  // y = s
      {{0, 4, 7, 3}},  // x = 0
      {{1, 2, 6, 5}},  // x = s
  };
  try {
    const cf::Polyhedron cube =
        cf::Polyhedron::from_features("cube", std::move(vertices), edges, faces);
    const double volume = cube.volume();  // mm^3
    std::printf("%s: %zu vertices, %zu edges, %zu faces, volume %.6f mm^3\n",
                cube.name().c_str(), cube.num_vertices(), cube.num_edges(), cube.num_faces(),
                volume);
    // Exact for an axis-aligned cube up to rounding in the divergence-theorem sum.
    const double tolerance = 1e-9 * s * s * s;
    return std::abs(volume - s * s * s) <= tolerance ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cf_consumer: %s\n", e.what());
    return 2;
  }
}

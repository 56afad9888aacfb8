// Uses the installed libcf as a haptic application would: builds a 10 mm cube from its
// features (and checks its volume), a slab for it to rest on and a one-CF graph, then steps
// a servo loop over a CfModel shared by the threads and this thread's CfState while the
// cube comes down onto the slab. Exit status 0 when the volume is 1000 mm^3 and the slab
// pushes the cube up once it is within the contact threshold.
#include <cf/polyhedron.hpp>
#include <cf/renderer.hpp>

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
    std::printf("%s: %zu vertices, %zu edges, %zu faces, volume %.6f mm^3\n", cube.name().c_str(),
                cube.num_vertices(), cube.num_edges(), cube.num_faces(), volume);
    // Exact for an axis-aligned cube up to rounding in the divergence-theorem sum.
    const double tolerance = 1e-9 * s * s * s;
    if (std::abs(volume - s * s * s) > tolerance) return 1;

    // B: a 50 x 10 x 50 mm slab whose top face (its face 3) is the plane y = 0.
    std::vector<cf::Vec3> slab_vertices;
    for (const cf::Vertex& v : cube.vertices())
      slab_vertices.push_back({-20 + 5 * v.p.x(), v.p.y() - s, -20 + 5 * v.p.z()});
    const cf::Polyhedron slab =
        cf::Polyhedron::from_features("slab", std::move(slab_vertices), edges, faces);
    // One CF: the cube's face y = 0 (its face 2) flat on the slab's top.
    std::vector<cf::CfRecord> cfs(1);
    cfs[0].pcs = cf::PcSet({cf::Pc{cf::PcType::kFF, 2, 3}});
    cfs[0].witness.t_BA = {0, 0, 0};
    const cf::CfGraph graph = cf::CfGraph::from_parts(cube, slab, std::move(cfs), {});

    const cf::CfModel model(graph);  // shared, read-only
    cf::CfState state(model);        // one per servo thread
    const cf::HapticResult* out = nullptr;
    for (int tick = 0; tick <= 200; ++tick) {  // 1 kHz, from 2 mm above to 0.5 mm
      cf::Pose X_WA;
      X_WA.t_BA = {0, 2.0 - 0.0075 * tick, 0};
      out = &cf::step(model, state, X_WA, 0.001 * tick);
    }
    std::printf("at 0.5 mm: CF %d, %s, %s, F_W = (%.3f, %.3f, %.3f) N\n", out->cf.value(),
                cf::to_string(out->status), cf::to_string(out->motion), out->F_W.x(), out->F_W.y(),
                out->F_W.z());
    const bool pushed_up = out->status == cf::RenderStatus::kOk && out->cf.value() == 0 &&
                           out->force != nullptr && out->F_W.y() > out->force->F_gravity_W.y();
    return pushed_up ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cf_consumer: %s\n", e.what());
    return 2;
  }
}

// The generator at growing model size (the scale issue; docs/spec.md, section 7): an n-gon peg in a
// block with an n-gon through-hole, n = 3, 4, 6, 8, 12, 16, on 1 and 2 threads, with one
// search per orbit of the pair's symmetries (symmetry:1, cfgen's default) and searching every
// set (symmetry:0, --no-symmetry). Reports the
// wall time of the whole enumeration (one iteration: a run takes seconds to an hour) and the
// CFs found, and the time per valid CF as a counter. The models are written by this file,
// not read from data/: a peg of radius 10 mm and length 40 mm, a block of outer radius 25 mm
// and height 20 mm whose hole is 5% wider than the peg, both n-gon prisms (the block a tube).
//
//   build/bench/cfgen_bench --benchmark_filter='n:(4|6)/.*/symmetry:1'   # square and hexagonal
//   pegs
// Figures go to docs/performance.md, "Graph generation".

#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/generate.hpp"
#include "mesh/model_loader.hpp"

#include <benchmark/benchmark.h>

#include <unistd.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

// OFF text of an n-gon prism of circumradius r along y in [y0, y1]; with r_in > 0, a tube
// (the n-gon hole of circumradius r_in through it). Faces counter-clockwise from outside.
std::string ngon_off(int n, double r, double r_in, double y0, double y1) {
  std::ostringstream os;
  os.precision(17);
  const bool tube = r_in > 0;
  const int nv = tube ? 4 * n : 2 * n;
  const int nf = tube ? 4 * n : n + 2;
  os << "OFF\n" << nv << ' ' << nf << " 0\n";
  auto ring = [&](double rad, double y) {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      os << rad * std::cos(a) << ' ' << y << ' ' << rad * std::sin(a) << '\n';
    }
  };
  ring(r, y0);  // 0..n-1: outer bottom
  ring(r, y1);  // n..2n-1: outer top
  if (tube) {
    ring(r_in, y0);  // 2n..3n-1: inner bottom
    ring(r_in, y1);  // 3n..4n-1: inner top
  }
  for (int i = 0; i < n; ++i) {  // outer sides, normals outward
    const int j = (i + 1) % n;
    os << "4 " << i << ' ' << n + i << ' ' << n + j << ' ' << j << '\n';
  }
  if (!tube) {
    os << n;  // bottom, normal -y
    for (int i = 0; i < n; ++i) os << ' ' << i;
    os << '\n' << n;  // top, normal +y
    for (int i = n - 1; i >= 0; --i) os << ' ' << n + i;
    os << '\n';
    return os.str();
  }
  for (int i = 0; i < n; ++i) {  // hole sides, normals toward the axis
    const int j = (i + 1) % n;
    os << "4 " << 2 * n + i << ' ' << 2 * n + j << ' ' << 3 * n + j << ' ' << 3 * n + i << '\n';
  }
  for (int i = 0; i < n; ++i) {  // bottom ring (-y) and top ring (+y), one quad per side
    const int j = (i + 1) % n;
    os << "4 " << i << ' ' << j << ' ' << 2 * n + j << ' ' << 2 * n + i << '\n';
    os << "4 " << n + i << ' ' << 3 * n + i << ' ' << 3 * n + j << ' ' << n + j << '\n';
  }
  return os.str();
}

cf::Polyhedron load_text(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("cfgen_bench_" + std::to_string(getpid()) + "_" + name + ".off"))
                               .string();
  {
    std::ofstream f(path);
    f << text;
  }
  cf::Polyhedron m = cf::tools::load_model(path, {});
  std::filesystem::remove(path);
  return m;
}

void BM_NgonPegInHole(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const bool symmetry = state.range(2) != 0;
  const cf::Polyhedron A = load_text("peg", ngon_off(n, 10.0, 0, -20, 20));
  const cf::Polyhedron B = load_text("hole", ngon_off(n, 25.0, 10.5, 0, 20));
  const cf::gen::ModelInfo ai = cf::gen::analyse_model(A), bi = cf::gen::analyse_model(B);
  cf::gen::EnumerateOptions opt;
  opt.use_symmetry = symmetry;
  cf::gen::ExecuteOptions exec;
  exec.threads = threads;
  const cf::gen::SearchParams search =
      cf::tools::scaled_search(A, B, cf::tools::RelativeLengths{});  // cfgen's defaults
  std::size_t cfs = 0, candidates = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const cf::gen::Enumeration e = cf::gen::enumerate_pair(ai, bi, search, opt, exec);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cfs = e.cfs.size();
    candidates = e.levels[1].candidates;
  }
  state.counters["faces_A_B"] = static_cast<double>(A.num_faces() + B.num_faces());
  state.counters["cfs"] = static_cast<double>(cfs);
  state.counters["level2_candidates"] = static_cast<double>(candidates);
  state.counters["ms_per_cf"] = cfs > 0 ? 1e3 * seconds / static_cast<double>(cfs) : 0.0;  // wall
}

}  // namespace

BENCHMARK(BM_NgonPegInHole)
    ->ArgNames({"n", "threads", "symmetry"})
    ->ArgsProduct({{3, 4, 6, 8, 12, 16}, {1, 2}, {1, 0}})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);

BENCHMARK_MAIN();

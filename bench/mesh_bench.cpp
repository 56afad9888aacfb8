// Model loading of one large polygon (tools/mesh: parsing, validation with the self-
// intersection test, feature extraction), against its number of sides: a prism whose caps are
// an n-gon. "star": the caps' corners alternate between two radii (every corner a real one);
// "straight": a square whose sides carry n/4 vertices each, as CAD exports write the edges a
// face shares with a tessellated one. Issue 41: a 30,000-gon in at most 1 s, doubling n at
// most 2.5x the time; the fitted complexity is printed (docs/performance.md, "Model loading").
//
//   build/bench/mesh_bench

#include "mesh/model_loader.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

namespace {

// OFF text of a prism along y (0 to 20 mm) over the polygon ring (x, z), faces outward.
std::string prism_off(const std::vector<std::pair<double, double>>& ring) {
  const std::size_t n = ring.size();
  std::ostringstream os;
  os.precision(17);
  os << "OFF\n" << 2 * n << ' ' << n + 2 << " 0\n";
  for (double y : {0.0, 20.0})
    for (const auto& [x, z] : ring) os << x << ' ' << y << ' ' << z << '\n';
  for (std::size_t i = 0; i < n; ++i) {  // sides
    const std::size_t j = (i + 1) % n;
    os << "4 " << i << ' ' << n + i << ' ' << n + j << ' ' << j << '\n';
  }
  os << n;  // bottom (-y)
  for (std::size_t i = 0; i < n; ++i) os << ' ' << i;
  os << '\n' << n;  // top (+y)
  for (std::size_t i = n; i-- > 0;) os << ' ' << n + i;
  os << '\n';
  return os.str();
}

std::vector<std::pair<double, double>> star(int n) {
  std::vector<std::pair<double, double>> ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, r = i % 2 == 0 ? 100.0 : 99.0;
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return ring;
}

std::vector<std::pair<double, double>> straight_square(int n) {
  std::vector<std::pair<double, double>> ring;
  const int k = n / 4;
  for (int s = 0; s < 4; ++s)
    for (int i = 0; i < k; ++i) {
      const double f = 100.0 * i / k;
      const std::pair<double, double> p[] = {{f, 0}, {100, f}, {100 - f, 100}, {0, 100 - f}};
      ring.push_back(p[s]);
    }
  return ring;
}

void BM_LoadPolygon(benchmark::State& state, bool straight) {
  const int n = static_cast<int>(state.range(0));
  const std::string text = prism_off(straight ? straight_square(n) : star(n));
  for (auto _ : state) {
    const cf::tools::PolygonSoup soup =
        cf::tools::parse_polygon_soup(text, cf::tools::MeshFormat::kOff, "bench.off");
    benchmark::DoNotOptimize(cf::tools::model_from_soup(soup, "bench.off").num_faces());
  }
  state.SetComplexityN(n);
}

BENCHMARK_CAPTURE(BM_LoadPolygon, star, false)
    ->Arg(3750)
    ->Arg(7500)
    ->Arg(15000)
    ->Arg(30000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity();
BENCHMARK_CAPTURE(BM_LoadPolygon, straight, true)
    ->Arg(3752)
    ->Arg(7500)
    ->Arg(15000)
    ->Arg(30000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity();

}  // namespace

BENCHMARK_MAIN();

// The full servo step (detect, identify, classify, force: HapticRenderer::step) on the
// paper's cube against its L-shaped block (SPEC section 7: median <= 5 us, 99.9th
// percentile <= 20 us), and its parts. Each step is timed on its own so that the median and
// the 99.9th percentile are reported (counters median_us, p99_us, p999_us, max_us).
//
// Graph: CF_STEP_BENCH_GRAPH (environment) or data/graphs/cube_l_block.json when present
// (cfgen's whole graph), else a small built-in graph (floor, wall, corner CFs). The
// trajectory: data/trajectories/cube_lblock_{guarded,slide,corner,rotate,break}.csv played
// back to back, cyclically.

#include "runtime_models.hpp"

#include <cf/detector.hpp>
#include <cf/force.hpp>
#include <cf/renderer.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Tick {
  double t;
  cf::Pose pose;
};

std::vector<Tick> load_ticks() {
  std::vector<Tick> out;
  double t_off = 0;
  for (const char* name : {"guarded", "slide", "corner", "rotate", "break"}) {
    std::ifstream in(std::string(CF_SOURCE_DIR) + "/data/trajectories/cube_lblock_" + name + ".csv");
    std::string line;
    std::getline(in, line);  // header
    double last = 0;
    while (std::getline(in, line)) {
      double v[8];
      char c;
      std::istringstream ss(line);
      ss >> v[0];
      for (int i = 1; i < 8; ++i) ss >> c >> v[i];
      Tick k;
      k.t = t_off + v[0];
      k.pose.t_BA = {v[1], v[2], v[3]};
      k.pose.R_BA = Eigen::Quaterniond(v[4], v[5], v[6], v[7]).normalized().toRotationMatrix();
      out.push_back(k);
      last = k.t;
    }
    t_off = last + 0.001;
  }
  return out;
}

std::unique_ptr<cf::CfGraph> load_graph(std::string* which) {
  const char* env = std::getenv("CF_STEP_BENCH_GRAPH");
  const std::string path = env ? env : std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json";
  if (std::ifstream(path).good()) {
    *which = path;
    return std::make_unique<cf::CfGraph>(cf::CfGraph::load(path));
  }
  *which = "built-in floor/wall/corner graph";
  const cf::Pc floor{cf::PcType::kFF, 2, 4}, wall{cf::PcType::kFF, 5, 5};
  std::vector<cf::CfRecord> cfs(3);
  cfs[0].pcs = cf::PcSet({floor});
  cfs[1].pcs = cf::PcSet({wall});
  cfs[2].pcs = cf::PcSet({floor, wall});
  std::vector<cf::Transition> tr = {{cf::CfId(0), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(0), cf::TransitionKind::kLose},
                                    {cf::CfId(1), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(1), cf::TransitionKind::kLose}};
  return std::make_unique<cf::CfGraph>(
      cf::CfGraph::from_parts(cf::testmodels::cube(), cf::testmodels::l_block(), std::move(cfs), std::move(tr)));
}

void report(benchmark::State& state, std::vector<double>& ns) {
  if (ns.empty()) return;
  std::sort(ns.begin(), ns.end());
  auto q = [&](double p) { return ns[std::min(ns.size() - 1, static_cast<std::size_t>(p * static_cast<double>(ns.size())))] / 1000.0; };
  state.counters["median_us"] = q(0.5);
  state.counters["p99_us"] = q(0.99);
  state.counters["p999_us"] = q(0.999);
  state.counters["max_us"] = ns.back() / 1000.0;
}

void BM_ServoStep(benchmark::State& state) {
  std::string which;
  const auto graph = load_graph(&which);
  const std::vector<Tick> ticks = load_ticks();
  cf::HapticRenderer renderer(*graph);
  std::vector<double> ns;
  ns.reserve(2'000'000);
  std::size_t i = 0;
  double t_base = 0;
  long contact_ticks = 0;
  for (auto _ : state) {
    const Tick& k = ticks[i];
    const auto a = std::chrono::steady_clock::now();
    const cf::HapticResult& r = renderer.step(k.pose, t_base + k.t);
    const auto b = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(r.F_W.data());
    contact_ticks += r.status != cf::RenderStatus::kNoContact;
    if (ns.size() < ns.capacity()) ns.push_back(std::chrono::duration<double, std::nano>(b - a).count());
    if (++i == ticks.size()) {
      i = 0;
      t_base += ticks.back().t + 0.001;
    }
  }
  report(state, ns);
  state.counters["contact_share"] = static_cast<double>(contact_ticks) / static_cast<double>(state.iterations());
  state.SetLabel(which);
}
BENCHMARK(BM_ServoStep)->MinTime(2.0)->Unit(benchmark::kMicrosecond);

// Detection alone on the same poses, to split the step's cost.
void BM_DetectOnly(benchmark::State& state) {
  const cf::Polyhedron A = cf::testmodels::cube(), B = cf::testmodels::l_block();
  cf::ContactDetector det(A, B);
  auto set = std::make_unique<cf::ContactSet>();
  const std::vector<Tick> ticks = load_ticks();
  std::vector<double> ns;
  ns.reserve(2'000'000);
  std::size_t i = 0;
  for (auto _ : state) {
    const auto a = std::chrono::steady_clock::now();
    det.detect(ticks[i].pose, *set);
    const auto b = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(set->size());
    if (ns.size() < ns.capacity()) ns.push_back(std::chrono::duration<double, std::nano>(b - a).count());
    if (++i == ticks.size()) i = 0;
  }
  report(state, ns);
}
BENCHMARK(BM_DetectOnly)->MinTime(1.0)->Unit(benchmark::kMicrosecond);

// The force model alone (two f-f PCs sliding along the L-block's corner: MT2.b with the
// freedoms computed every tick, the costliest case).
void BM_ForceOnly(benchmark::State& state) {
  const cf::Polyhedron A = cf::testmodels::cube(), B = cf::testmodels::l_block();
  cf::ForceModel model(A, B);
  cf::ContactPc cs[2];
  cs[0].pc = {cf::PcType::kFF, 2, 4};
  cs[0].distance = 0.5;
  cs[0].R_WT << 1, 0, 0, 0, 1, 0, 0, 0, 1;
  cs[1].pc = {cf::PcType::kFF, 5, 5};
  cs[1].distance = 0.5;
  cs[1].R_WT << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  cf::PriorMotion pm;
  pm.type = cf::MotionType::kMT2a;
  double t = 0, z = 40;
  std::vector<double> ns;
  ns.reserve(2'000'000);
  for (auto _ : state) {
    cf::Pose p;
    p.t_BA = {35.5, 35.5, z};
    cs[0].p_W = {35.5, 20.5, z};
    cs[1].p_W = {20.5, 35.5, z};
    z += 0.02;
    if (z > 60) z = 20;
    const auto a = std::chrono::steady_clock::now();
    const cf::ForceResult& r = model.step(p, t += 0.001, cs, 2, pm);
    const auto b = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(r.F_W.data());
    if (ns.size() < ns.capacity()) ns.push_back(std::chrono::duration<double, std::nano>(b - a).count());
  }
  report(state, ns);
}
BENCHMARK(BM_ForceOnly)->MinTime(1.0)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

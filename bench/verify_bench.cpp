// cfinspect's witness check (tools/cfgen/verify/record_check.hpp): every CF of a graph
// re-checked with cfgen's verify, on 1 and 2 threads. Reports CFs checked per second (the
// models' analysis, done once per graph, excluded; docs/performance.md, "Witness check").
//
//   build/bench/verify_bench
//   CF_VERIFY_BENCH_GRAPH=G.json build/bench/verify_bench   # another graph as well
// The graphs: data/graphs/*.json (cfgen's, shipped), and CF_VERIFY_BENCH_GRAPH when set.

#include "cfgen/execute/parallel.hpp"
#include "cfgen/generate.hpp"
#include "cfgen/verify/record_check.hpp"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace {

std::vector<std::string> graph_paths() {
  std::vector<std::string> out;
  for (const char* name : {"cube_l_block.json", "cube_corner_block.json", "peg_hole_block.json"})
    out.push_back(std::string(CF_SOURCE_DIR) + "/data/graphs/" + name);
  if (const char* env = std::getenv("CF_VERIFY_BENCH_GRAPH")) out.emplace_back(env);
  return out;
}

void BM_CheckRecords(benchmark::State& state, const std::string& path) {
  const int threads = static_cast<int>(state.range(0));
  const cf::CfGraph g = cf::CfGraph::load(path);
  const cf::gen::RecordCheck check(
      g, cf::tools::scaled_search(g.model_a(), g.model_b(), cf::tools::RelativeLengths{}));
  std::vector<std::string> why(g.num_cfs());
  for (auto _ : state) {
    cf::gen::parallel_for(g.num_cfs(), threads, [&](std::size_t i) {
      why[i] = check.check(g.cf(cf::CfId(static_cast<int>(i))));
    });
    benchmark::DoNotOptimize(why.data());
  }
  std::size_t failed = 0;
  for (const std::string& w : why) failed += w.empty() ? 0 : 1;
  if (failed > 0) state.SkipWithError("a record fails the check");
  state.counters["cfs"] = static_cast<double>(g.num_cfs());
  state.counters["cfs_per_s"] =
      benchmark::Counter(static_cast<double>(g.num_cfs()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}

const int kRegistered = [] {
  for (const std::string& path : graph_paths()) {
    if (!std::filesystem::exists(path)) continue;
    const std::string name = "BM_CheckRecords/" + std::filesystem::path(path).stem().string();
    benchmark::RegisterBenchmark(name.c_str(), BM_CheckRecords, path)
        ->ArgName("threads")
        ->Arg(1)
        ->Arg(2)
        ->UseRealTime()
        ->Unit(benchmark::kMillisecond);
  }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();

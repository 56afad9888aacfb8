// Loading a large CF graph: a synthetic graph of 100,000 CFs (a cube against an L-shaped
// block: every valid single PC, then two-PC CFs) with 4 transitions per two-PC CF, random
// full-precision witnesses (tests/support/synthetic_graph.hpp). Measures load() of JSON and
// CBOR, with and without the schema check, of a file of one's own (CF_GRAPH_BENCH_FILE), and
// find(). Figures go to docs/performance.md, "Graph loading".

#include <cf/graph.hpp>
#include "synthetic_graph.hpp"

#include <benchmark/benchmark.h>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

constexpr std::size_t kNumCfs = 100000;

struct Files {
  std::string json, cbor;
  std::size_t transitions = 0;
  Files() {
    const auto dir = std::filesystem::temp_directory_path();
    json = (dir / ("cf_graph_bench_" + std::to_string(::getpid()) + ".json")).string();
    cbor = (dir / ("cf_graph_bench_" + std::to_string(::getpid()) + ".cbor")).string();
    const cf::CfGraph g = cf::test::synthetic_graph(kNumCfs);
    transitions = g.num_transitions();
    g.save(json);
    g.save(cbor);
    // For profiling the reader outside the benchmark: CF_GRAPH_BENCH_OUT=/path/g.json
    if (const char* out = std::getenv("CF_GRAPH_BENCH_OUT")) g.save(out);
  }
  ~Files() {
    std::remove(json.c_str());
    std::remove(cbor.c_str());
  }
};

const Files& files() {
  static const Files f;
  return f;
}

void report(benchmark::State& state, const std::string& path) {
  state.counters["cfs"] = static_cast<double>(kNumCfs);
  state.counters["transitions"] = static_cast<double>(files().transitions);
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
}

// Loads `path` (JSON or CBOR by its name); argument 0: the schema check off or on.
void load(benchmark::State& state, const std::string& path) {
  cf::GraphLoadOptions options;
  options.validate_schema = state.range(0) != 0;
  for (auto _ : state) {
    cf::CfGraph g = cf::CfGraph::load(path, options);
    benchmark::DoNotOptimize(g.num_cfs());
  }
  report(state, path);
}

void BM_LoadJson(benchmark::State& state) { load(state, files().json); }
BENCHMARK(BM_LoadJson)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("schema")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

void BM_LoadCbor(benchmark::State& state) { load(state, files().cbor); }
BENCHMARK(BM_LoadCbor)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("schema")
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// A graph file of one's own, JSON or CBOR (CF_GRAPH_BENCH_FILE=/path/g.json; skipped without
// it): CGAL's star against its cross, 178 MB, is the figure of docs/performance.md.
void BM_LoadFile(benchmark::State& state) {
  const char* path = std::getenv("CF_GRAPH_BENCH_FILE");
  if (path == nullptr) {
    state.SkipWithError("CF_GRAPH_BENCH_FILE is not set");
    return;
  }
  cf::GraphLoadOptions options;
  options.validate_schema = state.range(0) != 0;
  std::size_t cfs = 0, transitions = 0;
  for (auto _ : state) {
    cf::CfGraph g = cf::CfGraph::load(path, options);
    cfs = g.num_cfs();
    transitions = g.num_transitions();
  }
  state.counters["cfs"] = static_cast<double>(cfs);
  state.counters["transitions"] = static_cast<double>(transitions);
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
}
BENCHMARK(BM_LoadFile)->Arg(0)->Arg(1)->ArgName("schema")->Unit(benchmark::kMillisecond);

void BM_Save(benchmark::State& state) {
  const cf::CfGraph g = cf::CfGraph::load(files().json);
  const std::string out = files().json + ".out.json";
  for (auto _ : state) g.save(out);
  std::remove(out.c_str());
}
BENCHMARK(BM_Save)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_Find(benchmark::State& state) {
  const cf::CfGraph g = cf::CfGraph::load(files().json);
  // Query the sets of every CF, in a scrambled order, built from PCs in reverse order.
  std::vector<cf::PcSet> queries;
  for (std::size_t i = 0; i < g.num_cfs(); i += 7)
    queries.push_back(g.cf(cf::CfId(static_cast<int>(i))).pcs);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(g.find(queries[k]));
    if (++k == queries.size()) k = 0;
  }
}
BENCHMARK(BM_Find);

}  // namespace

BENCHMARK_MAIN();

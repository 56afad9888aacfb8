// Loading a large CF graph: a synthetic graph of 100,000 CFs (a cube against an L-shaped
// block: every valid single PC, then two-PC CFs) with 4 transitions per two-PC CF, random
// full-precision witnesses. Measures load() of JSON and CBOR, with and without the schema
// check, and find(). Figures go to docs/performance.md, "Graph loading".

#include <cf/graph.hpp>
#include "fixtures.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

namespace {

bool share_plane(const cf::Pc& x, const cf::Pc& y) {
  using K = cf::ElementKind;
  return (cf::a_kind(x.type) == K::kFace && cf::a_kind(y.type) == K::kFace && x.a == y.a) ||
         (cf::b_kind(x.type) == K::kFace && cf::b_kind(y.type) == K::kFace && x.b == y.b);
}

cf::CfGraph synthetic_graph(std::size_t num_cfs) {
  const cf::Polyhedron a = cf::test::box(10, 10, 10, "cube"), b = cf::test::small_l_block();
  std::vector<cf::Pc> singles;
  for (int t = 0; t < 6; ++t) {
    const auto type = static_cast<cf::PcType>(t);
    auto count = [](const cf::Polyhedron& m, cf::ElementKind k) {
      return static_cast<int>(k == cf::ElementKind::kVertex ? m.num_vertices()
                              : k == cf::ElementKind::kEdge ? m.num_edges()
                                                            : m.num_faces());
    };
    for (int i = 0; i < count(a, cf::a_kind(type)); ++i)
      for (int j = 0; j < count(b, cf::b_kind(type)); ++j) singles.push_back({type, i, j});
  }
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-50, 50);
  auto witness = [&] {
    cf::Pose p;
    p.R_BA = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
                 .normalized()
                 .toRotationMatrix();
    p.t_BA = cf::Vec3(uniform(rng), uniform(rng), uniform(rng));
    return p;
  };
  std::vector<cf::CfRecord> cfs;
  std::vector<cf::Transition> transitions;
  for (const cf::Pc& p : singles) {
    cf::CfRecord r;
    r.pcs = cf::PcSet({p});
    r.witness = witness();
    cfs.push_back(r);
    if (cfs.size() == num_cfs) break;
  }
  for (std::size_t i = 0; i < singles.size() && cfs.size() < num_cfs; ++i)
    for (std::size_t j = i + 1; j < singles.size() && cfs.size() < num_cfs; ++j) {
      // A CF's PCs are principal: none on a plane another holds, none dominating another.
      if (share_plane(singles[i], singles[j]) || cf::dominates(a, b, singles[i], singles[j]) ||
          cf::dominates(a, b, singles[j], singles[i]))
        continue;
      cf::CfRecord r;
      r.pcs = cf::PcSet({singles[i], singles[j]});
      r.witness = witness();
      r.dof = 2;
      r.translation_dof = 1;
      const cf::CfId id(static_cast<int>(cfs.size()));
      cfs.push_back(r);
      const cf::CfId ci(static_cast<int>(i)), cj(static_cast<int>(j));
      transitions.push_back({ci, id, cf::TransitionKind::kGain});
      transitions.push_back({cj, id, cf::TransitionKind::kGain});
      transitions.push_back({id, ci, cf::TransitionKind::kLose});
      transitions.push_back({id, cj, cf::TransitionKind::kLose});
    }
  return cf::CfGraph::from_parts(a, b, std::move(cfs), std::move(transitions),
                                 R"({"stats":{"synthetic":true}})");
}

constexpr std::size_t kNumCfs = 100000;

struct Files {
  std::string json, cbor;
  std::size_t transitions = 0;
  Files() {
    const auto dir = std::filesystem::temp_directory_path();
    json = (dir / ("cf_graph_bench_" + std::to_string(::getpid()) + ".json")).string();
    cbor = (dir / ("cf_graph_bench_" + std::to_string(::getpid()) + ".cbor")).string();
    const cf::CfGraph g = synthetic_graph(kNumCfs);
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

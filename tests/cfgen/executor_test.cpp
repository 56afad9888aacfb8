// The execute layer (tools/cfgen/execute/executor.hpp) with a stand-in decide: no witness
// search at all, only a pure function of each task. Covers what the layer promises whatever
// the tasks mean: results by index whatever the thread count, slices and chunks, checkpoints
// and resume, stage numbering, other processes (a stand-in Distribute), and stopping.
#include "cfgen/execute/executor.hpp"
#include "cfgen/execute/shard.hpp"

#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

using cf::gen::Decide;
using cf::gen::ExecuteOptions;
using cf::gen::Executor;
using cf::gen::Stage;
using cf::gen::Task;
using cf::gen::TaskResult;

namespace {

// Task i of every stage in these tests: a single v-f PC whose indices encode i.
Task task_for(std::size_t i) {
  Task t;
  t.pcs = cf::PcSet(
      {cf::Pc{cf::PcType::kVF, static_cast<int>(i % 100000), static_cast<int>(i / 100000)}});
  t.pose.t_BA = cf::Vec3(static_cast<double>(i), 0, 0);
  return t;
}

// The stand-in decide: a pure function of the task, so the expected result of every task is
// known; counts its calls.
struct StandIn {
  std::atomic<std::size_t> calls{0};
  TaskResult operator()(const Task& t) {
    ++calls;
    TaskResult r;
    const double i = t.pose.t_BA.x();
    r.witness.found = static_cast<std::size_t>(i) % 3 != 0;
    r.witness.clearance = 0.5 * i;
    r.witness.pose.t_BA = cf::Vec3(i, 2 * i, -i);
    if (static_cast<std::size_t>(i) % 5 == 0) r.met.push_back({t.pcs, r.witness.pose});
    return r;
  }
  Decide decide() {
    return [this](const Task& t) { return (*this)(t); };
  }
};

// A witness not found carries nothing else (a checkpoint keeps only that it was not found).
bool same(const TaskResult& x, const TaskResult& y) {
  if (x.witness.found != y.witness.found || x.met.size() != y.met.size()) return false;
  return !x.witness.found ||
         (x.witness.clearance == y.witness.clearance && x.witness.pose.t_BA == y.witness.pose.t_BA);
}

// Runs one stage of n tasks; results by index, and the order take() saw them in.
std::vector<TaskResult> run_stage(Executor& ex, std::size_t n,
                                  std::vector<std::size_t>* order = nullptr) {
  std::vector<TaskResult> out(n);
  Stage s;
  s.size = n;
  s.make = task_for;
  s.take = [&](std::size_t i, TaskResult&& r) {
    out[i] = std::move(r);
    if (order) order->push_back(i);
  };
  ex.run(s);
  return out;
}

void check_results(const std::vector<TaskResult>& got) {
  StandIn reference;
  for (std::size_t i = 0; i < got.size(); ++i) {
    INFO("task " << i);
    CHECK(same(got[i], reference(task_for(i))));
  }
}

// A checkpoint in memory: chunks by (stage, chunk), with the tasks they were made from.
struct MemoryStore {
  std::mutex m;
  std::map<std::pair<std::size_t, std::size_t>,
           std::pair<std::vector<Task>, std::vector<TaskResult>>>
      kept;
  cf::gen::ChunkStore store() {
    cf::gen::ChunkStore s;
    s.load = [this](std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                    std::vector<TaskResult>& out) {
      std::lock_guard<std::mutex> lock(m);
      auto it = kept.find({stage, chunk});
      if (it == kept.end()) return false;
      // Not a Catch2 assertion: the shards' threads call this (Catch2 is not thread-safe).
      if (it->second.first.size() != tasks.size())
        throw std::logic_error("a kept chunk of other tasks");
      out = it->second.second;
      return true;
    };
    s.save = [this](std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                    const std::vector<TaskResult>& r) {
      std::lock_guard<std::mutex> lock(m);
      kept[{stage, chunk}] = {tasks, r};
    };
    return s;
  }
};

// Options of a run on `threads` threads that keeps its chunks in `mem`, as shard `shard`.
ExecuteOptions kept_in(MemoryStore& mem, int threads, cf::gen::ShardSpec shard = {}) {
  ExecuteOptions o;
  o.threads = threads;
  o.checkpoint = mem.store();
  o.shard = shard;
  return o;
}

}  // namespace

TEST_CASE("chunks: about 64 a stage, 8 to 1024 tasks each, fixed by the stage's size",
          "[execute]") {
  CHECK(cf::gen::chunk_size(0) == 8);
  CHECK(cf::gen::chunk_size(100) == 8);     // 100 / 64 rounds up to 2, below the floor
  CHECK(cf::gen::chunk_size(6400) == 100);  // 64 chunks
  CHECK(cf::gen::chunk_size(6401) == 101);
  CHECK(cf::gen::chunk_size(10000000) == 1024);
}

TEST_CASE("a stage's results come by index and in task order, whatever the thread count",
          "[execute]") {
  // 70,000 tasks: more than one slice (32,768) without a checkpoint.
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{9}, std::size_t{70000}})
    for (const int threads : {1, 2, 4}) {
      INFO(n << " tasks on " << threads << " threads");
      StandIn d;
      ExecuteOptions o;
      o.threads = threads;
      Executor ex(d.decide(), o);
      std::vector<std::size_t> order;
      check_results(run_stage(ex, n, &order));
      CHECK(d.calls == n);
      for (std::size_t i = 0; i < order.size(); ++i) REQUIRE(order[i] == i);
      CHECK(ex.stages() == 1);
    }
}

TEST_CASE("a checkpoint keeps every chunk of every stage, and a rerun takes them without deciding",
          "[execute]") {
  MemoryStore mem;
  ExecuteOptions o = kept_in(mem, 2);
  {
    StandIn d;
    Executor ex(d.decide(), o);
    check_results(run_stage(ex, 1000));  // 16 tasks a chunk: 63 chunks
    check_results(run_stage(ex, 20));    // stage 1: 3 chunks of 8
    CHECK(d.calls == 1020);
    CHECK(ex.stages() == 2);
  }
  CHECK(mem.kept.size() == 63 + 3);
  CHECK(mem.kept.count({1, 2}) == 1);
  CHECK(mem.kept.count({1, 3}) == 0);
  CHECK(mem.kept.at({1, 2}).first.size() == 4);  // the last chunk holds the rest
  // Resumed: nothing decided again.
  StandIn d;
  Executor ex(d.decide(), o);
  check_results(run_stage(ex, 1000));
  check_results(run_stage(ex, 20));
  CHECK(d.calls == 0);
  CHECK(ex.resumed_chunks() == 66);
  // A chunk lost is decided again, alone.
  mem.kept.erase({0, 5});
  StandIn again;
  Executor ex2(again.decide(), o);
  check_results(run_stage(ex2, 1000));
  CHECK(again.calls == 16);
}

// A stage of the enumeration's own items: item i's result names i; `who` records the shard
// (index + 1) that computed each item.
Stage own_items(std::size_t n, std::vector<std::size_t>& seen, std::vector<std::atomic<int>>& who,
                int shard) {
  Stage s;
  s.size = n;
  s.make = task_for;
  s.compute = [&who, shard](std::size_t i) {
    who[i] = shard + 1;
    TaskResult r;
    r.sets.push_back(task_for(i).pcs);
    return r;
  };
  s.take = [&seen](std::size_t i, TaskResult&& r) {
    if (r.sets.size() == 1 && r.sets[0] == task_for(i).pcs) seen.push_back(i);
  };
  s.chunk = 100;
  s.owner_key = 7;
  return s;
}

TEST_CASE(
    "the enumeration's own items are computed here, never decided; shards split them in chunks "
    "that keep their shard from stage to stage",
    "[execute][shard]") {
  {
    // One process with a checkpoint: computed on its threads, in order, nothing kept.
    MemoryStore mem;
    StandIn d;
    ExecuteOptions o = kept_in(mem, 3);
    Executor ex(d.decide(), o);
    std::vector<std::size_t> seen;
    std::vector<std::atomic<int>> who(1000);
    ex.run(own_items(1000, seen, who, 0));
    REQUIRE(seen.size() == 1000);
    for (std::size_t i = 0; i < seen.size(); ++i) REQUIRE(seen[i] == i);
    CHECK(d.calls == 0);
    CHECK(mem.kept.empty());
  }
  // Two shards, two stages of the same owner key, the second larger (a list that grew): chunk
  // k (items 100 k to 100 k + 99) is shard (k + 7) mod 2's in both.
  MemoryStore mem;
  const std::size_t sizes[] = {1000, 1550};
  std::vector<std::atomic<int>> who[2] = {std::vector<std::atomic<int>>(1000),
                                          std::vector<std::atomic<int>>(1550)};
  std::vector<std::size_t> seen[2][2];
  std::vector<std::thread> shards;
  for (int k = 0; k < 2; ++k)
    shards.emplace_back([&, k] {
      StandIn d;
      ExecuteOptions o = kept_in(mem, 1, {k, 2});
      Executor ex(d.decide(), o);
      for (int st = 0; st < 2; ++st) ex.run(own_items(sizes[st], seen[k][st], who[st], k));
    });
  for (auto& t : shards) t.join();
  for (int st = 0; st < 2; ++st) {
    for (int k = 0; k < 2; ++k) CHECK(seen[k][st].size() == sizes[st]);  // each sees all
    for (std::size_t i = 0; i < sizes[st]; ++i) {
      INFO("stage " << st << ", item " << i);
      REQUIRE(who[st][i] == static_cast<int>((i / 100 + 7) % 2) + 1);
    }
  }
}

TEST_CASE(
    "a stopped run throws Stopped and keeps exactly its finished chunks; the rerun completes it",
    "[execute]") {
  MemoryStore mem;
  cf::gen::StopFlag stop{false};
  ExecuteOptions o = kept_in(mem, 2);
  o.stop = &stop;
  // The stand-in asks to stop in the middle of the stage (its 500th task).
  std::atomic<std::size_t> calls{0};
  Decide stopping = [&](const Task& t) {
    if (++calls == 500) stop = true;
    StandIn d;
    return d(t);
  };
  {
    Executor ex(stopping, o);
    CHECK_THROWS_AS(run_stage(ex, 2000), cf::gen::Stopped);  // 32 a chunk
  }
  // Chunks end before task 500 at the latest; the one in hand when the flag was set is not kept,
  // and no chunk after it was started.
  CHECK(mem.kept.size() >= 480 / 32);
  CHECK(mem.kept.size() <= 500 / 32);
  for (const auto& [key, chunk] : mem.kept) CHECK(chunk.second.size() == 32);
  const std::size_t kept = mem.kept.size();
  // Stopped before the next stage starts: nothing decided.
  {
    StandIn d;
    Executor ex(d.decide(), o);
    CHECK_THROWS_AS(run_stage(ex, 10), cf::gen::Stopped);
    CHECK(d.calls == 0);
  }
  stop = false;
  StandIn d;
  Executor ex(d.decide(), o);
  check_results(run_stage(ex, 2000));
  CHECK(ex.resumed_chunks() == kept);
  CHECK(d.calls == 2000 - 32 * kept);
}

TEST_CASE("for_each runs every index on every thread, and stops between indices", "[execute]") {
  StandIn d;
  cf::gen::StopFlag stop{false};
  ExecuteOptions o;
  o.threads = 3;
  o.stop = &stop;
  Executor ex(d.decide(), o);
  std::vector<int> hit(1000, 0);
  ex.for_each(hit.size(), [&](std::size_t i) { ++hit[i]; });
  CHECK(std::count(hit.begin(), hit.end(), 1) == 1000);
  CHECK(ex.stages() == 0);  // not a stage: no chunk, no checkpoint
  std::atomic<std::size_t> ran{0};
  CHECK_THROWS_AS(ex.for_each(1000,
                              [&](std::size_t) {
                                if (++ran == 10) stop = true;
                              }),
                  cf::gen::Stopped);
  CHECK(ran < 1000);
}

TEST_CASE("progress: ticks count the stage's finished tasks, chunk by chunk with a checkpoint",
          "[execute]") {
  MemoryStore mem;
  std::vector<cf::gen::ProgressEvent> seen;
  ExecuteOptions o = kept_in(mem, 1);
  o.progress = [&](const cf::gen::ProgressEvent& e) { seen.push_back(e); };
  StandIn d;
  Executor ex(d.decide(), o);
  cf::gen::ProgressEvent ev{"level 1", "candidate sets", 0, 100, 0, false, {}};
  Stage s;
  s.size = 100;
  s.make = task_for;
  s.take = [](std::size_t, TaskResult&&) {};
  s.progress = &ev;
  s.started = cf::gen::Clock::now();
  ex.run(s);
  // 13 chunks of 8: one event after each, the last at 100 of 100.
  REQUIRE(seen.size() >= 13);
  CHECK(seen.back().done == 100);
  for (std::size_t k = 1; k < seen.size(); ++k) CHECK(seen[k].done >= seen[k - 1].done);
}

TEST_CASE(
    "a checkpoint directory keeps the chunks a stopped run finished, and the rerun resumes from "
    "them",
    "[execute][checkpoint]") {
  namespace fs = std::filesystem;
  const fs::path dir = cf::test::scratch() / "stopped.ckpt";
  const std::string model =
      cf::test::write_file("stopped_model.off", "OFF\n");  // an input never overwritten
  cf::gen::StopFlag stop{false};
  std::atomic<std::size_t> calls{0};
  Decide stopping = [&](const Task& t) {
    if (++calls == 95) stop = true;
    StandIn d;
    return d(t);
  };
  ExecuteOptions o;
  o.threads = 1;
  o.stop = &stop;
  o.checkpoint = cf::tools::open_checkpoint(dir.string(), "0123456789abcdef", {model});
  {
    Executor ex(stopping, o);
    CHECK_THROWS_AS(run_stage(ex, 640), cf::gen::Stopped);  // 10 a chunk
  }
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir))
    files += e.path().filename().string().rfind("stage", 0) == 0;
  CHECK(files == 9);  // the chunks before task 95 (one thread: in order); the tenth was in hand
  stop = false;
  StandIn d;
  o.checkpoint = cf::tools::open_checkpoint(dir.string(), "0123456789abcdef", {model});
  Executor ex(d.decide(), o);
  check_results(run_stage(ex, 640));
  CHECK(ex.resumed_chunks() == 9);
  CHECK(d.calls == 550);
  // Another run's checkpoint is refused, naming the directory.
  CHECK_THROWS_WITH(
      cf::tools::open_checkpoint(dir.string(), "fedcba9876543210", {model}),
      Catch::Contains("'" + dir.string() + "' was made from other models or options"));
}

TEST_CASE("shards that share a checkpoint split every stage and each sees every result",
          "[execute][shard]") {
  // Three shards on threads of their own, one store between them (a directory on shared
  // storage in a real run): each decides only its chunks, (chunk + stage) mod 3, and waits
  // for the others'.
  MemoryStore mem;
  constexpr int kShards = 3;
  const std::size_t sizes[] = {1000, 20, 8, 1, 333};  // stages of 63, 3, 1, 1 and 42 chunks
  std::vector<std::size_t> calls(kShards);
  std::vector<std::vector<std::vector<TaskResult>>> got(kShards);
  std::vector<std::thread> shards;
  for (int i = 0; i < kShards; ++i)
    shards.emplace_back([&, i] {
      StandIn d;
      ExecuteOptions o = kept_in(mem, 1, {i, kShards});
      Executor ex(d.decide(), o);
      for (std::size_t n : sizes) got[i].push_back(run_stage(ex, n));
      calls[i] = d.calls;
    });
  for (auto& t : shards) t.join();
  std::size_t total = 0;
  for (int i = 0; i < kShards; ++i) {
    for (const auto& r : got[i]) check_results(r);
    total += calls[i];
    CHECK(calls[i] > 0);  // the single-chunk stages too spread over the shards
  }
  CHECK(total == 1000 + 20 + 8 + 1 + 333);  // every task decided once
  // A shard without a checkpoint is refused.
  ExecuteOptions bad;
  bad.shard = {1, 2};
  StandIn d;
  CHECK_THROWS_WITH(
      Executor(d.decide(), bad),
      "a shard (1/2) needs a checkpoint directory that every shard sees (--checkpoint DIR)");
}

TEST_CASE(
    "a shard alone finishes the run: the chunks of a shard that never comes are computed after the "
    "patience",
    "[execute][shard]") {
  MemoryStore mem;
  StandIn d;
  ExecuteOptions o = kept_in(mem, 1, {0, 2});
  o.shard_patience = 0.05;  // s
  Executor ex(d.decide(), o);
  check_results(run_stage(ex, 100));  // 13 chunks, 6 of them shard 1's
  check_results(run_stage(ex, 24));   // 3 chunks, 2 of them shard 1's (the first and the last)
  CHECK(d.calls == 124);
  CHECK(ex.taken_over_chunks() == 8);
  CHECK(ex.shared_chunks() == 0);
  CHECK(mem.kept.size() == 16);  // kept for a rerun like any other chunk
}

#include "enumerate.hpp"

#include "explore.hpp"
#include "pair_conditions.hpp"
#include "symmetry.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <unordered_set>

namespace cf::gen {
namespace {

using Clock = std::chrono::steady_clock;

// Vertices within this fraction of the length scale D match under a symmetry: far below the
// touch tolerance (2e-11 D by default), so an image witness is verified as the witness was.
constexpr double kSymmetryTol = 1e-13;
// Members of an orbit searched before it counts as failed: each meets the search's fixed
// samples differently. On the hexagonal peg and hole 2 find 13 orbits more than 1 (4 no more
// than 2); on the square pair 4 find 2 more than 2.
constexpr std::size_t kOrbitTries = 4;
// Witnesses explored by motion per orbit a round adds: the one found, and those found by
// their own searches for up to three more members, spread over the orbit. Motion from one
// witness reaches what its place in the CF's region allows; the images of that witness reach
// the images of the same. On the hexagonal pair 4 find 13 orbits more than 1 at 17% more
// time, 16 one more than 4.
constexpr std::size_t kWitnessesPerOrbit = 4;
// Witnesses of neighbouring CFs a failed set is searched again from, after the fixed point.
constexpr std::size_t kNeighbourSeeds = 16;

struct PcSetHash {
  std::size_t operator()(const PcSet& s) const { return s.hash(); }
};

// Candidate sets grouped by orbit: orbit o is members[first[o], first[o + 1]).
struct OrbitGroups {
  std::vector<PcSet> members;
  std::vector<std::size_t> first;
  std::size_t size() const { return first.empty() ? 0 : first.size() - 1; }
  std::size_t count(std::size_t o) const { return first[o + 1] - first[o]; }
  const PcSet& member(std::size_t o, std::size_t k) const { return members[first[o] + k]; }
};

int element_count(const Polyhedron& m, ElementKind k) {
  return static_cast<int>(k == ElementKind::kVertex ? m.num_vertices()
                          : k == ElementKind::kEdge ? m.num_edges()
                                                    : m.num_faces());
}

// Runs fn(i) for i in [0, n) on `threads` threads; results are written by index, so the
// output does not depend on the thread count.
void parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn,
                  const std::function<void(std::size_t)>& tick) {
  std::atomic<std::size_t> next{0}, done{0};
  auto work = [&] {
    for (std::size_t i; (i = next++) < n;) {
      fn(i);
      ++done;
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(work);
  // The reporter ticks every 250 ms and is woken at the end, so a short loop costs no wait.
  std::thread reporter;
  std::mutex m;
  std::condition_variable cv;
  bool stop = false;
  if (tick)
    reporter = std::thread([&] {
      std::unique_lock<std::mutex> lock(m);
      while (!cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return stop; })) {
        lock.unlock();
        tick(done.load());
        lock.lock();
      }
    });
  work();
  for (auto& t : pool) t.join();
  {
    std::lock_guard<std::mutex> lock(m);
    stop = true;
  }
  cv.notify_one();
  if (reporter.joinable()) reporter.join();
}

}  // namespace

TaskResult run_task(const WitnessSearch& search, const Task& task) {
  TaskResult r;
  switch (task.kind) {
    case Task::Kind::kFind:
      r.witness = search.find(task.pcs, task.seeds);
      break;
    case Task::Kind::kFindNear:
      r.witness = search.find(task.pcs, task.seeds, true);
      break;
    case Task::Kind::kFindOrRefine:
      r.witness = search.find(task.pcs, {task.pose.R_BA});
      if (!r.witness.found) r.witness = search.refine(task.pcs, task.pose);
      break;
    case Task::Kind::kExplore: {
      r.met = explore_translations(search, task.pcs, task.pose);
      std::vector<Discovery> more = explore_rotations(search, task.pcs, task.pose);
      r.met.insert(r.met.end(), more.begin(), more.end());
      for (const Pose& q : turned_witnesses(search, task.pcs, task.pose)) {
        more = explore_translations(search, task.pcs, q);
        r.met.insert(r.met.end(), more.begin(), more.end());
      }
      break;
    }
  }
  return r;
}

std::vector<TaskResult> run_tasks(const WitnessSearch& search, const std::vector<Task>& tasks, int threads,
                                  const std::function<void(std::size_t)>& tick) {
  if (threads <= 0) threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<TaskResult> out(tasks.size());
  parallel_for(tasks.size(), threads, [&](std::size_t i) { out[i] = run_task(search, tasks[i]); }, tick);
  return out;
}

std::size_t chunk_size(std::size_t tasks) {
  // About 64 chunks a stage: enough to share among processes and to lose little when killed,
  // few enough files; at most 1024 tasks (about a minute of the slowest searches) a chunk.
  constexpr std::size_t kChunks = 64, kMin = 8, kMax = 1024;
  return std::clamp<std::size_t>((tasks + kChunks - 1) / kChunks, kMin, kMax);
}

std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B, int threads) {
  std::unordered_map<PcSet, int, PcSetHash> index;
  for (std::size_t i = 0; i < cfs.size(); ++i) index.emplace(cfs[i].pcs, static_cast<int>(i));
  // Every PC's neighbours, computed once before the CFs are shared out among the threads.
  std::map<Pc, std::vector<Pc>> nb;
  for (const CfRecord& r : cfs)
    for (const Pc& pc : r.pcs)
      if (!nb.count(pc)) nb.emplace(pc, cf::neighbouring_pcs(pc, A, B));
  // The CFs that hold each PC, by CF size.
  std::array<std::map<Pc, std::vector<int>>, PcSet::kMaxPcs + 1> holding;
  for (std::size_t i = 0; i < cfs.size(); ++i)
    for (const Pc& pc : cfs[i].pcs)
      holding[static_cast<std::size_t>(cfs[i].pcs.size())][pc].push_back(static_cast<int>(i));
  // Each CF's transitions on its own, joined in CF order (then sorted).
  std::vector<std::vector<Transition>> per_cf(cfs.size());
  parallel_for(
      cfs.size(),
      threads <= 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency())) : threads,
      [&](std::size_t i) {
        std::vector<Transition>& mine = per_cf[i];
        auto push = [&](int from, int to, TransitionKind k) {
          mine.push_back({CfId(from), CfId(to), k});
        };
        const PcSet& s = cfs[i].pcs;
        const int me = static_cast<int>(i);
        // gain / lose: drop one PC of a larger CF.
        if (s.size() > 1)
          for (int k = 0; k < s.size(); ++k) {
            PcSet sub;
            for (int j = 0; j < s.size(); ++j)
              if (j != k) sub.insert(s[j]);
            auto it = index.find(sub);
            if (it != index.end()) {
              push(it->second, me, TransitionKind::kGain);
              push(me, it->second, TransitionKind::kLose);
            }
          }
        // change: replace one or more PCs by neighbouring PCs, keeping the count: the CFs of
        // this size whose PCs match s's positions one to one, each the same PC or a neighbour.
        // They all hold some option of the position with the fewest, so only the CFs holding
        // one of those are tried.
        const int n = s.size();
        if (n == 0) return;
        std::vector<std::vector<Pc>> options(static_cast<std::size_t>(n));
        std::size_t best = 0, best_count = std::numeric_limits<std::size_t>::max();
        for (int k = 0; k < n; ++k) {
          auto& o = options[static_cast<std::size_t>(k)];
          o.push_back(s[k]);
          for (const Pc& q : nb.at(s[k])) o.push_back(q);
          std::sort(o.begin(), o.end());
          std::size_t count = 0;
          for (const Pc& q : o)
            if (auto it = holding[static_cast<std::size_t>(n)].find(q);
                it != holding[static_cast<std::size_t>(n)].end())
              count += it->second.size();
          if (count < best_count) best = static_cast<std::size_t>(k), best_count = count;
        }
        auto matches = [&](const PcSet& t) {
          std::array<int, PcSet::kMaxPcs> perm{0, 1, 2};
          do {
            bool all = true;
            for (int k = 0; k < n && all; ++k) {
              const auto& o = options[static_cast<std::size_t>(k)];
              all = std::binary_search(o.begin(), o.end(), t[perm[static_cast<std::size_t>(k)]]);
            }
            if (all) return true;
          } while (std::next_permutation(perm.begin(), perm.begin() + n));
          return false;
        };
        for (const Pc& q : options[best]) {
          auto it = holding[static_cast<std::size_t>(n)].find(q);
          if (it == holding[static_cast<std::size_t>(n)].end()) continue;
          for (int j : it->second)
            if (j != me && matches(cfs[static_cast<std::size_t>(j)].pcs))
              push(me, j, TransitionKind::kChange);
        }
      },
      {});
  std::vector<Transition> out;
  for (const auto& v : per_cf) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end(), [](const Transition& x, const Transition& y) {
    if (x.from != y.from) return x.from < y.from;
    if (x.to != y.to) return x.to < y.to;
    return x.kind < y.kind;
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const Transition& x, const Transition& y) {
                          return x.from == y.from && x.to == y.to && x.kind == y.kind;
                        }),
            out.end());
  return out;
}

Enumeration enumerate(const ModelInfo& Ai, const ModelInfo& Bi, const EnumerateOptions& opt) {
  const Polyhedron& A = *Ai.model;
  const Polyhedron& B = *Bi.model;
  const WitnessSearch search(Ai, Bi, opt.search);
  const int threads = opt.threads > 0 ? opt.threads
                                      : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  Enumeration out;
  std::vector<std::pair<PcSet, Witness>> valid[3];
  std::vector<PcSet> failed;  // candidates the search found no witness for

  // Every set that reached the witness search or was found valid: nothing is searched twice.
  std::unordered_set<PcSet, PcSetHash> seen;
  std::unordered_map<PcSet, Mat3, PcSetHash> witness_rot;  // seeds for the sets above them
  std::vector<std::pair<PcSet, Pose>> frontier;             // valid sets not explored by motion yet
  // The models' symmetries: a valid set's images are valid, at the image of its witness.
  const PairSymmetries sym(A, B, kSymmetryTol * search.scale(), opt.use_symmetry);
  out.symmetries_a = sym.size_a();
  out.symmetries_b = sym.size_b();
  // A set found valid, and the images of it that are not known yet, each verified at the image
  // of the witness (symmetric to rounding). Only the set found is explored by motion: its
  // images' motions are the images of its own.
  auto accept = [&](int level, const PcSet& s, const Witness& w) {
    valid[level].push_back({s, w});
    witness_rot.emplace(s, w.pose.R_BA);
    frontier.push_back({s, w.pose});
    for (std::size_t k = 1; k < sym.size(); ++k) {
      const PcSet t = sym.image(s, k);
      if (witness_rot.count(t)) continue;
      Witness v = w;
      v.pose = sym.image(w.pose, k);
      v.clearance = search.verify(t, v.pose);
      if (v.clearance < opt.search.min_clearance) continue;
      valid[level].push_back({t, v});
      witness_rot.emplace(t, v.pose.R_BA);
      seen.insert(t);
      ++out.levels[level].by_symmetry;
    }
  };
  // The candidates grouped by orbit, each orbit's members in candidate order, the orbits in
  // the order of their first member. Flat (members, and where each orbit starts), and built
  // from the candidates it takes with one copy: a large pair has tens of millions of them,
  // hundreds of MB.
  auto orbits_of = [&](std::vector<PcSet> cands) {
    OrbitGroups g;
    if (sym.size() == 1) {
      g.members = std::move(cands);
      g.first.resize(g.members.size() + 1);
      for (std::size_t i = 0; i < g.first.size(); ++i) g.first[i] = i;
      return g;
    }
    // Each candidate's orbit, numbered as first met. Every image of each orbit met so far is
    // entered with its number: one pass over the symmetries per orbit, not per candidate.
    std::vector<std::size_t> orbit(cands.size());
    std::size_t orbits = 0;
    std::unordered_map<PcSet, std::size_t, PcSetHash> orbit_of;
    for (std::size_t i = 0; i < cands.size(); ++i) {
      auto it = orbit_of.find(cands[i]);
      if (it == orbit_of.end()) {
        for (std::size_t k = 0; k < sym.size(); ++k) orbit_of.emplace(sym.image(cands[i], k), orbits);
        ++orbits;
        it = orbit_of.find(cands[i]);
      }
      orbit[i] = it->second;
    }
    // Counting sort by orbit, stable: the members of orbit o at [first[o], first[o + 1]).
    g.first.assign(orbits + 1, 0);
    for (std::size_t o : orbit) ++g.first[o + 1];
    for (std::size_t o = 1; o <= orbits; ++o) g.first[o] += g.first[o - 1];
    std::vector<std::size_t> next(g.first.begin(), g.first.end() - 1);
    g.members.resize(cands.size());
    for (std::size_t i = 0; i < cands.size(); ++i) g.members[next[orbit[i]]++] = cands[i];
    return g;
  };

  // Progress: ticks while a stage runs, one event when it ends.
  auto ticker = [&](ProgressEvent& ev, Clock::time_point t0) -> std::function<void(std::size_t)> {
    if (!opt.progress) return {};
    return [&ev, t0, &opt](std::size_t done) {
      ev.done = done;
      ev.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      opt.progress(ev);
    };
  };
  auto finished = [&](ProgressEvent& ev, Clock::time_point t0, const std::string& result) {
    if (!opt.progress) return;
    ev.done = ev.total;
    ev.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    ev.finished = true;
    ev.result = result;
    opt.progress(ev);
  };
  int motion_rounds = 0;
  int neighbour_rounds = 0;
  bool first_pair_round = true;  // the first level-2 round (the one --shard splits)

  // Every stage of the run, in order: its n tasks cut into chunks, each found in the
  // checkpoint, computed here or handed to another process, and kept when done. make(i) gives
  // task i and take(i, r) receives its result, in task order; the tasks are made a chunk (or,
  // without a checkpoint, a slice of kSliceTasks) at a time, so that a stage of millions of
  // candidates holds only the tasks in flight (under MPI, a window of chunks). The callers'
  // tasks do not depend on what take has seen in the same stage.
  std::size_t stages = 0;
  // ev: where progress goes, null for none.
  auto run_stage_made = [&](std::size_t n, const std::function<Task(std::size_t)>& make,
                            const std::function<void(std::size_t, TaskResult&&)>& take, ProgressEvent* ev,
                            Clock::time_point t0) {
    const std::size_t stage = stages++;
    const bool report = ev && opt.progress;
    std::size_t done = 0;  // tasks finished, for the progress
    auto tick = [&](std::size_t d) {
      if (!report) return;
      ev->done = done + d;
      ev->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      opt.progress(*ev);
    };
    auto make_range = [&](std::size_t b, std::size_t e) {
      std::vector<Task> tasks;
      tasks.reserve(e - b);
      for (std::size_t i = b; i < e; ++i) tasks.push_back(make(i));
      return tasks;
    };
    auto take_range = [&](std::size_t b, std::vector<TaskResult>& r) {
      for (std::size_t i = 0; i < r.size(); ++i) take(b + i, std::move(r[i]));
    };
    if (!opt.checkpoint.load && !opt.distribute) {
      constexpr std::size_t kSliceTasks = std::size_t{1} << 15;
      for (std::size_t b = 0; b < n; b += kSliceTasks) {
        const std::size_t e = std::min(n, b + kSliceTasks);
        std::vector<TaskResult> r =
            run_tasks(search, make_range(b, e), threads, report ? std::function<void(std::size_t)>(tick) : nullptr);
        done += r.size();
        take_range(b, r);
      }
      return;
    }
    const std::size_t size = chunk_size(n), count = (n + size - 1) / size;
    auto check = [&](std::size_t k, const std::vector<Task>& tasks, const std::vector<TaskResult>& r) {
      if (r.size() != tasks.size())
        throw Error("stage " + std::to_string(stage) + ", chunk " + std::to_string(k) + ": " +
                    std::to_string(r.size()) + " results for " + std::to_string(tasks.size()) + " tasks");
    };
    // Under MPI, windows of chunks are handed out in turn (their results taken between
    // windows, on this thread): every chunk of a window is made at once.
    constexpr std::size_t kWindowChunks = 256;
    const std::size_t window = opt.distribute ? kWindowChunks : 1;
    for (std::size_t w0 = 0; w0 < count; w0 += window) {
      const std::size_t w1 = std::min(count, w0 + window);
      std::vector<std::vector<Task>> chunks;
      for (std::size_t k = w0; k < w1; ++k) chunks.push_back(make_range(k * size, std::min(n, (k + 1) * size)));
      std::vector<std::vector<TaskResult>> res(chunks.size());
      std::vector<std::size_t> todo;  // within the window
      for (std::size_t j = 0; j < chunks.size(); ++j) {
        if (opt.checkpoint.load && opt.checkpoint.load(stage, w0 + j, chunks[j], res[j])) done += chunks[j].size();
        else todo.push_back(j);
      }
      auto finish = [&](std::size_t j, std::vector<TaskResult>&& r) {
        check(w0 + j, chunks[j], r);
        if (opt.checkpoint.save) opt.checkpoint.save(stage, w0 + j, chunks[j], r);
        res[j] = std::move(r);
        done += chunks[j].size();
        tick(0);
      };
      if (opt.distribute) {
        // Progress then moves chunk by chunk, from the thread that takes them.
        if (!todo.empty())
          opt.distribute(chunks, todo, [&](std::size_t j) { return run_tasks(search, chunks[j], threads); }, finish);
      } else {
        for (std::size_t j : todo)
          finish(j, run_tasks(search, chunks[j], threads, report ? std::function<void(std::size_t)>(tick) : nullptr));
      }
      for (std::size_t j = 0; j < chunks.size(); ++j) take_range((w0 + j) * size, res[j]);
    }
  };
  auto run_stage = [&](const std::vector<Task>& tasks, ProgressEvent* ev, Clock::time_point t0) {
    std::vector<TaskResult> results(tasks.size());
    run_stage_made(
        tasks.size(), [&](std::size_t i) { return tasks[i]; },
        [&](std::size_t i, TaskResult&& r) { results[i] = std::move(r); }, ev, t0);
    return results;
  };

  // given: results computed elsewhere (the shards of the first level-2 round), one per candidate.
  auto run_level = [&](int level, std::vector<PcSet> all,
                       const std::function<std::vector<Mat3>(const PcSet&)>& seeds_of,
                       const std::vector<Witness>* given = nullptr) {
    const auto t0 = Clock::now();
    // One search per orbit: the others follow from its witness. The search samples, and an
    // orbit's members meet its samples differently, so a failed orbit is searched again at
    // its next members, up to kOrbitTries.
    const OrbitGroups orbits = orbits_of(std::move(all));
    std::vector<char> done(orbits.size(), 0);
    std::size_t searched = 0;
    const std::size_t before = valid[level].size();
    ProgressEvent ev{
        "level " + std::to_string(level + 1), "candidate sets", 0, orbits.size(), 0, false, {}};
    for (std::size_t attempt = 0; attempt < kOrbitTries; ++attempt) {
      std::vector<std::size_t> open;
      for (std::size_t o = 0; o < orbits.size(); ++o) {
        if (done[o] || attempt >= orbits.count(o)) continue;
        if (witness_rot.count(orbits.member(o, attempt))) {
          done[o] = 1;  // an image of a CF found meanwhile
          continue;
        }
        open.push_back(o);
      }
      if (open.empty()) break;
      auto take = [&](std::size_t i, const Witness& w) {
        const PcSet& s = orbits.member(open[i], attempt);
        seen.insert(s);
        if (w.found) accept(level, s, w), done[open[i]] = 1;
      };
      if (attempt == 0 && given) {
        if (given->size() != open.size())
          throw Error("merging shards: the parts hold " + std::to_string(given->size()) +
                      " results of the first level-2 round, but these models and options give " +
                      std::to_string(open.size()) + " candidates");
        for (std::size_t i = 0; i < open.size(); ++i) take(i, (*given)[i]);
        ++stages;
      } else {
        // Seeds come from the sets below this level, which the results of this stage do not
        // change: the tasks are the same whenever they are made.
        ev.total = open.size();
        run_stage_made(
            open.size(),
            [&](std::size_t i) {
              Task t;
              t.kind = Task::Kind::kFind;
              t.pcs = orbits.member(open[i], attempt);
              t.seeds = seeds_of(t.pcs);
              return t;
            },
            [&](std::size_t i, TaskResult&& r) { take(i, r.witness); }, attempt == 0 ? &ev : nullptr, t0);
      }
      searched += open.size();
    }
    // Members of found orbits whose image witness did not verify (rounding at a borderline
    // pose): searched like any other set.
    std::vector<Task> rest;
    for (std::size_t o = 0; o < orbits.size(); ++o)
      if (done[o])
        for (std::size_t k = 0; k < orbits.count(o); ++k)
          if (const PcSet& m = orbits.member(o, k); !witness_rot.count(m) && !seen.count(m)) {
            Task t;
            t.pcs = m;
            t.seeds = seeds_of(m);
            rest.push_back(t);
          }
    if (!rest.empty()) {
      const std::vector<TaskResult> r = run_stage(rest, nullptr, t0);
      searched += rest.size();
      for (std::size_t i = 0; i < rest.size(); ++i) {
        seen.insert(rest[i].pcs);
        if (r[i].witness.found && !witness_rot.count(rest[i].pcs))
          accept(level, rest[i].pcs, r[i].witness);
      }
    }
    const std::size_t found = valid[level].size() - before;
    ev.total = searched;
    // The other members: valid as images above, or failed with their orbit.
    for (const PcSet& m : orbits.members) {
      if (witness_rot.count(m)) continue;
      seen.insert(m);
      failed.push_back(m);
    }
    LevelStats& st = out.levels[level];
    st.candidates += searched;
    st.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    finished(ev, t0, std::to_string(found) + " valid");
  };

  // Level 1: every element pair that local convexity allows.
  std::vector<PcSet> c1;
  const PcType types[] = {PcType::kFF, PcType::kEF, PcType::kFE, PcType::kVF, PcType::kFV, PcType::kEE};
  for (PcType t : types) {
    const int na = element_count(A, a_kind(t)), nb = element_count(B, b_kind(t));
    for (int a = 0; a < na; ++a)
      for (int b = 0; b < nb; ++b) {
        if ((t == PcType::kEF || t == PcType::kEE) && !A.edges()[a].convex) continue;
        if ((t == PcType::kFE || t == PcType::kEE) && !B.edges()[b].convex) continue;
        if (t == PcType::kVF && !Ai.cones[a].pointed) continue;
        if (t == PcType::kFV && !Bi.cones[b].pointed) continue;
        c1.push_back(PcSet({Pc{t, a, b}}));
      }
  }
  run_level(0, std::move(c1), [](const PcSet&) { return std::vector<Mat3>{}; });

  auto seeds_from_subsets = [&](const PcSet& s) {
    std::vector<Mat3> seeds;
    for (int k = 0; k < s.size(); ++k) {
      PcSet sub;
      for (int j = 0; j < s.size(); ++j)
        if (j != k) sub.insert(s[j]);
      auto it = witness_rot.find(sub);
      if (it != witness_rot.end()) seeds.push_back(it->second);
    }
    return seeds;
  };

  // Rejects only pairs that no pose verify accepts can make hold (pair_conditions.hpp):
  // ranges widened by far more than rounding (1e-9 rad: the slack's effect on the angle
  // between two edges' normals is second order, 2.5e-7 rad for the default angle margin);
  // normal cones shrunk by verify's local slack.
  // Contact points range over the points min_margin inside their elements; half of it, as the
  // LP's margin is checked only to its rounding.
  constexpr double kAngleTol = 1e-9;
  const PairConditions pair_ok(Ai, Bi, 1e-9 * search.scale() + opt.search.touch_tol, kAngleTol,
                               std::asin(search.verified_local_slack()) - kAngleTol, 0.5 * opt.search.min_margin);
  std::size_t singles_paired = 0;  // valid[0][0, singles_paired) have been paired with each other
  // Level 2 over the valid single PCs not paired yet (with every valid single PC).
  auto build_pairs = [&] {
    const std::size_t n = valid[0].size();
    if (n > std::numeric_limits<std::uint32_t>::max())
      throw Error("level 2: " + std::to_string(n) + " valid single PCs, more than the pairs' indices hold");
    // Each new single PC against the ones before it, on all cores (the conditions cost
    // microseconds a pair, and big models have millions of pairs); joined in order. Each
    // partner is kept as its index (a tenth of a set's size) until the sets are built, so
    // that tens of millions of candidates are not held twice.
    std::vector<std::vector<std::uint32_t>> by_j(n - singles_paired);
    parallel_for(by_j.size(), threads,
                 [&](std::size_t k) {
                   const std::size_t j = singles_paired + k;
                   const Pc& y = valid[0][j].first[0];
                   for (std::size_t i = 0; i < j; ++i) {
                     const Pc& x = valid[0][i].first[0];
                     // The table lookups first: they reject most pairs, for less than the
                     // set and its hash cost.
                     if (!pair_ok.compatible(x, y)) continue;
                     PcSet s({x, y});
                     if (seen.count(s) || !search.plausible(s)) continue;
                     by_j[k].push_back(static_cast<std::uint32_t>(i));
                   }
                 },
                 {});
    std::size_t total = 0;
    for (const auto& v : by_j) total += v.size();
    std::vector<PcSet> c2;
    c2.reserve(total);
    for (std::size_t k = 0; k < by_j.size(); ++k) {
      const Pc& y = valid[0][singles_paired + k].first[0];
      for (std::uint32_t i : by_j[k]) c2.push_back(PcSet({valid[0][i].first[0], y}));
      std::vector<std::uint32_t>().swap(by_j[k]);
    }
    singles_paired = n;
    return c2;
  };
  auto pairs_level = [&] {
    run_level(1, build_pairs(), seeds_from_subsets, first_pair_round ? opt.first_pairs : nullptr);
    first_pair_round = false;
  };
  std::size_t pairs_tripled = 0;  // valid pairs when the triples were last built
  // Level 3 over every set whose three pairs are valid and that was not searched yet.
  auto triples_level = [&] {
    // The valid pairs as partners: for each single PC x, the valid single PCs z (by index
    // in valid[0]) with {x, z} valid. A pair's third PCs are the partners of both.
    std::map<Pc, std::size_t> single_at;
    for (std::size_t i = 0; i < valid[0].size(); ++i) single_at.emplace(valid[0][i].first[0], i);
    std::map<Pc, std::vector<std::size_t>> partners;
    for (const auto& [s, w] : valid[1])
      for (int k = 0; k < 2; ++k)
        if (auto it = single_at.find(s[1 - k]); it != single_at.end())
          partners[s[k]].push_back(it->second);
    for (auto& [pc, v] : partners) {
      std::sort(v.begin(), v.end());
      v.erase(std::unique(v.begin(), v.end()), v.end());
    }
    std::vector<PcSet> c3;
    std::vector<std::size_t> common;
    for (const auto& [s, w] : valid[1]) {
      const auto x = partners.find(s[0]), y = partners.find(s[1]);
      if (x == partners.end() || y == partners.end()) continue;
      common.clear();
      std::set_intersection(x->second.begin(), x->second.end(), y->second.begin(), y->second.end(),
                            std::back_inserter(common));
      for (std::size_t i : common) {  // in valid[0]'s order
        const Pc& z = valid[0][i].first[0];
        if (!(s[1] < z)) continue;  // z beyond both, so each triple is built once
        PcSet t;
        t.insert(s[0]);
        t.insert(s[1]);
        t.insert(z);
        if (!seen.count(t) && search.plausible(t)) c3.push_back(t);
      }
    }
    pairs_tripled = valid[1].size();
    run_level(2, std::move(c3), seeds_from_subsets);
  };

  // Sets the necessary conditions reject cannot be verified: not searched (most sets that
  // motion meets have a contact on an element's boundary).
  auto conditions_hold = [&](const PcSet& t) {
    for (int x = 0; x < t.size(); ++x)
      for (int y = x + 1; y < t.size(); ++y)
        if (!pair_ok.compatible(t[x], t[y])) return false;
    return search.plausible(t);
  };

  // Closure by motion (explore.hpp): from every witness, translations and rotations that keep
  // some PCs and break the others, to the first contact. Sets met that are not in the graph yet are
  // searched (seeded with the rotation they were met at), and their own witnesses explored
  // in the next round, until a round adds nothing.
  auto motion_closure = [&] {
    while (!frontier.empty()) {
      const auto t0 = Clock::now();
      // More witnesses of each new orbit, each found by its own search (kWitnessesPerOrbit).
      if (sym.size() > 1) {
        std::vector<Task> more;
        std::unordered_set<PcSet, PcSetHash> orbits;
        for (const auto& [s, pose] : frontier) {
          if (!orbits.insert(sym.canonical(s)).second) continue;
          std::vector<PcSet> members;
          for (std::size_t k = 1; k < sym.size(); ++k) members.push_back(sym.image(s, k));
          std::sort(members.begin(), members.end(), pcset_less);
          members.erase(std::unique(members.begin(), members.end()), members.end());
          members.erase(std::remove(members.begin(), members.end(), s), members.end());
          const std::size_t step =
              std::max<std::size_t>(1, members.size() / (kWitnessesPerOrbit - 1));
          for (std::size_t i = 0, n = 1; i < members.size() && n < kWitnessesPerOrbit;
               i += step, ++n) {
            Task t;
            t.pcs = members[i];
            t.seeds = seeds_from_subsets(members[i]);
            more.push_back(t);
          }
        }
        const std::vector<TaskResult> r = run_stage(more, nullptr, t0);
        for (std::size_t i = 0; i < more.size(); ++i) {
          if (!r[i].witness.found) continue;
          if (witness_rot.count(more[i].pcs)) {
            frontier.push_back({more[i].pcs, r[i].witness.pose});
          } else {  // its image witness did not verify: a CF by its own witness
            seen.insert(more[i].pcs);
            accept(more[i].pcs.size() - 1, more[i].pcs, r[i].witness);
          }
        }
      }
      ProgressEvent ev{"motion round " + std::to_string(++motion_rounds), "CFs explored", 0, frontier.size(), 0, false, {}};
      std::vector<Task> explore(frontier.size());
      for (std::size_t i = 0; i < frontier.size(); ++i) {
        explore[i].kind = Task::Kind::kExplore;
        explore[i].pcs = frontier[i].first;
        explore[i].pose = frontier[i].second;
      }
      const std::vector<TaskResult> met = run_stage(explore, &ev, t0);
      // The first discovery of each new set, in frontier order: independent of thread count.
      std::vector<Discovery> fresh;
      std::unordered_set<PcSet, PcSetHash> pending;
      std::unordered_set<PcSet, PcSetHash> pending_orbits;  // one search per orbit a round
      for (const TaskResult& r : met)
        for (const Discovery& d : r.met)
          if (d.pcs.size() <= opt.max_pcs && !witness_rot.count(d.pcs) &&
              pending.insert(d.pcs).second && conditions_hold(d.pcs) &&
              pending_orbits.insert(sym.canonical(d.pcs)).second)
            fresh.push_back(d);
      std::vector<Task> search_fresh(fresh.size());
      for (std::size_t i = 0; i < fresh.size(); ++i) {
        search_fresh[i].kind = Task::Kind::kFindOrRefine;
        search_fresh[i].pcs = fresh[i].pcs;
        search_fresh[i].pose = fresh[i].pose;
      }
      std::vector<Witness> res(fresh.size());
      {
        const std::vector<TaskResult> r = run_stage(search_fresh, nullptr, t0);
        for (std::size_t i = 0; i < fresh.size(); ++i) res[i] = r[i].witness;
      }
      frontier.clear();
      std::size_t found = 0;
      for (std::size_t i = 0; i < fresh.size(); ++i) {
        if (!res[i].found) continue;
        if (witness_rot.count(fresh[i].pcs)) {
          frontier.push_back({fresh[i].pcs, fresh[i].pose});
          continue;
        }
        const int level = fresh[i].pcs.size() - 1;
        seen.insert(fresh[i].pcs);
        accept(level, fresh[i].pcs, res[i]);
        // Explore from where motion met the set too: another pose in its region, which
        // reaches what the witness's orientation does not.
        frontier.push_back({fresh[i].pcs, fresh[i].pose});
        ++out.levels[level].by_motion;
        ++found;
      }
      finished(ev, t0, std::to_string(found) + " new CFs");
    }
  };

  // Levels and motion to a fixed point: a single PC or a pair that only motion found takes
  // part in the levels above it like any other (a CF's subsets need not be found first).
  if (opt.shard.count > 0) {
    // One shard of the first level-2 round: its candidates only, results by index.
    const int index = opt.shard.index;
    std::vector<PcSet> reps;
    const OrbitGroups orbits = orbits_of(opt.max_pcs >= 2 ? build_pairs() : std::vector<PcSet>{});
    for (std::size_t o = 0; o < orbits.size(); ++o) reps.push_back(orbits.member(o, 0));
    out.first_pair_candidates = reps.size();
    std::vector<std::size_t> mine;
    for (std::size_t i = static_cast<std::size_t>(index); i < reps.size();
         i += static_cast<std::size_t>(opt.shard.count))
      mine.push_back(i);
    std::vector<Task> tasks(mine.size());
    for (std::size_t k = 0; k < mine.size(); ++k) {
      tasks[k].pcs = reps[mine[k]];
      tasks[k].seeds = seeds_from_subsets(reps[mine[k]]);
    }
    const auto t0 = Clock::now();
    ProgressEvent ev{"level 2, shard " + std::to_string(index) + "/" + std::to_string(opt.shard.count),
                     "candidate sets", 0, mine.size(), 0, false, {}};
    const std::vector<TaskResult> res = run_tasks(search, tasks, threads, ticker(ev, t0));
    std::size_t found = 0;
    for (std::size_t k = 0; k < mine.size(); ++k) {
      found += res[k].witness.found ? 1 : 0;
      out.shard_results.push_back({mine[k], res[k].witness});
    }
    finished(ev, t0, std::to_string(found) + " valid");
    return out;
  }
  // Failed sets near their neighbours (after each fixed point): a CF valid only in a sliver
  // of orientations (a peg tilted across a hole's rim) is missed by the search's samples, but
  // the CFs one change away (one PC replaced by a neighbouring PC, cf::neighbouring_pcs) hold
  // on either side of it, at rotations a few hundredths of a radian from the one it needs.
  // Each failed set with such CFs is searched again near their witnesses (WitnessSearch::find,
  // seeds_only): one member of an orbit a round, up to kOrbitTries members over the rounds,
  // as the levels do, each member once. The rounds add CFs, never take one away, so a graph
  // holds every CF the fixed point before them found. Returns the number of CFs found.
  std::unordered_set<PcSet, PcSetHash> near_searched;            // members searched so
  std::unordered_map<PcSet, std::size_t, PcSetHash> near_tries;  // per orbit
  std::map<Pc, std::vector<Pc>> pc_neighbours;
  // The sets one change away from s (one PC replaced by a neighbouring PC), in a fixed order.
  auto changes_of = [&](const PcSet& s, const std::function<void(const PcSet&)>& fn) {
    for (int k = 0; k < s.size(); ++k) {
      auto nb = pc_neighbours.find(s[k]);
      if (nb == pc_neighbours.end())
        nb = pc_neighbours.emplace(s[k], cf::neighbouring_pcs(s[k], A, B)).first;
      for (const Pc& q : nb->second) {
        PcSet n;
        for (int j = 0; j < s.size(); ++j) n.insert(j == k ? q : s[j]);
        if (n.size() == s.size()) fn(n);
      }
    }
  };
  auto neighbour_round = [&]() -> std::size_t {
    const auto t0 = Clock::now();
    std::vector<Task> tasks;
    std::unordered_set<PcSet, PcSetHash> round_orbits;
    auto consider = [&](const PcSet& s) {
      if (witness_rot.count(s) || near_searched.count(s)) return;
      Task t;
      t.kind = Task::Kind::kFindNear;
      t.pcs = s;
      changes_of(s, [&](const PcSet& n) {
        if (auto it = witness_rot.find(n);
            it != witness_rot.end() && t.seeds.size() < kNeighbourSeeds)
          t.seeds.push_back(it->second);
      });
      if (t.seeds.empty()) return;
      const PcSet orbit = sym.canonical(s);
      if (round_orbits.count(orbit) || near_tries[orbit] >= kOrbitTries) return;
      round_orbits.insert(orbit);
      ++near_tries[orbit];
      near_searched.insert(s);
      tasks.push_back(std::move(t));
    };
    // The failed candidates, then the sets one change away from a CF that no level proposed
    // (a subset of theirs is missing) and that the necessary conditions allow.
    for (const PcSet& s : failed) consider(s);
    for (int l = 0; l < 3; ++l)
      for (std::size_t i = 0; i < valid[l].size(); ++i)
        changes_of(valid[l][i].first, [&](const PcSet& n) {
          if (!witness_rot.count(n) && !near_searched.count(n) && !seen.count(n) &&
              conditions_hold(n))
            consider(n);
        });
    const std::string stage = "neighbour round " + std::to_string(++neighbour_rounds);
    ProgressEvent ev{stage, "failed sets", 0, tasks.size(), 0, false, {}};
    const std::vector<TaskResult> r = run_stage(tasks, &ev, t0);
    std::size_t found = 0;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if (!r[i].witness.found || witness_rot.count(tasks[i].pcs)) continue;
      const int level = tasks[i].pcs.size() - 1;
      const std::size_t before = valid[level].size();
      accept(level, tasks[i].pcs, r[i].witness);
      ++out.levels[level].by_neighbours;  // its images count under by_symmetry
      found += valid[level].size() - before;
    }
    finished(ev, t0, std::to_string(found) + " new CFs");
    return found;
  };
  for (;;) {
    if (opt.max_pcs >= 2) pairs_level();
    if (opt.max_pcs >= 3) triples_level();
    motion_closure();
    const bool grew = (opt.max_pcs >= 2 && valid[0].size() > singles_paired) ||
                      (opt.max_pcs >= 3 && valid[1].size() > pairs_tripled);
    if (!grew && neighbour_round() == 0) break;
  }
  // Orbit closure (--thorough): every member of every orbit met, at the image of the witness
  // found. The search above found each CF on its own, from its own seeds and motions; the
  // images add the members it missed. Verified on all cores, added in a fixed order.
  if (opt.close_orbits) {
    const PairSymmetries full(A, B, kSymmetryTol * search.scale(), true);
    out.symmetries_a = full.size_a();
    out.symmetries_b = full.size_b();
    // A set's images from several CFs: the first in canonical order, and where that one does
    // not verify (rounding at a borderline pose), the next, up to kClosureTries.
    constexpr std::size_t kClosureTries = 4;
    for (int l = 0; l < 3; ++l) {
      const std::size_t found = valid[l].size();
      for (std::size_t attempt = 0; attempt < kClosureTries; ++attempt) {
        std::vector<std::pair<PcSet, Witness>> images;
        std::unordered_map<PcSet, std::size_t, PcSetHash> sources;  // images met so far, by set
        for (std::size_t i = 0; i < found; ++i) {
          const auto& [s, w] = valid[l][i];
          for (std::size_t k = 1; k < full.size(); ++k) {
            const PcSet t = full.image(s, k);
            if (witness_rot.count(t) || sources[t]++ != attempt) continue;
            Witness v = w;
            v.pose = full.image(w.pose, k);
            images.push_back({t, v});
          }
        }
        parallel_for(images.size(), threads,
                     [&](std::size_t i) { images[i].second.clearance = search.verify(images[i].first, images[i].second.pose); },
                     {});
        bool refused = false;
        for (auto& [t, v] : images) {
          if (v.clearance < opt.search.min_clearance) {
            refused = true;
            continue;
          }
          witness_rot.emplace(t, v.pose.R_BA);
          valid[l].push_back({t, v});
          ++out.levels[l].by_symmetry;
        }
        if (!refused) break;
      }
    }
  }
  for (int l = 0; l < 3; ++l) out.levels[l].valid = valid[l].size();

  // What the search could not decide: failed candidates that motion did not find either and
  // that no proof rules out (WitnessSearch::refuted).
  {
    std::unordered_set<PcSet, PcSetHash> known;
    for (int l = 0; l < 3; ++l)
      for (const auto& [s, w] : valid[l]) known.insert(s);
    std::vector<char> open(failed.size(), 0);
    const auto t0 = Clock::now();
    ProgressEvent ev{"proofs of invalidity", "failed candidate sets", 0, failed.size(), 0, false, {}};
    parallel_for(failed.size(), threads,
                 [&](std::size_t i) { open[i] = !known.count(failed[i]) && !search.refuted(failed[i]); },
                 ticker(ev, t0));
    for (std::size_t i = 0; i < failed.size(); ++i)
      if (open[i]) out.undecided.push_back(failed[i]);
    finished(ev, t0, std::to_string(out.undecided.size()) + " undecided");
    std::sort(out.undecided.begin(), out.undecided.end(), pcset_less);
  }

  out.min_clearance = std::numeric_limits<double>::infinity();
  out.min_margin = std::numeric_limits<double>::infinity();
  for (int l = 0; l < 3; ++l) {
    std::sort(valid[l].begin(), valid[l].end(),
              [](const auto& x, const auto& y) { return pcset_less(x.first, y.first); });
    // Each CF's record on its own (all cores), in canonical order.
    std::vector<CfRecord> records(valid[l].size());
    std::vector<double> margins(valid[l].size());
    parallel_for(valid[l].size(), threads,
                 [&](std::size_t i) {
                   const auto& [s, w] = valid[l][i];
                   CfRecord& r = records[i];
                   r.pcs = s;
                   r.witness = w.pose;
                   search.freedoms(s, w.pose, r);
                   for (int k = 0; k < s.size(); ++k) {
                     const auto [n, d] = search.contact_plane(s[k], w.pose);
                     r.planes[static_cast<std::size_t>(k)] = {n.x(), n.y(), n.z(), d};
                   }
                   r.num_planes = s.size();
                   margins[i] = search.contact_margin(s, w.pose);
                 },
                 {});
    for (std::size_t i = 0; i < records.size(); ++i) {
      out.cfs.push_back(records[i]);
      out.min_clearance = std::min(out.min_clearance, valid[l][i].second.clearance);
      out.min_margin = std::min(out.min_margin, margins[i]);
    }
  }
  // The search's own sets are done with: a large pair's candidates take hundreds of MB,
  // which the transitions and the file need more.
  std::unordered_set<PcSet, PcSetHash>().swap(seen);
  std::vector<PcSet>().swap(failed);
  std::unordered_map<PcSet, Mat3, PcSetHash>().swap(witness_rot);
  for (auto& v : valid) std::vector<std::pair<PcSet, Witness>>().swap(v);
  out.transitions = transitions_between(out.cfs, A, B, threads);
  return out;
}

}  // namespace cf::gen

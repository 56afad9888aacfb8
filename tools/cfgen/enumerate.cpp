#include "enumerate.hpp"

#include "explore.hpp"
#include "pair_conditions.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <unordered_set>

namespace cf::gen {
namespace {

using Clock = std::chrono::steady_clock;

struct PcSetHash {
  std::size_t operator()(const PcSet& s) const { return s.hash(); }
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
                                            const Polyhedron& B) {
  std::unordered_map<PcSet, int, PcSetHash> index;
  for (std::size_t i = 0; i < cfs.size(); ++i) index.emplace(cfs[i].pcs, static_cast<int>(i));
  std::vector<Transition> out;
  auto push = [&](int from, int to, TransitionKind k) {
    out.push_back({CfId(from), CfId(to), k});
  };
  std::map<Pc, std::vector<Pc>> nb_cache;
  auto neighbours = [&](const Pc& pc) -> const std::vector<Pc>& {
    auto it = nb_cache.find(pc);
    if (it == nb_cache.end()) it = nb_cache.emplace(pc, cf::neighbouring_pcs(pc, A, B)).first;
    return it->second;
  };
  for (std::size_t i = 0; i < cfs.size(); ++i) {
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
    // change: replace one or more PCs by neighbouring PCs, keeping the count.
    std::vector<std::vector<Pc>> options(static_cast<std::size_t>(s.size()));
    for (int k = 0; k < s.size(); ++k) {
      options[k].push_back(s[k]);
      for (const Pc& q : neighbours(s[k])) options[k].push_back(q);
    }
    std::vector<std::size_t> pick(options.size(), 0);
    while (true) {
      std::size_t d = 0;
      while (d < pick.size() && ++pick[d] == options[d].size()) pick[d++] = 0;
      if (d == pick.size()) break;
      PcSet t;
      bool ok = true;
      for (std::size_t k = 0; k < pick.size() && ok; ++k) ok = t.insert(options[k][pick[k]]);
      if (!ok || t.size() != s.size()) continue;
      auto it = index.find(t);
      if (it != index.end() && it->second != me) push(me, it->second, TransitionKind::kChange);
    }
  }
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
  auto accept = [&](int level, const PcSet& s, const Witness& w) {
    valid[level].push_back({s, w});
    witness_rot.emplace(s, w.pose.R_BA);
    frontier.push_back({s, w.pose});
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
  bool first_pair_round = true;  // the first level-2 round (the one --shard splits)

  // Every stage of the run, in order: its tasks cut into chunks, each found in the checkpoint,
  // computed here or handed to another process, and kept when done.
  std::size_t stages = 0;
  // ev: where progress goes, null for none.
  auto run_stage = [&](const std::vector<Task>& tasks, ProgressEvent* ev, Clock::time_point t0) {
    const std::size_t stage = stages++;
    const bool report = ev && opt.progress;
    if (!opt.checkpoint.load && !opt.distribute)
      return run_tasks(search, tasks, threads, report ? ticker(*ev, t0) : std::function<void(std::size_t)>());
    const std::size_t n = tasks.size(), size = chunk_size(n);
    std::vector<std::vector<Task>> chunks;
    for (std::size_t b = 0; b < n; b += size)
      chunks.emplace_back(tasks.begin() + static_cast<std::ptrdiff_t>(b),
                          tasks.begin() + static_cast<std::ptrdiff_t>(std::min(n, b + size)));
    std::vector<TaskResult> res(n);
    std::vector<std::size_t> todo;
    std::size_t done = 0;
    auto tick = [&](std::size_t d) {
      if (!report) return;
      ev->done = done + d;
      ev->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      opt.progress(*ev);
    };
    auto take = [&](std::size_t k, std::vector<TaskResult>&& r) {
      if (r.size() != chunks[k].size())
        throw Error("stage " + std::to_string(stage) + ", chunk " + std::to_string(k) + ": " +
                    std::to_string(r.size()) + " results for " + std::to_string(chunks[k].size()) + " tasks");
      if (opt.checkpoint.save) opt.checkpoint.save(stage, k, chunks[k], r);
      std::move(r.begin(), r.end(), res.begin() + static_cast<std::ptrdiff_t>(k * size));
      done += chunks[k].size();
      tick(0);
    };
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      std::vector<TaskResult> kept;
      if (opt.checkpoint.load && opt.checkpoint.load(stage, k, chunks[k], kept)) {
        std::move(kept.begin(), kept.end(), res.begin() + static_cast<std::ptrdiff_t>(k * size));
        done += chunks[k].size();
      } else {
        todo.push_back(k);
      }
    }
    if (opt.distribute) {
      // Progress then moves chunk by chunk, from the thread that takes them.
      opt.distribute(chunks, todo, [&](std::size_t k) { return run_tasks(search, chunks[k], threads); }, take);
    } else {
      for (std::size_t k : todo)
        take(k, run_tasks(search, chunks[k], threads, report ? std::function<void(std::size_t)>(tick) : nullptr));
    }
    return res;
  };

  // given: results computed elsewhere (the shards of the first level-2 round), one per candidate.
  auto run_level = [&](int level, const std::vector<PcSet>& cands,
                       const std::function<std::vector<Mat3>(const PcSet&)>& seeds_of,
                       const std::vector<Witness>* given = nullptr) {
    const auto t0 = Clock::now();
    std::vector<Witness> res(cands.size());
    ProgressEvent ev{"level " + std::to_string(level + 1), "candidate sets", 0, cands.size(), 0, false, {}};
    if (given) {
      if (given->size() != cands.size())
        throw Error("merging shards: the parts hold " + std::to_string(given->size()) +
                    " results of the first level-2 round, but these models and options give " +
                    std::to_string(cands.size()) + " candidates");
      res = *given;
      ++stages;
    } else {
      std::vector<Task> tasks(cands.size());
      for (std::size_t i = 0; i < cands.size(); ++i) {
        tasks[i].kind = Task::Kind::kFind;
        tasks[i].pcs = cands[i];
        tasks[i].seeds = seeds_of(cands[i]);
      }
      std::vector<TaskResult> r = run_stage(tasks, &ev, t0);
      for (std::size_t i = 0; i < cands.size(); ++i) res[i] = r[i].witness;
    }
    std::size_t found = 0;
    for (std::size_t i = 0; i < cands.size(); ++i) {
      seen.insert(cands[i]);
      if (res[i].found) accept(level, cands[i], res[i]), ++found;
      else failed.push_back(cands[i]);
    }
    LevelStats& st = out.levels[level];
    st.candidates += cands.size();
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
  run_level(0, c1, [](const PcSet&) { return std::vector<Mat3>{}; });

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
    // Each new single PC against the ones before it, on all cores (the conditions cost
    // microseconds a pair, and big models have millions of pairs); joined in order.
    std::vector<std::vector<PcSet>> by_j(n - singles_paired);
    parallel_for(by_j.size(), threads,
                 [&](std::size_t k) {
                   const std::size_t j = singles_paired + k;
                   const Pc& y = valid[0][j].first[0];
                   for (std::size_t i = 0; i < j; ++i) {
                     const Pc& x = valid[0][i].first[0];
                     PcSet s({x, y});
                     if (seen.count(s) || !pair_ok.compatible(x, y) || !search.plausible(s)) continue;
                     by_j[k].push_back(s);
                   }
                 },
                 {});
    std::vector<PcSet> c2;
    for (auto& v : by_j) c2.insert(c2.end(), v.begin(), v.end());
    singles_paired = n;
    return c2;
  };
  auto pairs_level = [&] {
    const std::vector<PcSet> c2 = build_pairs();
    run_level(1, c2, seeds_from_subsets, first_pair_round ? opt.first_pairs : nullptr);
    first_pair_round = false;
  };
  std::size_t pairs_tripled = 0;  // valid pairs when the triples were last built
  // Level 3 over every set whose three pairs are valid and that was not searched yet.
  auto triples_level = [&] {
    std::unordered_set<PcSet, PcSetHash> pairs;
    for (const auto& [s, w] : valid[1]) pairs.insert(s);
    std::vector<PcSet> c3;
    for (const auto& [s, w] : valid[1])
      for (const auto& [s1, w1] : valid[0]) {
        const Pc& z = s1[0];
        if (!(s[1] < z)) continue;  // z beyond both, so each triple is built once
        if (!pairs.count(PcSet({s[0], z})) || !pairs.count(PcSet({s[1], z}))) continue;
        PcSet t({s[0], s[1], z});
        if (!seen.count(t) && search.plausible(t)) c3.push_back(t);
      }
    pairs_tripled = valid[1].size();
    run_level(2, c3, seeds_from_subsets);
  };

  // Closure by motion (explore.hpp): from every witness, translations and rotations that keep
  // some PCs and break the others, to the first contact. Sets met that are not in the graph yet are
  // searched (seeded with the rotation they were met at), and their own witnesses explored
  // in the next round, until a round adds nothing.
  auto motion_closure = [&] {
    while (!frontier.empty()) {
      const auto t0 = Clock::now();
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
      // Sets the necessary conditions reject cannot be verified: not searched (most are met
      // with a contact on an element's boundary).
      auto conditions_hold = [&](const PcSet& t) {
        for (int x = 0; x < t.size(); ++x)
          for (int y = x + 1; y < t.size(); ++y)
            if (!pair_ok.compatible(t[x], t[y])) return false;
        return search.plausible(t);
      };
      for (const TaskResult& r : met)
        for (const Discovery& d : r.met)
          if (d.pcs.size() <= opt.max_pcs && !witness_rot.count(d.pcs) && pending.insert(d.pcs).second &&
              conditions_hold(d.pcs))
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
    const std::vector<PcSet> c2 = opt.max_pcs >= 2 ? build_pairs() : std::vector<PcSet>{};
    out.first_pair_candidates = c2.size();
    const int index = opt.shard.index;
    std::vector<std::size_t> mine;
    for (std::size_t i = static_cast<std::size_t>(index); i < c2.size(); i += static_cast<std::size_t>(opt.shard.count))
      mine.push_back(i);
    std::vector<Task> tasks(mine.size());
    for (std::size_t k = 0; k < mine.size(); ++k) {
      tasks[k].pcs = c2[mine[k]];
      tasks[k].seeds = seeds_from_subsets(c2[mine[k]]);
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
  for (;;) {
    if (opt.max_pcs >= 2) pairs_level();
    if (opt.max_pcs >= 3) triples_level();
    motion_closure();
    const bool grew = (opt.max_pcs >= 2 && valid[0].size() > singles_paired) ||
                      (opt.max_pcs >= 3 && valid[1].size() > pairs_tripled);
    if (!grew) break;
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
    std::sort(out.undecided.begin(), out.undecided.end(), [](const PcSet& x, const PcSet& y) {
      if (x.size() != y.size()) return x.size() < y.size();
      for (int k = 0; k < x.size(); ++k)
        if (x[k] != y[k]) return x[k] < y[k];
      return false;
    });
  }

  out.min_clearance = std::numeric_limits<double>::infinity();
  out.min_margin = std::numeric_limits<double>::infinity();
  for (int l = 0; l < 3; ++l) {
    std::sort(valid[l].begin(), valid[l].end(), [](const auto& x, const auto& y) {
      for (int k = 0; k < x.first.size(); ++k)
        if (x.first[k] != y.first[k]) return x.first[k] < y.first[k];
      return false;
    });
    for (const auto& [s, w] : valid[l]) {
      CfRecord r;
      r.pcs = s;
      r.witness = w.pose;
      search.freedoms(s, w.pose, r);
      for (int k = 0; k < s.size(); ++k) {
        const auto [n, d] = search.contact_plane(s[k], w.pose);
        r.planes[static_cast<std::size_t>(k)] = {n.x(), n.y(), n.z(), d};
      }
      r.num_planes = s.size();
      out.cfs.push_back(r);
      out.min_clearance = std::min(out.min_clearance, w.clearance);
      out.min_margin = std::min(out.min_margin, search.contact_margin(s, w.pose));
    }
  }
  out.transitions = transitions_between(out.cfs, A, B);
  return out;
}

}  // namespace cf::gen

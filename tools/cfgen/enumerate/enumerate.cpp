// The order of the enumeration's steps (enumerator.hpp), and the transitions between the
// CFs found.

#include "cfgen/enumerate/enumerator.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <array>
#include <limits>
#include <map>

namespace cf::gen {
namespace internal {

Enumerator::Enumerator(const WitnessSearch& search, const EnumerateOptions& opt,
                       StageRunner& runner)
    : search_(search),
      A_(*search.a().model),
      B_(*search.b().model),
      opt_(opt),
      runner_(runner),
      sym_(A_, B_, kSymmetryTol * search.scale(), opt.use_symmetry),
      pair_ok_(pair_conditions_for(search)) {
  out_.symmetries_a = sym_.size_a();
  out_.symmetries_b = sym_.size_b();
}

// Levels and motion to a fixed point, then the neighbour rounds, to a fixed point of both: a
// single PC or a pair that only motion found takes part in the levels above it like any
// other (a CF's subsets need not be found first).
Enumeration Enumerator::run() {
  singles_level();
  for (;;) {
    if (opt_.max_pcs >= 2) pairs_level();
    if (opt_.max_pcs >= 3) triples_level();
    motion_closure();
    const bool grew = (opt_.max_pcs >= 2 && valid_[0].size() > singles_paired_) ||
                      (opt_.max_pcs >= 3 && valid_[1].size() > pairs_tripled_);
    if (!grew && neighbour_round() == 0) break;
  }
  if (opt_.close_orbits) close_orbits();
  for (int l = 0; l < 3; ++l) out_.levels[l].valid = valid_[l].size();
  if (!opt_.records) return std::move(out_);
  find_undecided();
  build_records();
  // The search's own sets are done with: a large pair's candidates take hundreds of MB,
  // which the transitions and the file need more.
  PcSetSet().swap(seen_);
  std::vector<PcSet>().swap(failed_);
  PcSetMap<Mat3>().swap(witness_rot_);
  for (auto& v : valid_) std::vector<std::pair<PcSet, Witness>>().swap(v);
  out_.transitions = transitions_between(out_.cfs, A_, B_, runner_);
  return std::move(out_);
}

}  // namespace internal

Enumeration enumerate(const WitnessSearch& search, const EnumerateOptions& opt,
                      StageRunner& runner) {
  return internal::Enumerator(search, opt, runner).run();
}

RunEstimate estimate(const WitnessSearch& search, const EnumerateOptions& opt,
                     StageRunner& runner, int threads) {
  return internal::Enumerator(search, opt, runner).estimate(threads);
}

std::vector<TaskResult> run_tasks(StageRunner& runner, const std::vector<Task>& tasks,
                                  ProgressEvent* progress, Clock::time_point started) {
  std::vector<TaskResult> results(tasks.size());
  Stage s;
  s.size = tasks.size();
  s.make = [&](std::size_t i) { return tasks[i]; };
  s.take = [&](std::size_t i, TaskResult&& r) { results[i] = std::move(r); };
  s.progress = progress;
  s.started = started;
  runner.run(s);
  return results;
}

std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B, StageRunner& runner) {
  using internal::PcSetHash;
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
  runner.for_each(cfs.size(), [&](std::size_t i) {
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
  });
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

}  // namespace cf::gen

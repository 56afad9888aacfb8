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

// Levels and motion to a fixed point, then the open single PCs admitted to the pairs, then
// the neighbour rounds, to a fixed point of all: a single PC or a pair that only motion found
// takes part in the levels above it like any other (a CF's subsets need not be found first).
Enumeration Enumerator::run() {
  singles_level();
  for (;;) {
    if (opt_.max_pcs >= 2) pairs_level();
    if (opt_.max_pcs >= 3) triples_level();
    motion_closure();
    const bool grew = (opt_.max_pcs >= 2 && valid_[0].size() > singles_valid_) ||
                      (opt_.max_pcs >= 3 && valid_[1].size() > pairs_tripled_);
    if (!grew && !admit_open_singles() && neighbour_round() == 0) break;
  }
  release_neighbour_rounds();
  if (opt_.close_orbits) close_orbits();
  for (int l = 0; l < 3; ++l) out_.levels[l].valid = valid_[l].size();
  if (!opt_.records) return std::move(out_);
  // What was searched is done with; the proofs take a large pair's failed sets in memory.
  PcSetMap<std::uint8_t>().swap(seen_);
  find_undecided();
  build_records();
  // The search's own sets are done with: a large pair's candidates take hundreds of MB,
  // which the transitions and the file need more.
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

RunEstimate estimate(const WitnessSearch& search, const EnumerateOptions& opt, StageRunner& runner,
                     int threads, std::size_t samples) {
  return internal::Enumerator(search, opt, runner).estimate(threads, samples);
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

namespace {

// The CFs of a graph as the transitions look them up: by PC set; the CFs of three PCs by
// each pair of their PCs (with the CF's set beside its index, read in sequence); every PC's
// neighbours.
struct CfIndex {
  struct Held {
    PcSet set;
    int cf;
  };
  std::unordered_map<PcSet, int, internal::PcSetHash> by_set;
  std::unordered_map<PcSet, std::vector<Held>, internal::PcSetHash> triples_by_pair;
  std::map<Pc, std::vector<Pc>> nb;

  CfIndex(const std::vector<CfRecord>& cfs, const Polyhedron& A, const Polyhedron& B) {
    for (std::size_t i = 0; i < cfs.size(); ++i) {
      const PcSet& s = cfs[i].pcs;
      by_set.emplace(s, static_cast<int>(i));
      for (int k = 0; k < s.size(); ++k) {
        if (!nb.count(s[k])) nb.emplace(s[k], cf::neighbouring_pcs(s[k], A, B));
        if (s.size() == 3)
          triples_by_pair[internal::without(s, k)].push_back({s, static_cast<int>(i)});
      }
    }
  }
};

// gain / lose: CF `me` (set s) and the CFs it leaves when it drops one PC.
void gains_and_losses(const CfIndex& idx, const PcSet& s, int me, std::vector<Transition>& out) {
  if (s.size() < 2) return;
  for (int k = 0; k < s.size(); ++k) {
    auto it = idx.by_set.find(internal::without(s, k));
    if (it == idx.by_set.end()) continue;
    out.push_back({CfId(it->second), CfId(me), TransitionKind::kGain});
    out.push_back({CfId(me), CfId(it->second), TransitionKind::kLose});
  }
}

// Whether t's PCs match the positions of `options` one to one, each PC among its position's.
bool matches(const std::vector<std::vector<Pc>>& options, const PcSet& t) {
  const int n = t.size();
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
}

// change: the CFs of s's size whose PCs match s's positions one to one, each the same PC or
// a neighbour (`options`). Every such CF holds one option of each of the first two positions:
// each pair of those is looked up (as the CF itself when s has two PCs, among the CFs of
// three PCs holding it when three).
void changes(const CfIndex& idx, const PcSet& s, int me, std::vector<Transition>& out) {
  const int n = s.size();
  std::vector<std::vector<Pc>> options(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    auto& o = options[static_cast<std::size_t>(k)];
    o.push_back(s[k]);
    for (const Pc& q : idx.nb.at(s[k])) o.push_back(q);
    std::sort(o.begin(), o.end());
  }
  auto push = [&](int to) {
    if (to != me) out.push_back({CfId(me), CfId(to), TransitionKind::kChange});
  };
  if (n == 1)
    for (const Pc& x : options[0])
      if (auto it = idx.by_set.find(PcSet(std::vector<Pc>{x})); it != idx.by_set.end())
        push(it->second);
  if (n < 2) return;
  for (const Pc& x : options[0])
    for (const Pc& y : options[1]) {
      PcSet pair;
      pair.insert(x);
      if (!pair.insert(y)) continue;
      if (n == 2) {
        if (auto it = idx.by_set.find(pair); it != idx.by_set.end()) push(it->second);
      } else if (auto it = idx.triples_by_pair.find(pair); it != idx.triples_by_pair.end()) {
        for (const CfIndex::Held& h : it->second)
          if (matches(options, h.set)) push(h.cf);
      }
    }
}

}  // namespace

std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B, StageRunner& runner) {
  const CfIndex idx(cfs, A, B);
  // Each CF's transitions on its own, joined in CF order (then sorted).
  std::vector<std::vector<Transition>> per_cf(cfs.size());
  runner.for_each(cfs.size(), [&](std::size_t i) {
    gains_and_losses(idx, cfs[i].pcs, static_cast<int>(i), per_cf[i]);
    changes(idx, cfs[i].pcs, static_cast<int>(i), per_cf[i]);
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

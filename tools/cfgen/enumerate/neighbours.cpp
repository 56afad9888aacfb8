// Failed sets near their neighbours (after each fixed point): a CF valid only in a sliver of
// orientations (a peg tilted across a hole's rim) is missed by the search's samples, but the
// CFs one change away (one PC replaced by a neighbouring PC, cf::neighbouring_pcs) hold on
// either side of it, at rotations a few hundredths of a radian from the one it needs. Each
// failed set with such CFs is searched again near their witnesses (WitnessSearch::find,
// seeds_only): one member of an orbit a round, up to kOrbitTries members over the rounds, as
// the levels do, each member once. The rounds add CFs, never take one away, so a graph holds
// every CF the fixed point before them found.

#include "cfgen/enumerate/enumerator.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <string>
#include <utility>

namespace cf::gen::internal {
namespace {

// Witnesses of neighbouring CFs a failed set is searched again from.
constexpr std::size_t kNeighbourSeeds = 16;

}  // namespace

// The neighbouring PCs of every PC in `pcs` not known yet, computed on all threads and
// kept in pc_neighbours_.
void Enumerator::know_neighbours(const std::vector<Pc>& pcs) {
  std::vector<Pc> missing;
  for (const Pc& pc : pcs)
    if (!pc_neighbours_.count(pc)) missing.push_back(pc);
  std::sort(missing.begin(), missing.end());
  missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
  std::vector<std::vector<Pc>> nb(missing.size());
  runner_.for_each(missing.size(),
                   [&](std::size_t i) { nb[i] = cf::neighbouring_pcs(missing[i], A_, B_); });
  for (std::size_t i = 0; i < missing.size(); ++i)
    pc_neighbours_.emplace(missing[i], std::move(nb[i]));
}

// The sets one change away from s (one PC replaced by a neighbouring PC), in a fixed order.
// Reads only: every PC of s must be in pc_neighbours_ (know_neighbours).
void Enumerator::changes_of(const PcSet& s, const std::function<void(const PcSet&)>& fn) const {
  any_change(s, [&](const PcSet& n) {
    fn(n);
    return false;
  });
}

// Whether some set one change away from s satisfies `pred` (stops at the first).
bool Enumerator::any_change(const PcSet& s, const std::function<bool(const PcSet&)>& pred) const {
  for (int k = 0; k < s.size(); ++k)
    for (const Pc& q : pc_neighbours_.at(s[k])) {
      PcSet n;
      for (int j = 0; j < s.size(); ++j) n.insert(j == k ? q : s[j]);
      if (n.size() == s.size() && pred(n)) return true;
    }
  return false;
}

// Whether a set is worth a neighbour search this round, judged on what the round starts
// with: never (valid, searched near before, or its orbit tried kOrbitTries times: each stays
// so, as witnesses, searches and tries only grow), not yet (no set one change away is
// valid), or yes, its orbit in `orbit`.
Enumerator::Near Enumerator::near_candidate(const PcSet& s, PcSet& orbit) const {
  if (witness_rot_.count(s) || near_searched_.count(s)) return Near::kNever;
  if (!any_change(s, [&](const PcSet& n) { return witness_rot_.count(n) > 0; }))
    return Near::kNotYet;
  orbit = sym_.canonical(s);
  auto it = near_tries_.find(orbit);
  return it == near_tries_.end() || it->second < kOrbitTries ? Near::kYes : Near::kNever;
}

// Screens one failed set, or the changes of one CF, into `kept`; sets `dead` when nothing it
// screens can be worth a search in any later round (a failed set that never will be, a CF
// whose changes never will be), so that later rounds pass it by.
void Enumerator::screen(const PcSet& s, bool failed, char& dead,
                        std::vector<std::pair<PcSet, PcSet>>& kept) const {
  PcSet orbit;
  if (failed) {
    const Near r = near_candidate(s, orbit);
    if (r == Near::kYes) kept.emplace_back(s, orbit);
    dead = r == Near::kNever;
    return;
  }
  bool never = true;
  changes_of(s, [&](const PcSet& n) {
    if (witness_rot_.count(n) || near_searched_.count(n) || seen_.count(n) || !conditions_hold(n))
      return;
    const Near r = near_candidate(n, orbit);
    if (r == Near::kYes) kept.emplace_back(n, orbit);
    never = never && r == Near::kNever;
  });
  dead = never;
}

// The sets of a neighbour round, in order: the failed candidates, then the sets one change
// away from a CF that no level proposed (a subset of theirs is missing) and that the
// necessary conditions allow. Screened on all threads a block at a time (near_candidate),
// then taken in order on this thread: one member of an orbit a round.
std::vector<Task> Enumerator::neighbour_tasks() {
  // The PCs of the failed sets and of the CFs, then those of the CFs' changes.
  std::vector<Pc> pcs;
  for (const PcSet& s : failed_) pcs.insert(pcs.end(), s.begin(), s.end());
  for (const auto& level : valid_)
    for (const auto& [s, w] : level) pcs.insert(pcs.end(), s.begin(), s.end());
  know_neighbours(pcs);
  std::vector<Pc> next;
  for (const auto& level : valid_)
    for (const auto& [s, w] : level)
      for (const Pc& pc : s)
        for (const Pc& q : pc_neighbours_.at(pc)) next.push_back(q);
  know_neighbours(next);
  // Failed sets, or CFs whose changes are screened, with their marks from earlier rounds.
  failed_dead_.resize(failed_.size(), 0);
  struct From {
    const PcSet* set;
    bool failed;
    char* dead;
  };
  std::vector<From> from;
  for (std::size_t i = 0; i < failed_.size(); ++i)
    if (!failed_dead_[i]) from.push_back({&failed_[i], true, &failed_dead_[i]});
  for (int l = 0; l < 3; ++l) {
    cf_dead_[l].resize(valid_[l].size(), 0);
    for (std::size_t i = 0; i < valid_[l].size(); ++i)
      if (!cf_dead_[l][i]) from.push_back({&valid_[l][i].first, false, &cf_dead_[l][i]});
  }
  std::vector<Task> tasks;
  PcSetSet round_orbits;
  constexpr std::size_t kBlock = 4096;
  std::vector<std::vector<std::pair<PcSet, PcSet>>> kept;  // per set: (candidate, its orbit)
  for (std::size_t b = 0; b < from.size(); b += kBlock) {
    const std::size_t e = std::min(from.size(), b + kBlock);
    kept.assign(e - b, {});
    runner_.for_each(e - b, [&](std::size_t k) {
      const From& f = from[b + k];
      screen(*f.set, f.failed, *f.dead, kept[k]);
    });
    for (const auto& list : kept)
      for (const auto& [s, orbit] : list) {
        // Taken earlier this round, as itself or by another member of its orbit.
        if (near_searched_.count(s) || round_orbits.count(orbit) ||
            near_tries_[orbit] >= kOrbitTries)
          continue;
        round_orbits.insert(orbit);
        ++near_tries_[orbit];
        near_searched_.insert(s);
        Task t;
        t.kind = Task::Kind::kFindNear;
        t.pcs = s;
        changes_of(s, [&](const PcSet& n) {
          if (auto it = witness_rot_.find(n);
              it != witness_rot_.end() && t.seeds.size() < kNeighbourSeeds)
            t.seeds.push_back(it->second);
        });
        tasks.push_back(std::move(t));
      }
  }
  return tasks;
}

// One round; returns the number of CFs found.
std::size_t Enumerator::neighbour_round() {
  const auto t0 = Clock::now();
  std::vector<Task> tasks = neighbour_tasks();
  ProgressEvent ev{"neighbour round " + std::to_string(++neighbour_rounds_),
                   "failed sets",
                   0,
                   tasks.size(),
                   0,
                   false,
                   {}};
  const std::vector<TaskResult> r = run_tasks(runner_, tasks, &ev, t0);
  prefetch_found(tasks, r);
  std::size_t found = 0;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!r[i].witness.found || witness_rot_.count(tasks[i].pcs)) continue;
    const int level = tasks[i].pcs.size() - 1;
    const std::size_t before = valid_[level].size();
    accept(level, tasks[i].pcs, r[i].witness);
    ++out_.levels[level].by_neighbours;  // its images count under by_symmetry
    found += valid_[level].size() - before;
  }
  prefetched_.clear();
  finished(ev, t0, std::to_string(found) + " new CFs");
  return found;
}

}  // namespace cf::gen::internal

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

#include <string>

namespace cf::gen::internal {
namespace {

// Witnesses of neighbouring CFs a failed set is searched again from.
constexpr std::size_t kNeighbourSeeds = 16;

}  // namespace

// The sets one change away from s (one PC replaced by a neighbouring PC), in a fixed order.
void Enumerator::changes_of(const PcSet& s, const std::function<void(const PcSet&)>& fn) {
  for (int k = 0; k < s.size(); ++k) {
    auto nb = pc_neighbours_.find(s[k]);
    if (nb == pc_neighbours_.end())
      nb = pc_neighbours_.emplace(s[k], cf::neighbouring_pcs(s[k], A_, B_)).first;
    for (const Pc& q : nb->second) {
      PcSet n;
      for (int j = 0; j < s.size(); ++j) n.insert(j == k ? q : s[j]);
      if (n.size() == s.size()) fn(n);
    }
  }
}

// One round; returns the number of CFs found.
std::size_t Enumerator::neighbour_round() {
  const auto t0 = Clock::now();
  std::vector<Task> tasks;
  PcSetSet round_orbits;
  auto consider = [&](const PcSet& s) {
    if (witness_rot_.count(s) || near_searched_.count(s)) return;
    Task t;
    t.kind = Task::Kind::kFindNear;
    t.pcs = s;
    changes_of(s, [&](const PcSet& n) {
      if (auto it = witness_rot_.find(n);
          it != witness_rot_.end() && t.seeds.size() < kNeighbourSeeds)
        t.seeds.push_back(it->second);
    });
    if (t.seeds.empty()) return;
    const PcSet orbit = sym_.canonical(s);
    if (round_orbits.count(orbit) || near_tries_[orbit] >= kOrbitTries) return;
    round_orbits.insert(orbit);
    ++near_tries_[orbit];
    near_searched_.insert(s);
    tasks.push_back(std::move(t));
  };
  // The failed candidates, then the sets one change away from a CF that no level proposed (a
  // subset of theirs is missing) and that the necessary conditions allow.
  for (const PcSet& s : failed_) consider(s);
  for (int l = 0; l < 3; ++l)
    for (std::size_t i = 0; i < valid_[l].size(); ++i)
      changes_of(valid_[l][i].first, [&](const PcSet& n) {
        if (!witness_rot_.count(n) && !near_searched_.count(n) && !seen_.count(n) &&
            conditions_hold(n))
          consider(n);
      });
  ProgressEvent ev{"neighbour round " + std::to_string(++neighbour_rounds_),
                   "failed sets",
                   0,
                   tasks.size(),
                   0,
                   false,
                   {}};
  const std::vector<TaskResult> r = run_tasks(runner_, tasks, &ev, t0);
  std::size_t found = 0;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!r[i].witness.found || witness_rot_.count(tasks[i].pcs)) continue;
    const int level = tasks[i].pcs.size() - 1;
    const std::size_t before = valid_[level].size();
    accept(level, tasks[i].pcs, r[i].witness);
    ++out_.levels[level].by_neighbours;  // its images count under by_symmetry
    found += valid_[level].size() - before;
  }
  finished(ev, t0, std::to_string(found) + " new CFs");
  return found;
}

}  // namespace cf::gen::internal

// Closure by motion (explore.hpp): from every witness, translations and rotations that keep
// some PCs and break the others, to the first contact. Sets met that are not in the graph yet
// are searched (seeded with the rotation they were met at), and their own witnesses explored
// in the next round, until a round adds nothing. The contact sets the levels' failed searches
// met where their contacts were placed (forced contacts) are searched the same way.

#include "cfgen/enumerate/enumerator.hpp"

#include <algorithm>
#include <string>

namespace cf::gen::internal {
// More witnesses of each new orbit of the frontier, each found by its own search
// (kWitnessesPerOrbit), added to the frontier.
void Enumerator::more_witnesses(Clock::time_point t0) {
  std::vector<Task> more;
  PcSetSet orbits;
  for (const auto& [s, pose] : frontier_) {
    if (!orbits.insert(sym_.canonical(s)).second) continue;
    std::vector<PcSet> members;
    for (std::size_t k = 1; k < sym_.size(); ++k) members.push_back(sym_.image(s, k));
    std::sort(members.begin(), members.end(), pcset_less);
    members.erase(std::unique(members.begin(), members.end()), members.end());
    members.erase(std::remove(members.begin(), members.end(), s), members.end());
    const std::size_t step = std::max<std::size_t>(1, members.size() / (kWitnessesPerOrbit - 1));
    for (std::size_t i = 0, n = 1; i < members.size() && n < kWitnessesPerOrbit; i += step, ++n) {
      Task t;
      t.pcs = members[i];
      t.seeds = seeds_from_subsets(members[i]);
      more.push_back(t);
    }
  }
  const std::vector<TaskResult> r = run_tasks(runner_, more, nullptr, t0);
  prefetch_found(more, r);
  for (std::size_t i = 0; i < more.size(); ++i) {
    if (!r[i].witness.found) continue;
    if (witness_rot_.count(more[i].pcs)) {
      frontier_.push_back({more[i].pcs, r[i].witness.pose});
    } else {  // its image witness did not verify: a CF by its own witness
      mark_searched(more[i].pcs);
      accept(more[i].pcs.size() - 1, more[i].pcs, r[i].witness);
    }
  }
  prefetched_.clear();
}

// One motion round: the frontier explored, the new sets met searched, and the frontier
// replaced by what they add.
void Enumerator::explore_frontier(Clock::time_point t0) {
  ProgressEvent ev{"motion round " + std::to_string(++motion_rounds_),
                   "CFs explored",
                   0,
                   frontier_.size(),
                   0,
                   false,
                   {}};
  std::vector<Task> explore(frontier_.size());
  for (std::size_t i = 0; i < frontier_.size(); ++i) {
    explore[i].kind = Task::Kind::kExplore;
    explore[i].pcs = frontier_[i].first;
    explore[i].pose = frontier_[i].second;
  }
  const std::vector<TaskResult> met = run_tasks(runner_, explore, &ev, t0);
  std::vector<Discovery> all;
  for (const TaskResult& r : met) all.insert(all.end(), r.met.begin(), r.met.end());
  frontier_.clear();
  const std::size_t found = search_met(all, t0);
  finished(ev, t0, std::to_string(found) + " new CFs");
}

// The sets of `met` not in the graph yet that the necessary conditions allow, the first
// discovery of each in order (independent of thread count), one of each orbit: searched from
// the pose met (kFindOrRefine), those found accepted and added to the frontier with the pose
// met too. Returns how many were found.
std::size_t Enumerator::search_met(const std::vector<Discovery>& met, Clock::time_point t0) {
  std::vector<Discovery> fresh;
  PcSetSet pending;
  PcSetSet pending_orbits;  // one search per orbit a round
  for (const Discovery& d : met)
    if (d.pcs.size() <= opt_.max_pcs && !witness_rot_.count(d.pcs) &&
        pending.insert(d.pcs).second && conditions_hold(d.pcs) &&
        pending_orbits.insert(sym_.canonical(d.pcs)).second)
      fresh.push_back(d);
  std::vector<Task> search_fresh(fresh.size());
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    search_fresh[i].kind = Task::Kind::kFindOrRefine;
    search_fresh[i].pcs = fresh[i].pcs;
    search_fresh[i].pose = fresh[i].pose;
  }
  const std::vector<TaskResult> res = run_tasks(runner_, search_fresh, nullptr, t0);
  prefetch_found(search_fresh, res);
  std::size_t found = 0;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    if (!res[i].witness.found) continue;
    if (witness_rot_.count(fresh[i].pcs)) {
      frontier_.push_back({fresh[i].pcs, fresh[i].pose});
      continue;
    }
    const int level = fresh[i].pcs.size() - 1;
    mark_searched(fresh[i].pcs);
    accept(level, fresh[i].pcs, res[i].witness);
    // Explore from where motion met the set too: another pose in its region, which reaches
    // what the witness's orientation does not.
    frontier_.push_back({fresh[i].pcs, fresh[i].pose});
    ++out_.levels[level].by_motion;
    ++found;
  }
  prefetched_.clear();
  return found;
}

void Enumerator::motion_closure() {
  // The contact sets the levels' failed searches were blocked by (forced contacts) first.
  if (!forced_.empty()) {
    std::vector<Discovery> forced;
    forced.swap(forced_);
    search_met(forced, Clock::now());
  }
  while (!frontier_.empty()) {
    const auto t0 = Clock::now();
    if (sym_.size() > 1) more_witnesses(t0);
    explore_frontier(t0);
  }
}

}  // namespace cf::gen::internal

#include "cfgen/decide/task.hpp"

#include <algorithm>

namespace cf::gen {

namespace {

// The contact sets larger than `pcs` and holding all of it, read at the poses where a failed
// search placed its contacts and met another pair of elements: contacts such a pose forces (a
// part in a slot exactly its width touches both walls) make a set the levels may not propose
// (docs/generator.md, "Enumeration, level by level").
std::vector<Discovery> forced_supersets(const WitnessSearch& search, const PcSet& pcs,
                                        const std::vector<Pose>& blocked) {
  std::vector<Discovery> out;
  for (const Pose& pose : blocked) {
    PcSet t;
    if (!search.contacts_at(pose, t) || t.size() <= pcs.size()) continue;
    bool holds = true;
    for (const Pc& pc : pcs) holds = holds && t.contains(pc);
    const bool known =
        std::any_of(out.begin(), out.end(), [&](const Discovery& d) { return d.pcs == t; });
    if (holds && !known) out.push_back({t, pose});
  }
  return out;
}

}  // namespace

TaskResult decide(const WitnessSearch& search, const Task& task) {
  TaskResult r;
  switch (task.kind) {
    case Task::Kind::kFind: {
      std::vector<Pose> blocked;
      r.witness = search.find(task.pcs, task.seeds, false, &blocked);
      r.met = forced_supersets(search, task.pcs, blocked);
      break;
    }
    case Task::Kind::kFindNear:
      r.witness = search.find(task.pcs, task.seeds, true);
      break;
    case Task::Kind::kFindOrRefine:
      r.witness = search.find(task.pcs, {task.pose.R_BA});
      if (!r.witness.found) r.witness = search.refine(task.pcs, task.pose);
      break;
    case Task::Kind::kVerify:
      r.witness = search.image_witness(task.pcs, task.pose);
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

}  // namespace cf::gen

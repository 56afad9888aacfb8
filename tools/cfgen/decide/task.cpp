#include "cfgen/decide/task.hpp"

namespace cf::gen {

TaskResult decide(const WitnessSearch& search, const Task& task) {
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

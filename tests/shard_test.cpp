// Tests of the text form of cfgen's chunks of tasks and their results
// (tools/cfgen/execute/shard.cpp), which MPI ranks exchange: every kind of task and result comes
// back exactly, doubles to the last bit, and text that is not such a chunk is refused with a
// message naming it.

#include "cfgen/execute/shard.hpp"

#include <cf/types.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Pose;
using cf::Vec3;
using cf::gen::Task;
using cf::gen::TaskResult;

namespace {

// A pose whose numbers have no short decimal form.
Pose odd_pose(double s) {
  Pose p;
  p.R_BA = Eigen::AngleAxisd(s * std::sqrt(2.0), Vec3(1, std::sqrt(3.0), -M_PI).normalized())
               .toRotationMatrix();
  p.t_BA = Vec3(s / 3.0, -s * M_E, std::nextafter(s, 10.0));
  return p;
}

bool same(const Pose& a, const Pose& b) { return a.R_BA == b.R_BA && a.t_BA == b.t_BA; }

}  // namespace

TEST_CASE("chunks of tasks and their results round-trip exactly") {
  std::vector<Task> tasks(5);
  tasks[0].kind = Task::Kind::kFind;
  tasks[0].pcs = PcSet({Pc{PcType::kFF, 0, 4}, Pc{PcType::kEE, 7, 16}});
  tasks[0].seeds = {odd_pose(0.1).R_BA, odd_pose(0.7).R_BA};
  tasks[1].kind = Task::Kind::kFindOrRefine;
  tasks[1].pcs = PcSet({Pc{PcType::kVF, 3, 2}});
  tasks[1].pose = odd_pose(1.3);
  tasks[2].kind = Task::Kind::kExplore;
  tasks[2].pcs = PcSet({Pc{PcType::kEF, 1, 0}, Pc{PcType::kFE, 2, 5}, Pc{PcType::kFV, 4, 9}});
  tasks[2].pose = odd_pose(2.9);
  tasks[3].kind = Task::Kind::kFindNear;
  tasks[3].pcs = PcSet({Pc{PcType::kEE, 3, 8}, Pc{PcType::kVF, 0, 10}});
  tasks[3].seeds = {odd_pose(3.7).R_BA};
  tasks[4].kind = Task::Kind::kVerify;
  tasks[4].pcs = PcSet({Pc{PcType::kFV, 5, 1}});
  tasks[4].pose = odd_pose(4.1);

  std::size_t chunk = 0;
  const std::vector<Task> back =
      cf::tools::tasks_from_text(cf::tools::tasks_text(41, tasks), "tasks", chunk);
  CHECK(chunk == 41);
  REQUIRE(back.size() == tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    CHECK(back[i].kind == tasks[i].kind);
    CHECK(back[i].pcs == tasks[i].pcs);
    REQUIRE(back[i].seeds.size() == tasks[i].seeds.size());
    for (std::size_t k = 0; k < tasks[i].seeds.size(); ++k)
      CHECK(back[i].seeds[k] == tasks[i].seeds[k]);
    CHECK(same(back[i].pose, tasks[i].pose));
  }

  std::vector<TaskResult> results(3);
  results[0].witness.found = true;
  results[0].witness.pose = odd_pose(0.3);
  results[0].witness.clearance = 1.0 / 3.0;
  results[0].witness.margin = std::nextafter(0.01, 1.0);
  // results[1]: no witness.
  results[2].met.push_back({PcSet({Pc{PcType::kEE, 0, 1}}), odd_pose(4.1)});
  results[2].met.push_back({PcSet({Pc{PcType::kFF, 2, 3}, Pc{PcType::kVF, 5, 6}}), odd_pose(5.2)});
  const std::vector<TaskResult> rb =
      cf::tools::task_results_from_text(cf::tools::task_results_text(7, results), "results", chunk);
  CHECK(chunk == 7);
  REQUIRE(rb.size() == 3);
  CHECK(rb[0].witness.found);
  CHECK(same(rb[0].witness.pose, results[0].witness.pose));
  CHECK(rb[0].witness.clearance == results[0].witness.clearance);
  CHECK(rb[0].witness.margin == results[0].witness.margin);
  CHECK_FALSE(rb[1].witness.found);
  CHECK(rb[1].met.empty());
  REQUIRE(rb[2].met.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(rb[2].met[k].pcs == results[2].met[k].pcs);
    CHECK(same(rb[2].met[k].pose, results[2].met[k].pose));
  }
}

TEST_CASE("text that is not a chunk is refused with what and why") {
  std::size_t chunk = 0;
  auto refused = [&](const std::string& text) {
    try {
      cf::tools::tasks_from_text(text, "a chunk from rank 0", chunk);
    } catch (const cf::Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(refused("{\"chunk\": 3"),
             Catch::Matchers::StartsWith("reading a chunk from rank 0: not JSON"));
  CHECK(refused("{\"tasks\": []}") ==
        "reading a chunk from rank 0: expected {\"chunk\", \"tasks\"}");
  CHECK(refused("{\"chunk\": 1, \"tasks\": [[9, [[0, 1, 2]], [], []]]}") ==
        "reading a chunk from rank 0: expected a task [kind, PCs, seeds, pose]");
  // One past the last kind (kVerify, 4).
  CHECK(refused("{\"chunk\": 1, \"tasks\": [[5, [[0, 1, 2]], [], [1,0,0,0,1,0,0,0,1,0,0,0]]]}") ==
        "reading a chunk from rank 0: expected a task [kind, PCs, seeds, pose]");
  CHECK(refused("{\"chunk\": 1, \"tasks\": [[0, [[0, 1, 2], [0, 1, 2]], [], " +
                std::string("[1,0,0,0,1,0,0,0,1,0,0,0]]]}")) ==
        "reading a chunk from rank 0: a PC is repeated");
  CHECK(refused("{\"chunk\": 1, \"tasks\": [[0, [[6, 1, 2]], [], [1,0,0,0,1,0,0,0,1,0,0,0]]]}") ==
        "reading a chunk from rank 0: expected a PC [type, a, b]");
  CHECK(refused("{\"chunk\": 1, \"tasks\": [[0, [[0, 1, 2]], [], [1,0,0,0,1,0,0,0,1,0,0]]]}") ==
        "reading a chunk from rank 0: expected a pose of 12 numbers");
  CHECK_THROWS_WITH(cf::tools::task_results_from_text("{\"chunk\": 0, \"results\": [[[true], []]]}",
                                                      "the results of rank 1", chunk),
                    "reading the results of rank 1: expected [true, pose, clearance, margin]");
}

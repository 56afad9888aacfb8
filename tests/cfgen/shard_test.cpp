// Tests of the text form of cfgen's chunks of results (tools/cfgen/execute/shard.cpp), which
// MPI ranks exchange: every kind of result comes back exactly, doubles to the last bit, and
// text that is not such a chunk is refused with a message naming it.

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

TEST_CASE("a chunk's results round-trip exactly") {
  std::vector<TaskResult> results(3);
  results[0].witness.found = true;
  results[0].witness.pose = odd_pose(0.3);
  results[0].witness.clearance = 1.0 / 3.0;
  results[0].witness.margin = std::nextafter(0.01, 1.0);
  // results[1]: no witness.
  results[2].met.push_back({PcSet({Pc{PcType::kEE, 0, 1}}), odd_pose(4.1)});
  results[2].met.push_back({PcSet({Pc{PcType::kFF, 2, 3}, Pc{PcType::kVF, 5, 6}}), odd_pose(5.2)});
  // The enumeration's own results: sets.
  results[1].sets = {PcSet({Pc{PcType::kEE, 3, 8}, Pc{PcType::kVF, 0, 10}}),
                     PcSet({Pc{PcType::kFV, 4, 9}})};
  std::size_t stage = 0, chunk = 0;
  const std::vector<TaskResult> rb =
      cf::tools::chunk_from_text(cf::tools::chunk_text(12, 7, results), "results", stage, chunk);
  CHECK(stage == 12);
  CHECK(chunk == 7);
  REQUIRE(rb.size() == 3);
  CHECK(rb[0].witness.found);
  CHECK(same(rb[0].witness.pose, results[0].witness.pose));
  CHECK(rb[0].witness.clearance == results[0].witness.clearance);
  CHECK(rb[0].witness.margin == results[0].witness.margin);
  CHECK_FALSE(rb[1].witness.found);
  CHECK(rb[1].met.empty());
  CHECK(rb[1].sets == results[1].sets);
  CHECK(rb[0].sets.empty());
  REQUIRE(rb[2].met.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(rb[2].met[k].pcs == results[2].met[k].pcs);
    CHECK(same(rb[2].met[k].pose, results[2].met[k].pose));
  }
}

TEST_CASE("text that is not a chunk is refused with what and why") {
  std::size_t stage = 0, chunk = 0;
  auto refused = [&](const std::string& text) {
    try {
      cf::tools::chunk_from_text(text, "a chunk from rank 1", stage, chunk);
    } catch (const cf::Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string head = "{\"stage\": 2, \"chunk\": 1, \"results\": ";
  const std::string pose = "[1,0,0,0,1,0,0,0,1,0,0,0]";
  CHECK_THAT(refused("{\"chunk\": 3"),
             Catch::Matchers::StartsWith("reading a chunk from rank 1: not JSON"));
  CHECK(refused("{\"chunk\": 1, \"results\": []}") ==
        "reading a chunk from rank 1: expected {\"stage\", \"chunk\", \"results\"}");
  CHECK(refused("{\"stage\": -1, \"chunk\": 1, \"results\": []}") ==
        "reading a chunk from rank 1: expected {\"stage\", \"chunk\", \"results\"}");
  CHECK(refused(head + "[[[true], []]]}") ==
        "reading a chunk from rank 1: expected [true, pose, clearance, margin]");
  CHECK(refused(head + "[[[false], [], [], []]]}") ==
        "reading a chunk from rank 1: expected a result [witness, met] or [witness, met, sets]");
  CHECK(refused(head + "[[[false], [[[[0, 1, 2]], [1,0,0]]]]]}") ==
        "reading a chunk from rank 1: expected a pose of 12 numbers");
  // Sets: "t.a.b,t.a.b t.a.b", PCs by ',', sets by ' '.
  CHECK(refused(head + "[[[false], [], \"0.1.2,0.1.2\"]]}") ==
        "reading a chunk from rank 1: a PC is repeated");
  const std::string form = "reading a chunk from rank 1: expected sets as \"t.a.b,t.a.b t.a.b\"";
  CHECK(refused(head + "[[[false], [], \"6.1.2\"]]}") == form);  // no PC type 6
  CHECK(refused(head + "[[[false], [], \"0.1\"]]}") == form);
  CHECK(refused(head + "[[[false], [], \"0.1.2 \"]]}") == form);
  CHECK(refused(head + "[[[false], [], \"0.1.2,1.1.2,2.1.2,3.1.2\"]]}") == form);  // 4 PCs
  CHECK(refused(head + "[[[false], [], \"0.1.99999999999\"]]}") == form);
  CHECK(refused(head + "[[[false], [], [[0, 1, 2]]]]}") ==
        "reading a chunk from rank 1: expected a result [witness, met] or [witness, met, sets]");
  CHECK(refused(head + "[[[true, " + pose + ", 0.5, 0.1], []]]}") == "accepted");
  CHECK(stage == 2);
}

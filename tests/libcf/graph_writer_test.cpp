// The graph writer (libcf/src/io/graph_writer.*, graph_json.cpp): one description of each
// record, written as JSON text or as CBOR. The CBOR must be exactly what nlohmann's to_cbor
// makes of the same document, and saving must stream (never a DOM of the whole graph).

#include <cf/graph.hpp>
#include "synthetic_graph.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The CBOR nlohmann writes for the document `json` holds (key order kept).
std::string nlohmann_cbor(const std::string& json) {
  const std::vector<std::uint8_t> bytes =
      nlohmann::ordered_json::to_cbor(nlohmann::ordered_json::parse(json));
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace

TEST_CASE("a graph saved as CBOR is the bytes nlohmann's to_cbor makes of its JSON",
          "[graph][writer]") {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("cf_graph_writer_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<cf::CfGraph> graphs;
  for (const char* name : {"cube_l_block", "cube_corner_block", "peg_hole_block"})
    graphs.push_back(
        cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/" + name + ".json"));
  graphs.push_back(cf::test::synthetic_graph(20000));  // 5 MB of CBOR: written in pieces
  for (const cf::CfGraph& g : graphs) {
    INFO(g.model_b().name() << ", " << g.num_cfs() << " CFs");
    const auto path = dir / "g.cbor";
    g.save(path.string());
    const std::string cbor = slurp(path);
    CHECK(cbor == nlohmann_cbor(g.to_json()));
    // And it reads back to the same JSON.
    CHECK(cf::CfGraph::load(path.string()).to_json(1) == g.to_json(1));
  }
  std::filesystem::remove_all(dir);
}

// Tests of the certificate file (tools/cfgen/certificate_file.cpp, docs/certificates.md): what
// it lists agrees with the graph written beside it, its trees are well formed, and its paths
// are checked like the graph's. The evidence itself is rechecked by the independent checker
// (tests/oracle/certificate_check.cpp, ctest cfgen_certificates:*).

#include "cfgen/generate.hpp"
#include "scratch.hpp"

#include <cf/graph.hpp>
#include <cf/types.hpp>

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using nlohmann::json;

cf::tools::GenerateArgs cube_and_corner(const std::string& graph, const std::string& certificates) {
  cf::tools::GenerateArgs args;
  args.a_path = std::string(CF_SOURCE_DIR) + "/data/models/cube.off";
  args.b_path = std::string(CF_SOURCE_DIR) + "/data/models/corner_block.off";
  args.out_path = (cf::test::scratch() / graph).string();
  args.certificates_path =
      certificates.empty() ? "" : (cf::test::scratch() / certificates).string();
  args.quiet = true;
  args.threads = 2;
  return args;
}

json read_json(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in);
  return json::parse(in);
}

// Parents before children; a split has its 8 or 2 (rotation) or 2 (translation) children; a
// leaf none; no leaf left open in a certificate of an invalid set.
void check_tree(const json& nodes, const std::string& set) {
  INFO(set);
  REQUIRE(!nodes.empty());
  std::vector<int> children(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    CHECK(nodes[i]["id"] == static_cast<int>(i));
    const int parent = nodes[i]["parent"];
    CHECK((i == 0 ? parent == -1 : (parent >= 0 && parent < static_cast<int>(i))));
    if (parent >= 0) ++children[static_cast<std::size_t>(parent)];
  }
  const std::set<std::string> leaves{"outside-ball", "bounds",  "rotation", "cone",
                                     "local-slack",  "program", "deep"};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::string kind = nodes[i]["kind"];
    INFO("node " << i << " " << kind);
    if (kind == "split-rotation")
      CHECK((children[i] == 8 || children[i] == 2));
    else if (kind == "split-translation")
      CHECK(children[i] == 2);
    else if (kind == "narrow")
      CHECK((children[i] >= 2 && children[i] <= 7));
    else
      CHECK((leaves.count(kind) == 1 && children[i] == 0));
  }
}

}  // namespace

TEST_CASE(
    "the certificate file lists every failed set the graph does not hold, as its stats "
    "count them",
    "[certificates]") {
  REQUIRE(cf::tools::run_generate(cube_and_corner("g.json", "c.json")) == 0);
  const json g = read_json((cf::test::scratch() / "g.json").string());
  const json c = read_json((cf::test::scratch() / "c.json").string());
  CHECK(c["format"] == "cf-certificates");
  CHECK(c["version"] == 1);
  // The decision's tolerances: the graph's touch tolerance, and a THIN pose's margin (4 touch
  // tolerances), so that a refuted set is not THIN either.
  CHECK(c["tolerances"]["touch_tol_mm"] == g["parameters"]["touch_tol_mm"]);
  CHECK(c["tolerances"]["min_margin_mm"].get<double>() ==
        4 * g["parameters"]["touch_tol_mm"].get<double>());
  const json& sets = c["sets"];
  const json& summary = c["summary"];
  CHECK(summary["sets"] == sets.size());
  CHECK(summary["undecided"] == g["stats"]["undecided"]);
  CHECK(summary["invalid_by_cells"].get<int>() + summary["invalid_as_image"].get<int>() ==
        g["stats"]["refuted_over_cells"]);
  // The cube against the corner block has every outcome but thin (docs/generator.md's table:
  // 456 failed sets the rules leave, 216 of them refuted over cells, one set an orbit).
  CHECK(summary["undecided"] == 240);
  CHECK(summary["invalid_by_cells"].get<int>() + summary["invalid_as_image"].get<int>() == 216);
  CHECK(summary["invalid_as_image"] > summary["invalid_by_cells"]);
  CHECK(summary["invalid_by_rule"] > 0);
  const cf::CfGraph graph = cf::CfGraph::load((cf::test::scratch() / "g.json").string());
  std::set<std::string> in_graph;
  for (std::size_t i = 0; i < graph.num_cfs(); ++i)
    in_graph.insert(cf::to_string(graph.cf(cf::CfId(static_cast<int>(i))).pcs));
  std::set<std::string> listed;
  std::map<std::string, const json*> by_cells;
  std::vector<const json*> images;
  std::size_t by_rule = 0, mirror = 0;
  for (const json& s : sets) {
    const std::string pcs = s["pcs"];
    CHECK(in_graph.count(pcs) == 0);
    CHECK(listed.insert(pcs).second);  // each once
    if (s["outcome"] == "undecided") continue;
    REQUIRE(s["outcome"] == "invalid");
    if (s.contains("rule")) {
      ++by_rule;
      // The only rules left to failed sets here (the others reject candidates before a search).
      CHECK((s["rule"] == "rotational-conditions" || s["rule"] == "mirror-corners"));
      mirror += s["rule"] == "mirror-corners";
    } else if (s.contains("image_of")) {
      images.push_back(&s);
    } else {
      check_tree(s["cells"]["nodes"], pcs);
      by_cells[pcs] = &s;
    }
  }
  CHECK(summary["invalid_by_rule"] == by_rule);
  // Two e-e PCs at the corner block's three saddle corners, in the mirror order: 3 x 24.
  CHECK(mirror == 72);
  // Each image names a set refuted over cells, whose tree was built with tolerances looser
  // than the file's by how far the maps miss (docs/certificates.md, "Images").
  for (const json* s : images) {
    const auto it = by_cells.find((*s)["image_of"]["pcs"].get<std::string>());
    REQUIRE(it != by_cells.end());
    const json& t = (*it->second)["cells"]["tolerances"];
    CHECK(t["touch_tol_mm"].get<double>() > c["tolerances"]["touch_tol_mm"].get<double>());
    CHECK(t["local_slack"].get<double>() < c["tolerances"]["local_slack"].get<double>());
    CHECK(t["rot_tol_rad"].get<double>() > c["tolerances"]["rot_tol_rad"].get<double>());
    CHECK((*s)["image_of"]["A"]["R"].size() == 9);
    CHECK((*s)["image_of"]["B"]["c"].size() == 3);
  }
  // The undecided sets the graph lists (the first 100) are the file's first undecided ones.
  std::vector<std::string> undecided;
  for (const json& s : sets)
    if (s["outcome"] == "undecided" && undecided.size() < g["stats"]["undecided_sets"].size())
      undecided.push_back(s["pcs"]);
  CHECK(json(undecided) == g["stats"]["undecided_sets"]);
}

namespace {

// The 30 mm cube against a U-channel whose slot is 30 + gap wide (profile in x-y, slot walls at
// x = 30 and 60 + gap, floor y = 10, extruded over z in [0, 60]); graph and certificate file.
struct SlotRun {
  json g, c;                  // the graph and the certificate file
  std::set<std::string> cfs;  // the graph's CFs' PC lists
};

SlotRun cube_in_slot(double gap, const std::string& name) {
  std::string b_path = std::string(CF_SOURCE_DIR) + "/tests/data/models/tight_slot.off";
  if (gap != 0.004) {
    const double w = 60 + gap, o = 90 + gap;
    std::ostringstream os;
    os.precision(17);
    os << "OFF\n16 10 0\n";
    const double prof[8][2] = {{0, 0},  {o, 0},   {o, 30},  {w, 30},
                               {w, 10}, {30, 10}, {30, 30}, {0, 30}};
    for (double z : {0.0, 60.0})
      for (const auto& p : prof) os << p[0] << ' ' << p[1] << ' ' << z << '\n';
    os << "8 7 6 5 4 3 2 1 0\n8 8 9 10 11 12 13 14 15\n";
    for (int i = 0; i < 8; ++i)
      os << "4 " << i << ' ' << (i + 1) % 8 << ' ' << 8 + (i + 1) % 8 << ' ' << 8 + i << '\n';
    b_path = cf::test::write_file(name + ".off", os.str());
  }
  cf::tools::GenerateArgs args = cube_and_corner(name + ".json", name + "_c.json");
  args.b_path = b_path;
  REQUIRE(cf::tools::run_generate(args) == 0);
  SlotRun r{read_json(args.out_path), read_json(args.certificates_path), {}};
  const cf::CfGraph graph = cf::CfGraph::load(args.out_path);
  for (std::size_t i = 0; i < graph.num_cfs(); ++i)
    r.cfs.insert(cf::to_string(graph.cf(cf::CfId(static_cast<int>(i))).pcs));
  return r;
}

// "f-f:i:w" for each face i of A and each face w of B in the plane x = wall_x.
std::set<std::string> faces_on_walls(const json& g, std::vector<double> walls_x) {
  std::set<std::string> out;
  const json& B = g["models"]["B"];
  for (std::size_t w = 0; w < B["faces"].size(); ++w) {
    const json& loop = B["faces"][w]["loops"][0];
    for (double x : walls_x) {
      bool on = true;
      for (const json& v : loop)
        on = on && std::abs(B["vertices"][v.get<int>()][0].get<double>() - x) < 1e-9;
      if (!on) continue;
      for (int i = 0; i < 6; ++i) out.insert("f-f:" + std::to_string(i) + ":" + std::to_string(w));
    }
  }
  return out;
}

}  // namespace

TEST_CASE("THIN sets: realised only below the witnesses' clearance, listed, not CFs",
          "[certificates]") {
  // 4 um to spare: a face of the cube on a wall of the slot has the other wall 4 um away, below
  // the default min_clearance (2e-4 x D = 0.0104 mm); with 0.4 mm the same sets are CFs.
  const SlotRun tight = cube_in_slot(0.004, "tight_slot");
  const json &g = tight.g, &c = tight.c;
  const std::set<std::string> on_walls = faces_on_walls(g, {30.0, 60.004});
  REQUIRE(on_walls.size() == 12);
  std::set<std::string> thin;
  const double min_clearance = g["parameters"]["min_clearance_mm"];
  const double touch_tol = g["parameters"]["touch_tol_mm"];
  const json& listed = g["stats"]["thin_sets"];
  CHECK(g["stats"]["thin"] == listed.size());
  for (const json& t : listed) {
    const std::string pcs = t["pcs"];
    INFO(pcs);
    CHECK(tight.cfs.count(pcs) == 0);
    CHECK(t["clearance_mm"].get<double>() < min_clearance);
    CHECK(t["clearance_mm"].get<double>() >= 4 * touch_tol);
    thin.insert(pcs);
  }
  for (const std::string& s : on_walls) {
    INFO(s);
    CHECK(thin.count(s) == 1);
  }
  // A face on a wall lacks clearance, not room: its overlap with the wall lies well inside both
  // faces, and margin_mm is the verifier's contact margin at the pose found (the images of one
  // pose under the pair's symmetries have the same), not what the search that found it used.
  const double min_margin = g["parameters"]["min_margin_mm"];
  for (const json& t : listed)
    if (on_walls.count(t["pcs"])) {
      INFO(t["pcs"].get<std::string>());
      CHECK(t["margin_mm"].get<double>() >= min_margin);
    }
  // The certificate file lists the same sets as "thin", with the same poses.
  json from_file = json::array();
  for (json s : c["sets"])
    if (s["outcome"] == "thin") {
      s.erase("outcome");
      from_file.push_back(s);
    }
  CHECK(from_file == listed);
  CHECK(c["summary"]["thin"] == listed.size());

  const SlotRun wide = cube_in_slot(0.4, "wide_slot");
  const std::set<std::string> wide_walls = faces_on_walls(wide.g, {30.0, 60.4});
  REQUIRE(wide_walls.size() == 12);
  for (const std::string& s : wide_walls) {
    INFO(s);
    CHECK(wide.cfs.count(s) == 1);
  }
  for (const json& t : wide.g["stats"]["thin_sets"]) CHECK(wide_walls.count(t["pcs"]) == 0);
}

TEST_CASE("the graph does not depend on whether certificates are written", "[certificates]") {
  REQUIRE(cf::tools::run_generate(cube_and_corner("with.json", "with_c.json")) == 0);
  REQUIRE(cf::tools::run_generate(cube_and_corner("without.json", "")) == 0);
  json with = read_json((cf::test::scratch() / "with.json").string());
  json without = read_json((cf::test::scratch() / "without.json").string());
  with.erase("generator");  // names the output path
  without.erase("generator");
  CHECK(with == without);
}

TEST_CASE("the certificate file's path is checked before the run like the graph's",
          "[certificates]") {
  auto message = [](const cf::tools::GenerateArgs& args) {
    try {
      cf::tools::run_generate(args);
    } catch (const cf::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  cf::tools::GenerateArgs args = cube_and_corner("p.json", "");
  args.certificates_path = args.out_path;
  CHECK(message(args) == "writing certificates '" + args.out_path + "': is also the output '" +
                             args.out_path + "'; each output needs its own file");
  args.certificates_path = args.b_path;
  CHECK(message(args).rfind("writing certificates '" + args.b_path + "': ", 0) == 0);
  args.certificates_path = cf::test::scratch().string();
  CHECK(message(args).rfind("writing certificates '" + args.certificates_path + "': ", 0) == 0);
  CHECK_FALSE(std::ifstream(args.out_path));  // nothing written
}

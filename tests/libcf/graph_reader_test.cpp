// The graph reader on files of the sizes and layouts it meets (libcf/src/io/graph_reader.cpp,
// json_stream.*): a file is read in windows and its items in batches of about 1 MiB, so
// these tests use graphs of several MiB, laid out as cfgen writes them (an item a line), on
// one line, with every value on a line of its own, and with CRLF line ends; faults far into a
// file; and files whose bulk is not in the items.

#include <cf/graph.hpp>
#include "synthetic_graph.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using cf::CfGraph;
using cf::CfId;

// 30,000 CFs and 110,976 transitions: 12 MB of JSON, a dozen batches and several windows.
const CfGraph& big_graph() {
  static const CfGraph g = cf::test::synthetic_graph(30000);
  return g;
}

void check_same(const CfGraph& x, const CfGraph& y) {
  REQUIRE(x.num_cfs() == y.num_cfs());
  REQUIRE(x.num_transitions() == y.num_transitions());
  bool same = true;
  for (std::size_t i = 0; i < x.num_cfs() && same; ++i) {
    const cf::CfRecord& a = x.cf(CfId(static_cast<int>(i)));
    const cf::CfRecord& b = y.cf(CfId(static_cast<int>(i)));
    same = a.pcs == b.pcs && a.witness.R_BA == b.witness.R_BA && a.witness.t_BA == b.witness.t_BA &&
           a.dof == b.dof && a.translation_dof == b.translation_dof &&
           a.pure_rotation == b.pure_rotation && a.num_planes == b.num_planes &&
           a.planes == b.planes;
    if (!same) INFO("CF " << i);
  }
  CHECK(same);
  for (std::size_t i = 0; i < x.num_transitions() && same; ++i)
    same = x.transition(i).from == y.transition(i).from &&
           x.transition(i).to == y.transition(i).to && x.transition(i).kind == y.transition(i).kind;
  CHECK(same);
  CHECK(x.metadata_json() == y.metadata_json());
}

/// Line and column (1-based) of byte `at` of `text`.
std::string line_col(const std::string& text, std::size_t at) {
  const std::size_t line = 1 + static_cast<std::size_t>(std::count(
                                   text.begin(), text.begin() + static_cast<long>(at), '\n'));
  const std::size_t start = at == 0 ? 0 : text.rfind('\n', at - 1);
  const std::size_t col = start == std::string::npos ? at + 1 : at - start;
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

}  // namespace

TEST_CASE("a large graph reads the same in every layout", "[graph][reader]") {
  const CfGraph& g = big_graph();
  const std::string lines = g.to_json(1);  // cfgen's layout: an item a line
  REQUIRE(lines.size() > 10'000'000);
  check_same(g, CfGraph::from_bytes(lines, "lines.json", false));
  check_same(g, CfGraph::from_bytes(g.to_json(-1), "one_line.json", false));
  // Every value on a line of its own (Python's json.dump(indent=2)), keys sorted (cfs first:
  // the format is looked for before them).
  const std::string pretty = nlohmann::json::parse(lines).dump(2);
  check_same(g, CfGraph::from_bytes(pretty, "pretty.json", false));
  std::string crlf;
  crlf.reserve(lines.size() + lines.size() / 8);
  for (const char c : lines) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  check_same(g, CfGraph::from_bytes(crlf, "crlf.json", false));
  const std::vector<std::uint8_t> cbor = nlohmann::json::to_cbor(nlohmann::json::parse(lines));
  check_same(g, CfGraph::from_bytes(std::string(cbor.begin(), cbor.end()), "g.cbor", true));
}

TEST_CASE("a graph cfgen wrote reads and writes back byte for byte", "[graph][reader]") {
  // The bundled graphs hold every member a CF can have, planes included.
  for (const char* name : {"cube_l_block", "cube_corner_block", "peg_hole_block"}) {
    INFO(name);
    const std::string path = std::string(CF_SOURCE_DIR) + "/data/graphs/" + name + ".json";
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const CfGraph g = CfGraph::load(path);
    CHECK(g.cf(CfId(0)).num_planes == g.cf(CfId(0)).pcs.size());
    CHECK(g.to_json(1) == text.str());
  }
}

TEST_CASE("planes are read in the PCs' order, one per PC", "[graph][reader]") {
  const CfGraph base = cf::test::synthetic_graph(1000);  // the single PCs, then pairs
  std::vector<cf::CfRecord> cfs;
  std::vector<cf::Transition> transitions;
  for (std::size_t i = 0; i < base.num_cfs(); ++i) {
    cf::CfRecord r = base.cf(CfId(static_cast<int>(i)));
    r.num_planes = r.pcs.size();
    for (int k = 0; k < r.num_planes; ++k)
      r.planes[static_cast<std::size_t>(k)] = {0.6, 0.0, 0.8, 10.0 * static_cast<double>(i) + k};
    cfs.push_back(r);
  }
  for (std::size_t i = 0; i < base.num_transitions(); ++i)
    transitions.push_back(base.transition(i));
  const CfGraph g =
      CfGraph::from_parts(base.model_a(), base.model_b(), std::move(cfs), std::move(transitions));
  nlohmann::json doc = nlohmann::json::parse(g.to_json());
  std::size_t two = 0;  // the first CF of two PCs
  while (two + 1 < doc["cfs"].size() && doc["cfs"][two]["pcs"].size() != 2) ++two;
  REQUIRE(doc["cfs"][two]["pcs"].size() == 2);
  for (const char* member : {"pcs", "planes"}) {
    nlohmann::json& list = doc["cfs"][two][member];
    std::swap(list[0], list[1]);
  }
  check_same(g, CfGraph::from_bytes(doc.dump(), "swapped.json", false));
  doc["cfs"][two]["planes"].erase(1);
  CHECK_THROWS_WITH(CfGraph::from_bytes(doc.dump(), "x.json", false),
                    Catch::Contains("reading 'x.json' at /cfs/" + std::to_string(two) +
                                    "/planes: 1 planes for 2 PCs (one per PC"));
}

TEST_CASE("members and items larger than a batch are read in pieces", "[graph][reader]") {
  // A metadata member of 300,000 numbers (2 MB) and a CF with an extra member as large: both
  // longer than a batch, so read member by member and item by item.
  std::string numbers;
  for (int i = 0; i < 300000; ++i) numbers += (i ? "," : "") + std::to_string(i * 7);
  const CfGraph base = cf::test::synthetic_graph(300);
  const CfGraph g = CfGraph::from_parts(
      base.model_a(), base.model_b(),
      [&] {
        std::vector<cf::CfRecord> cfs;
        for (std::size_t i = 0; i < base.num_cfs(); ++i)
          cfs.push_back(base.cf(CfId(static_cast<int>(i))));
        return cfs;
      }(),
      [&] {
        std::vector<cf::Transition> t;
        for (std::size_t i = 0; i < base.num_transitions(); ++i) t.push_back(base.transition(i));
        return t;
      }(),
      R"({"stats":{"big":[)" + numbers + "]}}");
  for (const int indent : {1, -1}) {
    std::string text = g.to_json(indent);
    check_same(g, CfGraph::from_bytes(text, "big_meta.json", false));
    // CFs may carry members of their own, which the reader skips.
    const std::size_t first_cf = text.find("{\"id\":0,");
    REQUIRE(first_cf != std::string::npos);
    text.insert(first_cf + 1, "\"extra\":[" + numbers + "],");
    check_same(g, CfGraph::from_bytes(text, "big_item.json", false));
  }
}

TEST_CASE("a fault far into a large file gives its line and column", "[graph][reader]") {
  const CfGraph& g = big_graph();
  for (const int indent : {1, -1}) {
    INFO("indent " << indent);
    std::string text = g.to_json(indent);
    // An invalid literal in a CF past the middle of the file, 'fals' for 'false'.
    const std::size_t at = text.find("\"pure_rotation\":false", text.size() / 2) + 16;
    REQUIRE(at > text.size() / 2);
    text.erase(at + 4, 1);
    CHECK_THROWS_WITH(CfGraph::from_bytes(text, "x.json", false),
                      Catch::Contains("reading 'x.json': not valid JSON: syntax error at " +
                                      line_col(text, at) + " near 'f': invalid literal"));
  }
  // A member missing its ':' in the 100,000th transition.
  std::string text = g.to_json(1);
  std::size_t at = text.find("\"transitions\"");
  for (int k = 0; k <= 100000; ++k) at = text.find("{\"from\"", at + 1);
  at = text.find("\"kind\":", at) + 6;
  text[at] = ' ';
  CHECK_THROWS_WITH(CfGraph::from_bytes(text, "x.json", false),
                    Catch::Contains("syntax error at " + line_col(text, at).substr(0, 12)));
  // A value out of range there is named by its pointer.
  text = g.to_json(1);
  at = text.find("\"transitions\"");
  for (int k = 0; k <= 100000; ++k) at = text.find("{\"from\"", at + 1);
  at = text.find("\"to\":", at) + 5;
  text.insert(at, "9");
  CHECK_THROWS_WITH(CfGraph::from_bytes(text, "x.json", false),
                    Catch::Contains("reading 'x.json' at /transitions/100000/to: to = 9"));
  // A comma after the last item.
  text = g.to_json(1);
  at = text.rfind('}', text.rfind(']'));
  text.insert(at + 1, ",");
  CHECK_THROWS_WITH(
      CfGraph::from_bytes(text, "x.json", false),
      Catch::Contains("syntax error at " + line_col(text, text.rfind(']')) + " near ']'"));
}

TEST_CASE("brackets the input ends inside, or that close another kind, are refused unread",
          "[graph][reader][bad]") {
  // simdjson's On-Demand parser must not walk unbalanced brackets (a fuzzer's input, now
  // fuzz/regressions/fuzz_graph_json/unbalanced_nested_member.json, made it read past its
  // index): the framing refuses them first, with the position.
  const std::string nested = std::string(26, '[');
  CHECK_THROWS_WITH(CfGraph::from_bytes("{\"x\":" + nested + "\n{\"x\":" + nested, "x.json", false),
                    Catch::Contains("syntax error at line 2, column 32 at the end of the input"));
  const std::string head = R"({"format":"cf-graph","version":1,)";
  CHECK_THROWS_WITH(CfGraph::from_bytes(head + R"("x":[[[1,2}]]})", "x.json", false),
                    Catch::Contains("syntax error at line 1, column 44 near '}'"));
  CHECK_THROWS_WITH(
      CfGraph::from_bytes(head + R"("cfs":[{"id":0,"pcs":[}],"transitions":[]})", "x.json", false),
      Catch::Contains("syntax error at line 1, column 56 near '}'"));
  CHECK_THROWS_WITH(CfGraph::from_bytes(head + R"("cfs":[{"id":0},[[[)", "x.json", false),
                    Catch::Contains("at the end of the input"));
}

TEST_CASE("a file's models and metadata hold at most one value per 32 bytes of it",
          "[graph][reader][bad]") {
  // 3 million values in a member of its own (6 MB): a DOM of them would take ten times that.
  std::string zeros = "0";
  for (int i = 1; i < 3000000; ++i) zeros += ",0";
  const std::string json = R"({"format":"cf-graph","version":1,"x":[)" + zeros + "]}";
  const std::string expected =
      "at /x: the members other than cfs and transitions hold more than 2097152 values";
  CHECK_THROWS_WITH(CfGraph::from_bytes(json, "x.json", false), Catch::Contains(expected));
  const std::vector<std::uint8_t> cbor = nlohmann::json::to_cbor(nlohmann::json::parse(json));
  CHECK_THROWS_WITH(CfGraph::from_bytes(std::string(cbor.begin(), cbor.end()), "x.cbor", true),
                    Catch::Contains(expected));
  // As many members of the root each count.
  std::string keys = R"({"format":"cf-graph","version":1)";
  for (int i = 0; i < 2200000; ++i) keys += ",\"k" + std::to_string(i) + "\":0";
  CHECK_THROWS_WITH(CfGraph::from_bytes(keys + "}", "k.json", false),
                    Catch::Contains("the members other than cfs and transitions hold more than"));
}

namespace {

// Every value at or below `at` in `j`, by JSON pointer.
void paths_below(const nlohmann::json& j, const nlohmann::json::json_pointer& at,
                 std::vector<nlohmann::json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) paths_below(it.value(), at / it.key(), out);
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) paths_below(j[i], at / i, out);
}

bool loads(const std::string& text, bool full) {
  cf::GraphLoadOptions options;
  options.full_schema_check = full;
  try {
    CfGraph::from_bytes(text, "m.json", false, options);
    return true;
  } catch (const cf::Error&) {
    return false;
  }
}

}  // namespace

TEST_CASE("the reader refuses every item the schema refuses", "[graph][reader][schema]") {
  // cfinspect and every loader check the items of cfs and transitions with the reader's own
  // rules, not valijson (which takes 6 s on a graph of 2.8 million transitions): those rules
  // must hold at least what the schema says. Every value of a CF (with planes and freedoms)
  // and of a transition is replaced by values of each type and range, or removed, and every
  // object gains an unknown member; whatever the full schema check refuses, the reader must.
  // Three CFs, {p}, {q} and {p, q}, of the synthetic graph, and the four transitions of the
  // pair.
  const CfGraph base = cf::test::synthetic_graph(700);
  const cf::CfRecord& pair = base.cf(CfId(static_cast<int>(base.num_cfs() - 1)));
  REQUIRE(pair.pcs.size() == 2);
  std::vector<cf::CfRecord> cfs = {base.cf(*base.find(cf::PcSet({pair.pcs[0]}))),
                                   base.cf(*base.find(cf::PcSet({pair.pcs[1]}))), pair};
  for (cf::CfRecord& r : cfs) {
    r.num_planes = r.pcs.size();
    for (int k = 0; k < r.num_planes; ++k) r.planes[static_cast<std::size_t>(k)] = {0, 0, 1, 2.5};
  }
  using K = cf::TransitionKind;
  std::vector<cf::Transition> transitions = {{CfId(0), CfId(2), K::kGain},
                                             {CfId(1), CfId(2), K::kGain},
                                             {CfId(2), CfId(0), K::kLose},
                                             {CfId(2), CfId(1), K::kLose}};
  const nlohmann::json doc = nlohmann::json::parse(
      CfGraph::from_parts(base.model_a(), base.model_b(), std::move(cfs), std::move(transitions))
          .to_json());
  const std::size_t two = 2;
  std::vector<nlohmann::json::json_pointer> paths;
  paths_below(doc["cfs"][two], nlohmann::json::json_pointer("/cfs/" + std::to_string(two)), paths);
  paths_below(doc["transitions"][0], nlohmann::json::json_pointer("/transitions/0"), paths);
  const std::vector<nlohmann::json> values = {nullptr,
                                              true,
                                              "x",
                                              "f-f",
                                              "gain",
                                              -1,
                                              0,
                                              1,
                                              3,
                                              4,
                                              7,
                                              2147483648.0,
                                              1.5,
                                              -0.0,
                                              1e300,
                                              nlohmann::json::array(),
                                              nlohmann::json::object(),
                                              {1, 2, 3},
                                              {1, 2, 3, 4},
                                              {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                              {{{"type", "f-f"}, {"a", 0}, {"b", 0}}}};
  int refused_by_schema = 0, refused_by_reader_only = 0;
  const auto check = [&](const nlohmann::json& mutated, const std::string& what) {
    const std::string text = mutated.dump();
    if (loads(text, true)) {
      if (!loads(text, false)) ++refused_by_reader_only;  // a semantic rule (ids, ranges)
      return;
    }
    ++refused_by_schema;
    INFO(what);
    CHECK_FALSE(loads(text, false));
  };
  for (const auto& path : paths) {
    for (const nlohmann::json& v : values) {
      nlohmann::json m = doc;
      m[path] = v;
      check(m, path.to_string() + " = " + v.dump());
    }
    const auto parent = path.parent_pointer();
    nlohmann::json m = doc;
    if (m[parent].is_object()) {
      m[parent].erase(path.back());
      check(m, path.to_string() + " removed");
    } else if (m[parent].is_array()) {
      m[parent].erase(static_cast<std::size_t>(std::stoul(path.back())));
      check(m, path.to_string() + " removed");
    }
    if (doc[path].is_object()) {
      nlohmann::json e = doc;
      e[path]["unknown"] = 1;
      check(e, path.to_string() + " with an unknown member");
    }
  }
  INFO(refused_by_schema << " refused by the schema, " << refused_by_reader_only
                         << " by the reader alone");
  CHECK(refused_by_schema > 300);
}

// The record check of the verify layer (tools/cfgen/verify/record_check.hpp), which cfinspect
// runs on every CF of a graph: a 10 mm cube A on a 40 x 40 x 10 mm slab B, records made by
// hand, true ones and the false ones a careless or malicious file holds.

#include "cfgen/verify/record_check.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <string>
#include <vector>

namespace {

using cf::CfRecord;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Vec3;

// Faces of cf::test::box: 0 bottom (-z), 1 top (+z).
constexpr int kBottom = 0, kTop = 1;

CfRecord on_top(const Vec3& t) {
  CfRecord r;
  r.pcs = PcSet({Pc{PcType::kFF, kBottom, kTop}});  // A's bottom face on B's top face
  r.witness.t_BA = t;
  // A face lying on a face: it slides in the plane (2) and turns about the normal (1).
  r.dof = 3;
  r.translation_dof = 2;
  r.pure_rotation = true;
  return r;
}

// The check of a graph holding `r` alone, with cfgen's default lengths in mm.
std::string check(const CfRecord& r, const std::string& meta = "{}") {
  const cf::CfGraph g = cf::CfGraph::from_parts(cf::test::box(10, 10, 10, "A"),
                                                cf::test::box(40, 40, 10, "B"), {r}, {}, meta);
  const cf::gen::RecordCheck c(g, cf::gen::SearchParams{});
  return c.check(g.cf(cf::CfId(0)));
}

}  // namespace

TEST_CASE("a true record passes the check", "[verify][record]") {
  CHECK(check(on_top({15, 15, 10})).empty());
  // Freedoms the file leaves out are not compared.
  CfRecord r = on_top({15, 15, 10});
  r.dof = r.translation_dof = -1;
  r.pure_rotation = false;
  CHECK(check(r).empty());
}

TEST_CASE("a witness that is not one is refused, with verify's reason", "[verify][record]") {
  // A sunk 5 mm into the slab: its side edges cross the slab's top face.
  CHECK(check(on_top({15, 15, 5})) == "witness refused by verify: extra contact e8-f1 at 0.000000");
  // Lifted 1 mm: not touching.
  CHECK(check(on_top({15, 15, 11})) == "witness refused by verify: a PC is not touching");
}

TEST_CASE("a witness far beyond B is refused before any distance overflows", "[verify][record]") {
  CHECK(check(on_top({1e308, 0, 0})) == "witness puts A 1e+308 mm beyond touching B");
  CHECK(check(on_top({0, 0, -1e300})) == "witness puts A 1e+300 mm beyond touching B");
}

TEST_CASE("a CF no pose can realise is refused", "[verify][record]") {
  // The cube's bottom on the slab's top and its top on the slab's bottom, at once.
  CfRecord r = on_top({15, 15, 10});
  r.pcs = PcSet({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kFF, kTop, kBottom}});
  r.dof = r.translation_dof = -1;
  CHECK(check(r).rfind("witness refused by verify:", 0) == 0);
}

TEST_CASE("stored freedoms other than the witness's are refused", "[verify][record]") {
  CfRecord r = on_top({15, 15, 10});
  r.dof = 4;
  CHECK(check(r) == "dof = 4, but 3 at the witness");
  r = on_top({15, 15, 10});
  r.translation_dof = 1;
  CHECK(check(r) == "translation_dof = 1, but 2 at the witness");
  r = on_top({15, 15, 10});
  r.pure_rotation = false;
  CHECK(check(r) == "pure_rotation = 0, but 1 at the witness");
}

TEST_CASE("the check uses the tolerances the graph records", "[verify][record]") {
  // 0.5 mm below the top face is a touch when the graph's touch tolerance is 1 mm (a
  // min_clearance of 2 mm keeps the others apart: the cube is 15 mm from every side).
  const std::string loose = R"({"parameters": {"touch_tol_mm": 1.0, "min_clearance_mm": 2.0}})";
  CHECK(check(on_top({15, 15, 10.5}), loose).empty());
  CHECK(!check(on_top({15, 15, 10.5})).empty());
  const cf::CfGraph g = cf::CfGraph::from_parts(cf::test::box(10, 10, 10, "A"),
                                                cf::test::box(40, 40, 10, "B"), {}, {}, loose);
  const cf::gen::SearchParams p = cf::gen::recorded_params(g, cf::gen::SearchParams{});
  CHECK(p.touch_tol == 1.0);
  CHECK(p.min_clearance == 2.0);
  CHECK(p.min_margin == cf::gen::SearchParams{}.min_margin);  // not recorded: the default
}

TEST_CASE("recorded tolerances that are not positive finite numbers are refused",
          "[verify][record]") {
  for (const char* meta :
       {R"({"parameters": {"touch_tol_mm": -1}})", R"({"parameters": {"min_clearance_mm": "1"}})",
        R"({"parameters": {"angle_margin_rad": 0}})"}) {
    const cf::CfGraph g = cf::CfGraph::from_parts(cf::test::box(10, 10, 10, "A"),
                                                  cf::test::box(40, 40, 10, "B"), {}, {}, meta);
    CHECK_THROWS_WITH(
        cf::gen::recorded_params(g, cf::gen::SearchParams{}),
        Catch::Matchers::StartsWith("reading the generator's parameters: /parameters/") &&
            Catch::Matchers::EndsWith("is not a positive finite number"));
  }
}

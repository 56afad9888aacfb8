#include "cfgen/certificate_file.hpp"

#include "cfgen/decide/deep_points.hpp"
#include "cfgen/decide/first_order.hpp"
#include "cfgen/enumerate/symmetry.hpp"

#include <cf/file_io.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <map>
#include <set>

namespace cf::tools {
namespace {

using gen::CellNode;
using gen::CellRelaxation;
using nlohmann::json;
using Verdict = CellRelaxation::Verdict;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

json mat(const Mat3& m) {
  json out = json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.push_back(m(r, c));
  return out;
}

// The name of a leaf's or an inner node's kind in the file.
const char* kind_name(const CellNode& n) {
  switch (n.kind) {
    case CellNode::Kind::kSplitRotation:
      return "split-rotation";
    case CellNode::Kind::kSplitTranslation:
      return "split-translation";
    case CellNode::Kind::kNarrow:
      return "narrow";
    case CellNode::Kind::kOutsideBall:
      return "outside-ball";
    case CellNode::Kind::kRefuted:
      break;
  }
  switch (n.refutation.verdict) {
    case Verdict::kBounds:
      return "bounds";
    case Verdict::kRotation:
      return "rotation";
    case Verdict::kCone:
      return "cone";
    case Verdict::kSlack:
      return "local-slack";
    case Verdict::kFirstOrder:
      return "first-order";
    case Verdict::kProgram:
      return "program";
    case Verdict::kDeep:
      return "deep";
    case Verdict::kOpen:
      break;
  }
  return "open";  // never in a complete tree
}

// What one node claims, with the data a checker needs to recheck it.
json node_json(const CellNode& n, int id, bool circle, const std::vector<std::vector<int>>& choices,
               const gen::DeepPoints& deep, const PcSet& pcs) {
  json j = {{"id", id}, {"parent", n.parent}};
  j["rot"] = circle ? json{{"arc", {n.arc.centre, n.arc.half}}}
                    : json{{"centre", vec(n.cell.centre)}, {"half", n.cell.half}};
  j["t_lo"] = vec(n.t_lo);
  j["t_hi"] = vec(n.t_hi);
  j["kind"] = kind_name(n);
  const auto& r = n.refutation;
  if (n.kind == CellNode::Kind::kSplitTranslation) {
    j["axis"] = n.axis;
    j["at"] = n.at;
  }
  if (n.kind != CellNode::Kind::kRefuted) return j;
  if (r.verdict == Verdict::kRotation || r.verdict == Verdict::kCone ||
      r.verdict == Verdict::kSlack)
    j["pc"] = r.pc;
  if (r.verdict == Verdict::kCone) j["direction"] = vec(r.direction);
  if (r.verdict == Verdict::kDeep) {
    j["of"] = n.deep_of_a ? "A" : "B";
    j["point"] = vec(deep.points(n.deep_of_a)[static_cast<std::size_t>(n.deep_point)]);
  }
  if (r.verdict == Verdict::kProgram) {
    json f = json::array();
    for (std::size_t k = 0; k < r.certificates.size() && k < choices.size(); ++k)
      f.push_back({{"choice", choices[k]}, {"y", r.certificates[k].y}});
    j["farkas"] = std::move(f);
  }
  if (r.verdict == Verdict::kFirstOrder) {
    json f = json::array();
    for (std::size_t k = 0; k < r.certificates.size(); ++k)
      f.push_back({{"signs", gen::first_order_signs(pcs, k)}, {"y", r.certificates[k].y}});
    j["farkas"] = std::move(f);
  }
  return j;
}

json cells_json(const gen::CellTree& tree, const CellRelaxation& relaxation,
                const gen::DeepPoints& deep, const PcSet& pcs) {
  const bool circle = tree.circle_pc >= 0;
  json j = {{"pivot", vec(tree.pivot)}, {"domain", circle ? "circle" : "ball"}};
  if (circle)
    j["circle"] = {{"pc", tree.circle_pc}, {"R0", mat(tree.R0)}, {"axis", vec(tree.axis)}};
  const std::vector<std::vector<int>> choices = relaxation.choice_list();
  json nodes = json::array();
  for (std::size_t i = 0; i < tree.nodes.size(); ++i)
    nodes.push_back(node_json(tree.nodes[i], static_cast<int>(i), circle, choices, deep, pcs));
  j["nodes"] = std::move(nodes);
  return j;
}

// The faces whose convex pieces some program of a set's cells uses: those of its PCs.
void add_faces(const PcSet& s, std::set<int>& faces_a, std::set<int>& faces_b) {
  for (const Pc& pc : s) {
    if (a_kind(pc.type) == ElementKind::kFace) faces_a.insert(pc.a);
    if (b_kind(pc.type) == ElementKind::kFace) faces_b.insert(pc.b);
  }
}

json pieces_json(const gen::ModelInfo& m, const std::set<int>& faces) {
  json out = json::array();
  for (int f : faces) {
    const Face& F = m.model->faces()[static_cast<std::size_t>(f)];
    json pieces = json::array();
    for (const gen::ConvexPiece& p : m.pieces[static_cast<std::size_t>(f)]) {
      json pts = json::array();
      for (const auto& q : p.points) pts.push_back({q.x(), q.y()});
      pieces.push_back({{"points", std::move(pts)}, {"boundary", p.boundary}});
    }
    out.push_back(
        {{"face", f},
         {"frame", {{"n", vec(F.normal)}, {"offset", F.offset}, {"U", vec(F.u)}, {"V", vec(F.v)}}},
         {"pieces", std::move(pieces)}});
  }
  return out;
}

// The THIN set `pcs` of e.thin (sorted), or null.
const gen::Witness* thin_of(const gen::Enumeration& e, const PcSet& pcs) {
  auto it = std::lower_bound(e.thin.begin(), e.thin.end(), pcs, [](const auto& x, const PcSet& s) {
    return gen::pcset_less(x.first, s);
  });
  return it != e.thin.end() && it->first == pcs ? &it->second : nullptr;
}

// The tolerances of a decision (the file's, or a tree's own).
json tolerances_json(const gen::CellSearchLimits& l) {
  json j = {{"touch_tol_mm", l.touch_tol},
            {"min_margin_mm", l.margin},
            {"local_slack", l.local_slack},
            {"rot_tol_rad", l.rot_tol},
            {"off_circle_rad", gen::off_circle(l.rot_tol)}};
  if (l.deep_extra != 0) j["deep_extra_mm"] = l.deep_extra;
  return j;
}

json set_json(const gen::SetDecision& d, const gen::Enumeration& e,
              const gen::WitnessSearch& search, const gen::CellSearchLimits& limits,
              const gen::DeepPoints& deep) {
  if (const gen::Witness* w = d.thin ? thin_of(e, d.pcs) : nullptr) {
    json j = thin_set_json(d.pcs, *w);
    j["outcome"] = "thin";
    return j;
  }
  json j = {{"pcs", to_string(d.pcs)}, {"outcome", d.invalid ? "invalid" : "undecided"}};
  if (!d.invalid) return j;
  if (!d.image_of.empty()) {
    j["image_of"] = {{"pcs", to_string(d.image_of)},
                     {"A", {{"R", mat(d.H)}, {"c", vec(d.c_A)}}},
                     {"B", {{"R", mat(d.G)}, {"c", vec(d.c_B)}}}};
  } else if (d.cells) {
    const gen::CellSearchLimits& l = d.cell_limits;
    const CellRelaxation relaxation(search.a(), search.b(), d.pcs, l.touch_tol, l.margin,
                                    l.local_slack, l.rot_tol);
    j["cells"] = cells_json(*d.cells, relaxation, deep, d.pcs);
    if (json own = tolerances_json(l); own != tolerances_json(limits))
      j["cells"]["tolerances"] = std::move(own);
  } else {
    j["rule"] = gen::rule_name(d.rule.rule);
    json involved = json::array();
    for (int k : {d.rule.first, d.rule.second})
      if (k >= 0) involved.push_back(k);
    j["pcs_involved"] = std::move(involved);
  }
  if (d.contradicted) j["contradicted"] = true;
  return j;
}

// The file's head: everything before the sets.
json head_json(const std::string& graph_path, const gen::Enumeration& e,
               const gen::WitnessSearch& search, const gen::CellSearchLimits& limits, double size) {
  std::set<int> faces_a, faces_b;
  std::map<std::string, std::size_t> counts{{"invalid_by_rule", 0},
                                            {"invalid_by_cells", 0},
                                            {"invalid_as_image", 0},
                                            {"thin", 0},
                                            {"undecided", 0}};
  for (const gen::SetDecision& d : e.decisions) {
    if (d.cells && d.image_of.empty()) add_faces(d.pcs, faces_a, faces_b);
    ++counts[d.thin                ? "thin"
             : !d.invalid          ? "undecided"
             : !d.image_of.empty() ? "invalid_as_image"
             : d.cells             ? "invalid_by_cells"
                                   : "invalid_by_rule"];
  }
  json summary = {{"sets", e.decisions.size()}};
  for (const auto& [k, v] : counts) summary[k] = v;
  json tolerances = tolerances_json(limits);
  tolerances["rounding_mm"] = 1e-12 * size;
  tolerances["size_mm"] = size;
  return {{"format", "cf-certificates"},
          {"version", 1},
          {"graph", graph_path},
          {"tolerances", tolerances},
          {"pieces",
           {{"A", pieces_json(search.a(), faces_a)}, {"B", pieces_json(search.b(), faces_b)}}},
          {"summary", std::move(summary)}};
}

}  // namespace

json thin_set_json(const PcSet& pcs, const gen::Witness& w) {
  json R = json::array();
  for (int r = 0; r < 3; ++r)
    R.push_back({w.pose.R_BA(r, 0), w.pose.R_BA(r, 1), w.pose.R_BA(r, 2)});
  return {{"pcs", to_string(pcs)},
          {"clearance_mm", w.clearance},
          {"margin_mm", w.margin},
          {"pose", {{"R", std::move(R)}, {"t", vec(w.pose.t_BA)}}}};
}

void write_certificates(const std::string& path, const std::vector<std::string>& inputs,
                        const std::string& graph_path, const gen::Enumeration& e,
                        const gen::WitnessSearch& search) {
  const Polyhedron& A = *search.a().model;
  const Polyhedron& B = *search.b().model;
  const double size =
      std::max((A.bbox_max() - A.bbox_min()).norm(), (B.bbox_max() - B.bbox_min()).norm());
  // The tolerances the run's decision used (the number of cells does not matter here).
  const gen::CellSearchLimits limits = gen::decision_limits(search, 0);
  const gen::DeepPoints deep(search.a(), search.b());
  const json head = head_json(graph_path, e, search, limits, size);
  write_streamed_outputs({{path,
                           [&](const ByteSink& sink) {
                             // The head, then one set a line, so that a large file is never held
                             // whole.
                             std::string text = head.dump(1);
                             text.resize(text.size() - 2);  // the closing "\n}"
                             text += ",\n \"sets\": [";
                             for (std::size_t i = 0; i < e.decisions.size(); ++i) {
                               text += i ? ",\n  " : "\n  ";
                               text += set_json(e.decisions[i], e, search, limits, deep).dump();
                               if (text.size() > (1u << 20)) {
                                 sink(text.data(), text.size());
                                 text.clear();
                               }
                             }
                             text += "\n ]\n}\n";
                             sink(text.data(), text.size());
                           }}},
                         inputs, "writing certificates");
}

}  // namespace cf::tools

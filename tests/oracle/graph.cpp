#include "graph.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace oracle {

namespace {

Poly poly_from_json(const nlohmann::json& m, const std::string& name) {
  std::vector<Vec3> verts;
  for (const auto& v : m.at("vertices"))
    verts.emplace_back(v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>());
  std::vector<std::array<int, 2>> edges;
  for (const auto& e : m.at("edges")) edges.push_back({e.at(0).get<int>(), e.at(1).get<int>()});
  std::vector<std::vector<std::vector<int>>> faces;
  for (const auto& f : m.at("faces")) {
    std::vector<std::vector<int>> loops;
    for (const auto& L : f.at("loops")) loops.push_back(L.get<std::vector<int>>());
    faces.push_back(loops);
  }
  std::string nm = name;
  if (m.contains("name") && m["name"].is_string()) nm += " '" + m["name"].get<std::string>() + "'";
  return build_poly(verts, edges, faces, nm);
}

}  // namespace

std::vector<Pc> parse_pc_list(const std::string& text) {
  std::vector<Pc> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ';')) {
    const auto c1 = item.find(':'), c2 = item.rfind(':');
    PcType t;
    if (c1 == std::string::npos || c1 == c2 || !parse_type(item.substr(0, c1), &t) ||
        !nondegenerate(t))
      throw std::runtime_error("\"" + item + "\" is not a PC type:a:b");
    out.push_back({t, std::stoi(item.substr(c1 + 1, c2 - c1 - 1)), std::stoi(item.substr(c2 + 1))});
  }
  return out;
}

Graph read_graph(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open graph " + path);
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw std::runtime_error("graph " + path + ": " + e.what());
  }
  Graph G;
  G.path = path;
  try {
    G.A = poly_from_json(j.at("models").at("A"), "A");
    G.B = poly_from_json(j.at("models").at("B"), "B");
    for (const auto& c : j.at("cfs")) {
      GraphCf cf;
      cf.id = c.at("id").get<int>();
      for (const auto& p : c.at("pcs")) {
        PcType t;
        if (!parse_type(p.at("type").get<std::string>(), &t))
          throw std::runtime_error("unknown PC type");
        cf.key.push_back(Pc{t, p.at("a").get<int>(), p.at("b").get<int>()});
      }
      std::sort(cf.key.begin(), cf.key.end());
      const auto& R = c.at("witness").at("R");
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) cf.witness.R(r, k) = R.at(r).at(k).get<double>();
      const auto& t = c.at("witness").at("t");
      cf.witness.t = Vec3(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
      G.cfs.push_back(cf);
    }
    if (j.contains("stats") && j["stats"].contains("thin_sets"))
      for (const auto& t : j["stats"]["thin_sets"]) {
        CfKey k = parse_pc_list(t.at("pcs").get<std::string>());
        std::sort(k.begin(), k.end());
        G.thin.push_back(k);
      }
    if (j.contains("parameters"))
      G.min_clearance_mm = j["parameters"].value("min_clearance_mm", 0.0);
  } catch (const std::exception& e) {
    throw std::runtime_error("graph " + path + ": " + e.what());
  }
  return G;
}

namespace {
std::string problem_of(const Verdict& V, const CfKey& want) {
  if (V.penetrating) return "interiors overlap: " + V.why;
  if (V.touches.empty()) return "A touches nothing at the witness";
  CfKey got = V.key();
  std::string s;
  if (got != want)
    s = "PCs at the witness {" + key_string(got) + "} differ from the CF's {" + key_string(want) +
        "}";
  if (V.degenerate) s += std::string(s.empty() ? "" : "; ") + "a PC is degenerate";
  if (V.too_many) s += std::string(s.empty() ? "" : "; ") + "more than 3 PCs";
  if (V.same_plane) s += std::string(s.empty() ? "" : "; ") + "two PCs share a contact plane";
  return s;
}
}  // namespace

WitnessResult check_witness(const Classifier& nominal, const Classifier& lo, const Classifier& hi,
                            const GraphCf& cf) {
  WitnessResult r;
  r.id = cf.id;
  r.key = cf.key;
  r.pose = cf.witness;
  Verdict V = nominal.classify(cf.witness, true);
  r.clearance = V.clearance;
  r.problem = problem_of(V, cf.key);
  if (r.problem.empty()) {
    r.verdict = 0;
    return r;
  }
  Verdict Vl = lo.classify(cf.witness, false), Vh = hi.classify(cf.witness, false);
  bool ok_lo = problem_of(Vl, cf.key).empty(), ok_hi = problem_of(Vh, cf.key).empty();
  r.verdict = (ok_lo || ok_hi) ? 1 : 2;
  return r;
}

CheckReport check_graph(const Graph& G, const Tolerances& tol,
                        const std::function<bool(const GraphCf&)>& which) {
  Tolerances tlo = tol, thi = tol;
  tlo.len /= 100;
  tlo.ang /= 100;
  thi.len *= 100;
  thi.ang *= 100;
  Classifier C(G.A, G.B, tol), Clo(G.A, G.B, tlo), Chi(G.A, G.B, thi);
  CheckReport rep;
  for (const GraphCf& cf : G.cfs) {
    if (which && !which(cf)) continue;
    WitnessResult w = check_witness(C, Clo, Chi, cf);
    ++rep.total;
    if (w.verdict == 0) ++rep.sound;
    if (w.verdict == 1) ++rep.marginal;
    if (w.verdict == 2) ++rep.unsound;
    if (w.verdict == 0) rep.min_clearance = std::min(rep.min_clearance, w.clearance);
    if (w.verdict != 0) rep.bad.push_back(w);
  }
  return rep;
}

}  // namespace oracle

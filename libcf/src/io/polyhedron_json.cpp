#include "polyhedron_json.hpp"

namespace cf {
namespace internal {

namespace {
json vec_json(const Vec3& p) { return json::array({p.x(), p.y(), p.z()}); }
}  // namespace

json polyhedron_to_json(const Polyhedron& m) {
  json j;
  j["name"] = m.name();
  json vs = json::array();
  for (const Vertex& v : m.vertices()) vs.push_back(vec_json(v.p));
  j["vertices"] = std::move(vs);
  json es = json::array();
  json info = json::array();
  for (const Edge& e : m.edges()) {
    es.push_back(json::array({e.v0.value(), e.v1.value()}));
    info.push_back({{"left", e.left.value()},
                    {"right", e.right.value()},
                    {"convex", e.convex},
                    {"dihedral_deg", e.dihedral * 180.0 / M_PI}});
  }
  j["edges"] = std::move(es);
  json fs = json::array();
  for (const Face& f : m.faces()) {
    json loops = json::array();
    for (const auto& loop : f.loops) {
      json l = json::array();
      for (VertexId v : loop) l.push_back(v.value());
      loops.push_back(std::move(l));
    }
    fs.push_back({{"loops", std::move(loops)},
                  {"normal", vec_json(f.normal)},
                  {"offset", f.offset},
                  {"area", f.area},
                  {"centroid", vec_json(f.centroid)}});
  }
  j["faces"] = std::move(fs);
  j["edge_info"] = std::move(info);
  j["mass"] = {{"volume", m.volume()},
               {"vertex_centroid", vec_json(m.vertex_centroid())},
               {"volume_centroid", vec_json(m.volume_centroid())}};
  return j;
}

Polyhedron polyhedron_from_json(const json& j, const JsonWhere& w) {
  std::string name = "unnamed";
  if (j.is_object() && j.contains("name")) name = json_string(j["name"], w / "name");
  const json& jv = json_array(json_member(j, "vertices", w), w / "vertices");
  const json& je = json_array(json_member(j, "edges", w), w / "edges");
  const json& jf = json_array(json_member(j, "faces", w), w / "faces");
  std::vector<Vec3> vertices;
  vertices.reserve(jv.size());
  for (std::size_t i = 0; i < jv.size(); ++i)
    vertices.push_back(json_vec3(jv[i], w / "vertices" / i));
  std::vector<std::array<int, 2>> edges;
  edges.reserve(je.size());
  for (std::size_t i = 0; i < je.size(); ++i) {
    const JsonWhere we = w / "edges" / i;
    json_array(je[i], we);
    if (je[i].size() != 2)
      json_fail(we, "expected a pair of vertex indices, got " + json_short(je[i]));
    edges.push_back({json_index(je[i][0], we / 0), json_index(je[i][1], we / 1)});
  }
  std::vector<std::vector<std::vector<int>>> faces(jf.size());
  for (std::size_t f = 0; f < jf.size(); ++f) {
    const JsonWhere wf = w / "faces" / f;
    const json& jl = json_array(json_member(jf[f], "loops", wf), wf / "loops");
    for (std::size_t l = 0; l < jl.size(); ++l) {
      const JsonWhere wl = wf / "loops" / l;
      json_array(jl[l], wl);
      std::vector<int> loop;
      for (std::size_t k = 0; k < jl[l].size(); ++k) loop.push_back(json_index(jl[l][k], wl / k));
      faces[f].push_back(std::move(loop));
    }
  }
  try {
    return Polyhedron::from_features(std::move(name), std::move(vertices), edges, faces);
  } catch (const Error& e) {
    throw Error("reading " + w.str() + ": " + e.what());
  }
}

}  // namespace internal

std::string to_json(const Polyhedron& model, int indent) {
  return internal::polyhedron_to_json(model).dump(indent);
}

Polyhedron polyhedron_from_json(const std::string& text, const std::string& source) {
  internal::json j;
  try {
    j = internal::json::parse(text);
  } catch (const internal::json::parse_error& e) {
    throw Error("reading '" + source + "': not valid JSON: " + e.what());
  }
  return internal::polyhedron_from_json(j, internal::JsonWhere{source, ""});
}

}  // namespace cf

// The PC vocabulary: names of PC types, PCs and PC sets, and the closure, dominance and
// neighbouring relations over a model pair.

#include <cf/pc.hpp>
#include <cf/polyhedron.hpp>

#include <algorithm>
#include <charconv>
#include <cstdint>

namespace cf {

namespace {

constexpr const char* kPcTypeNames[] = {"f-f", "e-f", "f-e", "v-f", "f-v", "e-e"};

std::uint64_t mix64(std::uint64_t x) {  // splitmix64 finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

}  // namespace

const char* to_string(PcType type) { return kPcTypeNames[static_cast<int>(type)]; }

std::optional<PcType> pc_type_from_string(std::string_view name) {
  for (int i = 0; i < 6; ++i)
    if (name == kPcTypeNames[i]) return static_cast<PcType>(i);
  return std::nullopt;
}

std::string to_string(const Pc& pc) {
  return std::string(to_string(pc.type)) + ":" + std::to_string(pc.a) + ":" + std::to_string(pc.b);
}

std::optional<Pc> pc_from_string(std::string_view text) {
  const std::size_t c1 = text.find(':');
  if (c1 == std::string_view::npos) return std::nullopt;
  const std::size_t c2 = text.find(':', c1 + 1);
  if (c2 == std::string_view::npos) return std::nullopt;
  const auto type = pc_type_from_string(text.substr(0, c1));
  if (!type) return std::nullopt;
  auto parse_index = [](std::string_view s, std::int32_t& out) {
    if (s.empty()) return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size() && out >= 0;
  };
  Pc pc;
  pc.type = *type;
  if (!parse_index(text.substr(c1 + 1, c2 - c1 - 1), pc.a)) return std::nullopt;
  if (!parse_index(text.substr(c2 + 1), pc.b)) return std::nullopt;
  return pc;
}

std::vector<Pc> neighbouring_pcs(const Pc& pc, const Polyhedron& A, const Polyhedron& B) {
  std::vector<Pc> out;
  auto add = [&](PcType t, int a, int b) { out.push_back({t, a, b}); };
  auto edges_of_face = [](const Polyhedron& m, int f) { return m.faces()[f].edges; };
  auto faces_of_edge = [](const Polyhedron& m, int e) {
    return std::vector<int>{m.edges()[e].left.value(), m.edges()[e].right.value()};
  };
  auto ends_of_edge = [](const Polyhedron& m, int e) {
    return std::vector<int>{m.edges()[e].v0.value(), m.edges()[e].v1.value()};
  };
  switch (pc.type) {
    case PcType::kFF:
      for (EdgeId e : edges_of_face(A, pc.a)) add(PcType::kEF, e.value(), pc.b);
      for (EdgeId e : edges_of_face(B, pc.b)) add(PcType::kFE, pc.a, e.value());
      break;
    case PcType::kEF:
      for (int f : faces_of_edge(A, pc.a)) add(PcType::kFF, f, pc.b);
      for (int v : ends_of_edge(A, pc.a)) add(PcType::kVF, v, pc.b);
      for (EdgeId e : edges_of_face(B, pc.b)) add(PcType::kEE, pc.a, e.value());
      break;
    case PcType::kFE:
      for (int f : faces_of_edge(B, pc.b)) add(PcType::kFF, pc.a, f);
      for (int v : ends_of_edge(B, pc.b)) add(PcType::kFV, pc.a, v);
      for (EdgeId e : edges_of_face(A, pc.a)) add(PcType::kEE, e.value(), pc.b);
      break;
    case PcType::kVF:
      for (EdgeId ea : A.vertices()[pc.a].edges) {
        add(PcType::kEF, ea.value(), pc.b);
        for (EdgeId eb : edges_of_face(B, pc.b)) add(PcType::kEE, ea.value(), eb.value());
      }
      break;
    case PcType::kFV:
      for (EdgeId eb : B.vertices()[pc.b].edges) {
        add(PcType::kFE, pc.a, eb.value());
        for (EdgeId ea : edges_of_face(A, pc.a)) add(PcType::kEE, ea.value(), eb.value());
      }
      break;
    case PcType::kEE:
      for (int f : faces_of_edge(B, pc.b)) add(PcType::kEF, pc.a, f);
      for (int f : faces_of_edge(A, pc.a)) add(PcType::kFE, f, pc.b);
      for (int v : ends_of_edge(A, pc.a))
        for (int f : faces_of_edge(B, pc.b)) add(PcType::kVF, v, f);
      for (int v : ends_of_edge(B, pc.b))
        for (int f : faces_of_edge(A, pc.a)) add(PcType::kFV, f, v);
      break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// ---------------------------------------------------------------------------------------
// PcSet

PcSet::PcSet(const std::vector<Pc>& pcs) {
  if (pcs.size() > static_cast<std::size_t>(kMaxPcs))
    throw Error("PcSet: " + std::to_string(pcs.size()) + " PCs given, a CF has at most 3");
  for (const Pc& pc : pcs)
    if (!insert(pc)) throw Error("PcSet: PC " + to_string(pc) + " is repeated");
}

std::size_t PcSet::hash() const {
  std::uint64_t h = static_cast<std::uint64_t>(size_);
  for (int i = 0; i < size_; ++i) {
    const Pc& pc = pcs_[static_cast<std::size_t>(i)];
    const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(pc.a)) << 32) |
                              static_cast<std::uint32_t>(pc.b);
    h = mix64(h ^ key ^ (static_cast<std::uint64_t>(pc.type) << 61));
  }
  return static_cast<std::size_t>(h);
}

std::string to_string(const PcSet& pcs) {
  std::string s;
  for (const Pc& pc : pcs) {
    if (!s.empty()) s += ';';
    s += to_string(pc);
  }
  return s;
}

// ---------------------------------------------------------------------------------------
// Relations

std::string check_pc(const Pc& pc, const Polyhedron& A, const Polyhedron& B, const char** field) {
  const auto check = [&](std::int32_t index, const Polyhedron& m, ElementKind kind,
                         const char* side, const char* name) -> std::string {
    const std::size_t n = m.num_elements(kind);
    if (index < 0 || static_cast<std::size_t>(index) >= n) {
      if (field) *field = name;
      const char* plural = kind == ElementKind::kVertex ? "vertices"
                           : kind == ElementKind::kEdge ? "edges"
                                                        : "faces";
      return std::string(to_string(pc.type)) + " PC: " + name + " = " + std::to_string(index) +
             " is not an index into the " + plural + " of model " + side + " '" + m.name() + "' (" +
             std::to_string(n) + " " + plural + ")";
    }
    return {};
  };
  std::string r = check(pc.a, A, a_kind(pc.type), "A", "a");
  if (r.empty()) r = check(pc.b, B, b_kind(pc.type), "B", "b");
  return r;
}

bool in_closure(const Polyhedron& m, ElementKind kx, int x, ElementKind ky, int y) {
  if (kx == ky) return x == y;
  if (kx == ElementKind::kVertex && ky == ElementKind::kEdge)
    return m.vertex_ends_edge(VertexId(x), EdgeId(y));
  if (kx == ElementKind::kVertex && ky == ElementKind::kFace)
    return m.vertex_on_face(VertexId(x), FaceId(y));
  if (kx == ElementKind::kEdge && ky == ElementKind::kFace)
    return m.edge_bounds_face(EdgeId(x), FaceId(y));
  return false;
}

bool dominates(const Polyhedron& A, const Polyhedron& B, const Pc& y, const Pc& x) {
  return x != y && in_closure(A, a_kind(x.type), x.a, a_kind(y.type), y.a) &&
         in_closure(B, b_kind(x.type), x.b, b_kind(y.type), y.b);
}

}  // namespace cf

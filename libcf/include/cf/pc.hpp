#pragma once
/// @file
/// The vocabulary of principal contacts (docs/spec.md, section 4; paper Fig. 1): element kinds, PC
/// types with their element kinds and geometric extent, PCs, PC sets, and the relations
/// between the elements of a model (closure) and between PCs (dominance, neighbouring PCs).
/// Everything else in libcf, and cfgen, speaks in these terms.

#include <cf/types.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cf {

class Polyhedron;

/// Kinds of elements. A PC type names the A element kind then the B element kind.
enum class ElementKind : std::uint8_t { kVertex, kEdge, kFace };

/// Non-degenerate PC types, named A-element then B-element (paper Fig. 1). The enumerator
/// order is the canonical order used to sort PCs.
enum class PcType : std::uint8_t { kFF = 0, kEF, kFE, kVF, kFV, kEE };

/// "f-f", "e-f", ... as in the graph file.
const char* to_string(PcType type);
/// Parses "f-f", "e-f", ...; std::nullopt for anything else.
std::optional<PcType> pc_type_from_string(std::string_view name);

/// Kind of the A element (first letter of the type's name).
constexpr ElementKind a_kind(PcType type) {
  switch (type) {
    case PcType::kEF:
    case PcType::kEE:
      return ElementKind::kEdge;
    case PcType::kVF:
      return ElementKind::kVertex;
    default:
      return ElementKind::kFace;
  }
}
/// Kind of the B element (last letter of the type's name).
constexpr ElementKind b_kind(PcType type) {
  switch (type) {
    case PcType::kFE:
    case PcType::kEE:
      return ElementKind::kEdge;
    case PcType::kFV:
      return ElementKind::kVertex;
    default:
      return ElementKind::kFace;
  }
}

/// Geometric category of a PC (paper section 2): where its contact region can be a point, a
/// segment or a polygon.
enum class PcExtent : std::uint8_t { kPoint, kLine, kPlane };
/// f-f: plane; e-f, f-e: line; v-f, f-v, e-e: point.
constexpr PcExtent extent(PcType type) {
  switch (type) {
    case PcType::kFF:
      return PcExtent::kPlane;
    case PcType::kEF:
    case PcType::kFE:
      return PcExtent::kLine;
    default:
      return PcExtent::kPoint;
  }
}

/// A principal contact: a pair of elements, by index into A's and B's arrays of the kinds
/// that `type` names.
struct Pc {
  PcType type = PcType::kFF;
  std::int32_t a = -1;  ///< index of A's element (vertex, edge or face per type)
  std::int32_t b = -1;  ///< index of B's element
  friend bool operator==(const Pc& x, const Pc& y) {
    return x.type == y.type && x.a == y.a && x.b == y.b;
  }
  friend bool operator!=(const Pc& x, const Pc& y) { return !(x == y); }
  friend bool operator<(const Pc& x, const Pc& y) {
    if (x.type != y.type) return x.type < y.type;
    if (x.a != y.a) return x.a < y.a;
    return x.b < y.b;
  }
};

/// "type:a:b", as in the `pcs` column of cfreplay's output.
std::string to_string(const Pc& pc);
/// Parses "type:a:b" (e.g. "v-f:3:5"); std::nullopt when malformed. Ranges are not checked.
std::optional<Pc> pc_from_string(std::string_view text);

/// Up to three PCs in canonical (sorted) order: the key of a CF. Fixed capacity, no heap.
class PcSet {
 public:
  static constexpr int kMaxPcs = 3;
  PcSet() = default;
  /// Builds the canonical set.
  /// @throws cf::Error when pcs has more than 3 PCs or repeats one.
  explicit PcSet(const std::vector<Pc>& pcs);
  /// Inserts keeping the order; returns false when full or already present. (Inline, as
  /// contains and ==: the generator's enumeration makes sets by the million.)
  bool insert(const Pc& pc) {
    if (size_ == kMaxPcs || contains(pc)) return false;
    int i = size_;
    for (; i > 0 && pc < pcs_[static_cast<std::size_t>(i - 1)]; --i)
      pcs_[static_cast<std::size_t>(i)] = pcs_[static_cast<std::size_t>(i - 1)];
    pcs_[static_cast<std::size_t>(i)] = pc;
    ++size_;
    return true;
  }
  int size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const Pc& operator[](int i) const { return pcs_[static_cast<std::size_t>(i)]; }
  const Pc* begin() const { return pcs_.data(); }
  const Pc* end() const { return pcs_.data() + size_; }
  bool contains(const Pc& pc) const {
    for (int i = 0; i < size_; ++i)
      if (pcs_[static_cast<std::size_t>(i)] == pc) return true;
    return false;
  }
  std::size_t hash() const;
  friend bool operator==(const PcSet& x, const PcSet& y) {
    if (x.size_ != y.size_) return false;
    for (int i = 0; i < x.size_; ++i)
      if (x.pcs_[static_cast<std::size_t>(i)] != y.pcs_[static_cast<std::size_t>(i)]) return false;
    return true;
  }
  friend bool operator!=(const PcSet& x, const PcSet& y) { return !(x == y); }

 private:
  std::array<Pc, kMaxPcs> pcs_{};
  int size_ = 0;
};

/// The PCs as "type:a:b" joined by ';' in canonical order (cfreplay's `pcs` column);
/// "" for the empty set.
std::string to_string(const PcSet& pcs);

/// Empty when pc's indices are in range for the element kinds its type names in A and B,
/// else the reason ("v-f PC: a = 9 is not an index into the vertices of model A 'cube' (8
/// vertices)"); `field`, when given, is then set to "a" or "b".
std::string check_pc(const Pc& pc, const Polyhedron& A, const Polyhedron& B,
                     const char** field = nullptr);

/// True when element (kx, x) of m is element (ky, y) or lies on its boundary: a vertex
/// ending an edge or on a face's boundary, an edge bounding a face.
/// @pre the indices are in range for their kinds in m.
bool in_closure(const Polyhedron& m, ElementKind kx, int x, ElementKind ky, int y);

/// True when PC `y` dominates PC `x` (docs/spec.md, section 4): they differ, and each element
/// of x is in the closure of the element of y on the same side (e.g. the e-f of an edge
/// dominates the v-f of its end vertices on the same face).
/// @pre the indices are in range for the element kinds the types name in A and B.
bool dominates(const Polyhedron& A, const Polyhedron& B, const Pc& y, const Pc& x);

/// The PCs neighbouring `pc` (docs/spec.md, section 4): one step through a degenerate touch,
/// under the boundary relations of A and B (edge bounds face, vertex ends edge; the table is in
/// docs/generator.md). Sorted, without repeats; the relation is symmetric. This is the rule
/// behind `change` transitions, for cfgen and for the graph reader's checks.
/// @pre pc's indices are in range for the element kinds its type names in A and B.
std::vector<Pc> neighbouring_pcs(const Pc& pc, const Polyhedron& A, const Polyhedron& B);

}  // namespace cf

template <>
struct std::hash<cf::PcSet> {
  std::size_t operator()(const cf::PcSet& s) const noexcept { return s.hash(); }
};

// The in-memory CF graph: construction, consistency checks and queries.
// Reading and writing the file is in io/graph_reader.cpp and io/graph_json.cpp.

#include "check.hpp"
#include "io/json_util.hpp"
#include "model/graph_impl.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

namespace cf {

namespace {

constexpr const char* kTransitionKindNames[] = {"gain", "lose", "change"};

}  // namespace

// ---------------------------------------------------------------------------------------
// Transition kinds

const char* to_string(TransitionKind kind) { return kTransitionKindNames[static_cast<int>(kind)]; }

std::optional<TransitionKind> transition_kind_from_string(std::string_view name) {
  for (int i = 0; i < 3; ++i)
    if (name == kTransitionKindNames[i]) return static_cast<TransitionKind>(i);
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------
// Checks and construction

namespace internal {

std::string check_witness(const Pose& pose, const char** field) {
  // Witnesses are written with full double precision; 1e-6 leaves room for hand-written
  // files with 7 significant digits while still catching a scaled or sheared matrix.
  constexpr double kRotationTol = 1e-6;
  if (!pose.t_BA.allFinite()) {
    *field = "t";
    return "translation is not finite";
  }
  const Mat3& R = pose.R_BA;
  const double ortho =
      R.allFinite() ? (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() : HUGE_VAL;
  const double det = R.determinant();
  if (!(ortho <= kRotationTol) || !(det > 0)) {
    *field = "R";
    std::ostringstream s;
    s << "not a rotation matrix (max |R^T R - I| = " << ortho << ", det R = " << det << ")";
    return s.str();
  }
  return {};
}

}  // namespace internal

namespace {

// PCs of one CF have pairwise distinct contact planes (docs/spec.md, section 4): two PCs on the
// same face of B (types x-f) or of A (types f-x) share that face's plane.
void check_distinct_planes(const PcSet& pcs, std::size_t i, const internal::FaultLocator& where) {
  for (int p = 0; p < pcs.size(); ++p)
    for (int q = p + 1; q < pcs.size(); ++q) {
      const Pc& x = pcs[p];
      const Pc& y = pcs[q];
      const bool same_b_face = b_kind(x.type) == ElementKind::kFace &&
                               b_kind(y.type) == ElementKind::kFace && x.b == y.b;
      const bool same_a_face = a_kind(x.type) == ElementKind::kFace &&
                               a_kind(y.type) == ElementKind::kFace && x.a == y.a;
      if (same_a_face || same_b_face)
        where.cf_fault(i, "PCs " + to_string(x) + " and " + to_string(y) +
                              " share the contact plane of " +
                              (same_b_face ? "B's face " + std::to_string(x.b)
                                           : "A's face " + std::to_string(x.a)) +
                              "; the PCs of a CF have distinct contact planes");
    }
}

// A CF's PCs are principal (none dominated by another of its PCs: docs/spec.md, section 4) and
// its freedoms ordered (translation_dof at most dof) when the record has them.
void check_principal_and_freedoms(const CfRecord& r, const Polyhedron& A, const Polyhedron& B,
                                  std::size_t i, const internal::FaultLocator& where) {
  for (int p = 0; p < r.pcs.size(); ++p)
    for (int q = 0; q < r.pcs.size(); ++q)
      if (p != q && dominates(A, B, r.pcs[q], r.pcs[p]))
        where.cf_fault(i, "PC " + to_string(r.pcs[p]) + " is dominated by its PC " +
                              to_string(r.pcs[q]) +
                              " (both its elements lie in the other's); a CF's PCs are principal");
  if (r.dof >= 0 && r.translation_dof > r.dof)
    where.cf_fault(i, "translation_dof = " + std::to_string(r.translation_dof) +
                          " exceeds dof = " + std::to_string(r.dof));
}

// `change` (MT3; docs/spec.md, section 4), as cfgen builds it: the target is the source with each
// PC kept or replaced by one of its neighbouring PCs, all distinct. So some one-to-one
// pairing maps every source PC to an equal or a neighbouring target PC (sizes are equal).
class ChangeRule {
 public:
  ChangeRule(const Polyhedron& a, const Polyhedron& b) : a_(a), b_(b) {}
  bool holds(const PcSet& f, const PcSet& g) {
    // A file lists a CF's transitions together: the source's neighbour lists are looked up
    // once for all of them.
    if (!(f == source_)) {
      source_ = f;
      for (int i = 0; i < f.size(); ++i) {
        auto it = neighbours_of_.find(f[i]);
        if (it == neighbours_of_.end())
          it = neighbours_of_.emplace(f[i], neighbouring_pcs(f[i], a_, b_)).first;
        lists_[static_cast<std::size_t>(i)] = &it->second;  // nodes never move
      }
    }
    // Most changes replace one PC and keep the others; when matching only the replaced ones
    // fails, every one-for-one matching is tried. Each pair is looked up once.
    near_ = {};
    return matches(f, g, true) || matches(f, g, false);
  }

 private:
  // Whether f[i] may become g[j]: equal, or g[j] among f[i]'s neighbours.
  bool may_become(const PcSet& f, const PcSet& g, int i, int j) {
    signed char& memo = near_[static_cast<std::size_t>(i * PcSet::kMaxPcs + j)];
    if (memo == 0) {
      const std::vector<Pc>& near = *lists_[static_cast<std::size_t>(i)];
      memo = f[i] == g[j] || std::binary_search(near.begin(), near.end(), g[j]) ? 1 : -1;
    }
    return memo > 0;
  }

  bool matches(const PcSet& f, const PcSet& g, bool keep_common) {
    std::array<int, PcSet::kMaxPcs> perm{0, 1, 2};
    do {
      bool ok = true;
      for (int i = 0; i < f.size() && ok; ++i) {
        const int j = perm[static_cast<std::size_t>(i)];
        if (f[i] == g[j]) continue;
        ok = !(keep_common && (g.contains(f[i]) || f.contains(g[j]))) && may_become(f, g, i, j);
      }
      if (ok) return true;
    } while (std::next_permutation(perm.begin(), perm.begin() + g.size()));
    return false;
  }

  const Polyhedron& a_;
  const Polyhedron& b_;
  std::unordered_map<Pc, std::vector<Pc>, internal::PcHash> neighbours_of_;  // a cache
  PcSet source_;                                                             // of lists_
  std::array<const std::vector<Pc>*, PcSet::kMaxPcs> lists_{};
  std::array<signed char, PcSet::kMaxPcs * PcSet::kMaxPcs> near_{};  // 0 unknown, 1 yes, -1 no
};

bool one_more(const PcSet& big, const PcSet& small) {
  if (big.size() != small.size() + 1) return false;
  for (const Pc& pc : small)
    if (!big.contains(pc)) return false;
  return true;
}

// Transition t: its ends are CF ids, distinct, and its kind holds between their PC sets.
void check_transition(std::size_t t, const Transition& tr, const std::vector<PcSet>& sets,
                      ChangeRule& change, const internal::FaultLocator& where) {
  const std::size_t n = sets.size();
  const auto in_range = [&](CfId id, const char* field) {
    if (!id.valid() || id.index() >= n)
      where.transition_fault(t, field,
                             std::string(field) + " = " + std::to_string(id.value()) +
                                 " is not a CF id (the graph has " + std::to_string(n) + " CFs)");
  };
  in_range(tr.from, "from");
  in_range(tr.to, "to");
  if (tr.from == tr.to)
    where.transition_fault(
        t, "to", "a transition from CF " + std::to_string(tr.from.value()) + " to itself");
  const PcSet& f = sets[tr.from.index()];
  const PcSet& g = sets[tr.to.index()];
  bool ok = false;
  const char* rule = "";
  switch (tr.kind) {
    case TransitionKind::kGain:
      ok = one_more(g, f);
      rule = "'gain' needs the target to be the source plus one PC";
      break;
    case TransitionKind::kLose:
      ok = one_more(f, g);
      rule = "'lose' needs the target to be the source minus one PC";
      break;
    case TransitionKind::kChange:
      ok = f.size() == g.size();
      rule = "'change' needs the same number of PCs";
      if (ok) {
        ok = f != g && change.holds(f, g);
        rule =
            "'change' needs the target to be the source with one or more PCs replaced by "
            "neighbouring PCs, one for one";
      }
      break;
  }
  if (!ok)
    where.transition_fault(t, "kind",
                           std::string("kind ") + rule + ": CF " + std::to_string(tr.from.value()) +
                               " {" + to_string(f) + "} -> CF " + std::to_string(tr.to.value()) +
                               " {" + to_string(g) + "}");
}

// Sorts each CF's transitions by target; a target listed twice is a fault at its second
// listing in file order.
void sort_out_lists(std::vector<std::vector<Transition>>& out,
                    const std::vector<Transition>& transitions,
                    const internal::FaultLocator& where) {
  const auto by_target = [](const Transition& x, const Transition& y) { return x.to < y.to; };
  for (auto& list : out) {
    // cfgen writes each CF's transitions in target order: no sort (and no buffer) for them.
    if (!std::is_sorted(list.begin(), list.end(), by_target))
      std::stable_sort(list.begin(), list.end(), by_target);
    for (std::size_t k = 1; k < list.size(); ++k)
      if (list[k].to == list[k - 1].to) {
        std::size_t seen = 0, t = 0;
        for (; t < transitions.size(); ++t)
          if (transitions[t].from == list[k].from && transitions[t].to == list[k].to && seen++ == 1)
            break;
        where.transition_fault(t, "to",
                               "transition CF " + std::to_string(list[k].from.value()) + " -> CF " +
                                   std::to_string(list[k].to.value()) + " is listed twice");
      }
  }
}

}  // namespace

void CfGraph::Impl::build(const internal::FaultLocator& where) {
  const std::size_t n = cfs.size();
  index.clear();
  index.reserve(n + n / 4);
  held.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const PcSet& pcs = cfs[i].pcs;
    if (pcs.empty()) where.cf_fault(i, "a CF needs 1 to 3 PCs, this one has none");
    check_distinct_planes(pcs, i, where);
    if (cfs[i].num_planes != 0 && cfs[i].num_planes != pcs.size())
      where.cf_fault(i, std::to_string(cfs[i].num_planes) + " contact planes for " +
                            std::to_string(pcs.size()) + " PCs (one per PC, or none)");
    check_principal_and_freedoms(cfs[i], a, b, i, where);
    for (const Pc& pc : pcs) held.insert(pc);
    const auto [it, inserted] = index.emplace(pcs, CfId(static_cast<std::int32_t>(i)));
    if (!inserted)
      where.cf_fault(
          i, "PC set {" + to_string(pcs) + "} repeats CF " + std::to_string(it->second.value()));
  }
  ChangeRule change(a, b);
  // The PC sets side by side: a transition's target is anywhere in the graph, and a whole
  // CfRecord per lookup would be a cache miss each.
  std::vector<PcSet> sets(n);
  for (std::size_t i = 0; i < n; ++i) sets[i] = cfs[i].pcs;
  out.assign(n, {});
  std::vector<std::uint32_t> out_degree(n, 0);
  for (std::size_t t = 0; t < transitions.size(); ++t) {
    check_transition(t, transitions[t], sets, change, where);
    ++out_degree[transitions[t].from.index()];
  }
  // Each list allocated once, at its size.
  for (std::size_t i = 0; i < n; ++i) out[i].reserve(out_degree[i]);
  for (const Transition& t : transitions) out[t.from.index()].push_back(t);
  sort_out_lists(out, transitions, where);
}

namespace {

class PartsLocator final : public internal::FaultLocator {
 public:
  [[noreturn]] void cf_fault(std::size_t cf, const std::string& what) const override {
    throw Error("CfGraph::from_parts: CF " + std::to_string(cf) + ": " + what);
  }
  [[noreturn]] void pc_fault(std::size_t cf, std::size_t pc, const char*,
                             const std::string& what) const override {
    throw Error("CfGraph::from_parts: CF " + std::to_string(cf) + ", PC " + std::to_string(pc) +
                ": " + what);
  }
  [[noreturn]] void transition_fault(std::size_t t, const char*,
                                     const std::string& what) const override {
    throw Error("CfGraph::from_parts: transition " + std::to_string(t) + ": " + what);
  }
  [[noreturn]] void metadata_fault(const std::string& what) const override {
    throw Error("CfGraph::from_parts: metadata: " + what);
  }
};

}  // namespace

std::string internal::check_metadata(const json& meta) {
  static const char* const kReserved[] = {"format", "version", "units",
                                          "models", "cfs",     "transitions"};
  if (!meta.is_object()) return "expected a JSON object, got " + json_short(meta);
  for (const char* key : kReserved)
    if (meta.contains(key))
      return std::string("member \"") + key + "\" is part of the graph itself, not metadata";
  return {};
}

CfGraph CfGraph::from_parts(Polyhedron a, Polyhedron b, std::vector<CfRecord> cfs,
                            std::vector<Transition> transitions, const std::string& metadata_json) {
  const PartsLocator where;
  auto impl = std::make_unique<Impl>();
  internal::json meta;
  try {
    meta = internal::json::parse(metadata_json.empty() ? std::string("{}") : metadata_json);
  } catch (const internal::json::parse_error& e) {
    where.metadata_fault(std::string("not valid JSON: ") + e.what());
  }
  if (std::string why = internal::check_metadata(meta); !why.empty()) where.metadata_fault(why);
  impl->metadata = meta.dump();
  for (std::size_t i = 0; i < cfs.size(); ++i) {
    const CfRecord& r = cfs[i];
    for (int p = 0; p < r.pcs.size(); ++p) {
      const char* field = "";
      if (std::string why = check_pc(r.pcs[p], a, b, &field); !why.empty())
        where.pc_fault(i, static_cast<std::size_t>(p), field, why);
    }
    {
      const char* field = "";
      if (std::string why = internal::check_witness(r.witness, &field); !why.empty())
        where.cf_fault(i, std::string("witness ") + field + ": " + why);
    }
    if (r.dof < -1 || r.dof > 6)
      where.cf_fault(i, "dof = " + std::to_string(r.dof) + " is not in 0..6");
    if (r.translation_dof < -1 || r.translation_dof > 3)
      where.cf_fault(i,
                     "translation_dof = " + std::to_string(r.translation_dof) + " is not in 0..3");
  }
  impl->a = std::move(a);
  impl->b = std::move(b);
  impl->cfs = std::move(cfs);
  impl->transitions = std::move(transitions);
  impl->build(where);
  CfGraph g;
  g.impl_ = std::move(impl);
  return g;
}

// ---------------------------------------------------------------------------------------
// Queries

namespace {
const CfGraph::Impl& empty_impl() {
  static const CfGraph::Impl e;
  return e;
}
}  // namespace

const CfGraph::Impl& CfGraph::impl() const { return impl_ ? *impl_ : empty_impl(); }

const Polyhedron& CfGraph::model_a() const { return impl().a; }
const Polyhedron& CfGraph::model_b() const { return impl().b; }
std::size_t CfGraph::num_cfs() const { return impl().cfs.size(); }
namespace {
std::string not_a_cf(const char* operation, CfId id, std::size_t num_cfs) {
  return std::string("CfGraph::") + operation + ": CF id " + std::to_string(id.value()) +
         " is not in the graph (" + std::to_string(num_cfs) + " CFs)";
}
}  // namespace

const CfRecord& CfGraph::cf(CfId id) const {
  CF_REQUIRE(id.valid() && id.index() < num_cfs(), not_a_cf("cf", id, num_cfs()));
  return impl().cfs[id.index()];
}
std::size_t CfGraph::num_transitions() const { return impl().transitions.size(); }
const Transition& CfGraph::transition(std::size_t i) const {
  CF_REQUIRE(i < num_transitions(), "CfGraph::transition: index " + std::to_string(i) +
                                        " is not in the graph (" +
                                        std::to_string(num_transitions()) + " transitions)");
  return impl().transitions[i];
}

std::optional<CfId> CfGraph::find(const PcSet& pcs) const {
  const auto& index = impl().index;
  const auto it = index.find(pcs);
  if (it == index.end()) return std::nullopt;
  return it->second;
}

bool CfGraph::holds(const Pc& pc) const {
  const auto& held = impl().held;
  return held.find(pc) != held.end();
}

const std::vector<Transition>& CfGraph::out_transitions(CfId id) const {
  CF_REQUIRE(id.valid() && id.index() < num_cfs(), not_a_cf("out_transitions", id, num_cfs()));
  return impl().out[id.index()];
}

bool CfGraph::adjacent(CfId from, CfId to) const {
  if (!from.valid() || from.index() >= num_cfs()) return false;
  const auto& list = impl().out[from.index()];
  const auto it = std::lower_bound(list.begin(), list.end(), to,
                                   [](const Transition& t, CfId id) { return t.to < id; });
  return it != list.end() && it->to == to;
}

const std::string& CfGraph::metadata_json() const {
  static const std::string kEmpty = "{}";
  return impl_ ? impl_->metadata : kEmpty;
}

CfGraph::CfGraph() = default;
CfGraph::~CfGraph() = default;
CfGraph::CfGraph(CfGraph&&) noexcept = default;
CfGraph& CfGraph::operator=(CfGraph&&) noexcept = default;

}  // namespace cf

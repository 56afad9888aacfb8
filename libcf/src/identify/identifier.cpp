#include <cf/identifier.hpp>

#include "../check.hpp"
#include "identify.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace cf {

const char* to_string(IdStatus status) {
  switch (status) {
    case IdStatus::kMatchedPrevious:
      return "matched-previous";
    case IdStatus::kMatchedNeighbour:
      return "matched-neighbour";
    case IdStatus::kMatchedByFit:
      return "matched-by-fit";
    case IdStatus::kNoContact:
      return "no-contact";
    case IdStatus::kNonNeighbourJump:
      return "non-neighbour-jump";
    case IdStatus::kOutsideGraph:
      return "outside-graph";
    case IdStatus::kTooManyPlanes:
      return "too-many-planes";
  }
  return "?";
}

namespace {

constexpr int kMaxGroups = 8;  // contact planes examined; more cannot be explained anyway

// Vertices of an element's closure, as a small view.
struct Closure {
  const VertexId* v = nullptr;
  int n = 0;
  VertexId own[2];
};

Closure closure(const Polyhedron& m, ElementKind k, int i) {
  Closure c;
  switch (k) {
    case ElementKind::kVertex:
      c.own[0] = VertexId(i);
      c.v = c.own;
      c.n = 1;
      break;
    case ElementKind::kEdge:
      c.own[0] = m.edges()[static_cast<std::size_t>(i)].v0;
      c.own[1] = m.edges()[static_cast<std::size_t>(i)].v1;
      if (c.own[1] < c.own[0]) std::swap(c.own[0], c.own[1]);
      c.v = c.own;
      c.n = 2;
      break;
    case ElementKind::kFace: {
      const auto& vs = m.faces()[static_cast<std::size_t>(i)].vertices;  // ascending
      c.v = vs.data();
      c.n = static_cast<int>(vs.size());
      break;
    }
  }
  return c;
}

bool closures_meet(const Polyhedron& m, ElementKind ki, int i, ElementKind kj, int j) {
  Closure x = closure(m, ki, i), y = closure(m, kj, j);
  if (ki == ElementKind::kEdge || ki == ElementKind::kVertex) x.v = x.own;
  if (kj == ElementKind::kEdge || kj == ElementKind::kVertex) y.v = y.own;
  int p = 0, q = 0;  // both ascending
  while (p < x.n && q < y.n) {
    if (x.v[p] == y.v[q]) return true;
    if (x.v[p] < y.v[q])
      ++p;
    else
      ++q;
  }
  return false;
}

}  // namespace

namespace internal {

struct IdentifyScratch {
  // Set per call by identify().
  const CfGraph* graph = nullptr;
  IdentificationParams prm;
  double eps_mm = 1;  // Params::epsilon_mm
  Identification* res = nullptr;
  CfId prev;
  // Per step scratch (fixed size).
  std::array<std::array<std::int16_t, ContactSet::kCapacity>, kMaxGroups> members{};
  std::array<std::pair<double, std::int16_t>, ContactSet::kCapacity>
      by_fit{};  // scratch: (misfit, position)
  std::array<int, kMaxGroups> count{};
  // The members some CF of the graph holds (best fit first): only these can be chosen.
  std::array<std::array<std::int16_t, ContactSet::kCapacity>, kMaxGroups> choosable{};
  std::array<int, kMaxGroups> nchoose{};
  // A direct-mapped memo of CfGraph::holds: the PCs detected at a tick are mostly those of
  // the tick before, and each lookup in the graph's hash set costs a cache miss or two (on
  // 2,000-face spheres with 70 contacts per tick, 6 of the 47 us per step).
  struct HeldEntry {
    Pc pc;  // a = -1: empty
    bool held = false;
  };
  static constexpr std::size_t kHeldMemo = 1024;
  std::array<HeldEntry, kHeldMemo> held_memo{};

  bool holds(const Pc& pc) {
    const std::uint64_t k = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(pc.a)) << 34) ^
                            (static_cast<std::uint64_t>(static_cast<std::uint32_t>(pc.b)) << 3) ^
                            static_cast<std::uint64_t>(pc.type);
    HeldEntry& e =
        held_memo[static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> 54) % kHeldMemo];
    if (e.pc != pc) {
      e.pc = pc;
      e.held = graph->holds(pc);
    }
    return e.held;
  }

  // Is contact c an alternative reading of contact s (their elements' closures meet on
  // both sides)? Used to let a chosen PC explain another plane's contacts.
  bool related(const ContactPc& c, const ContactPc& s) const {
    return closures_meet(graph->model_a(), a_kind(c.pc.type), c.pc.a, a_kind(s.pc.type), s.pc.a) &&
           closures_meet(graph->model_b(), b_kind(c.pc.type), c.pc.b, b_kind(s.pc.type), s.pc.b);
  }

  // Group g, from which nothing is chosen, is accounted for: each of its contacts is apart
  // (beyond apart_beyond: farther than touching and than every chosen PC, by more than
  // touch_distance_mm; the CF says those touch and this does not, which only a nearer contact
  // can say) or related to a chosen contact (another reading of the same degenerate touch).
  // Returns 0 when every contact is apart, 1 when some need explaining, 2 when one is
  // neither.
  int accounted(int g, const int* chosen, int nchosen, double apart_beyond) const {
    const ContactSet& cs = res->contacts;
    int worst = 0;
    for (int k = 0; k < count[static_cast<std::size_t>(g)]; ++k) {
      const ContactPc& c = cs[members[static_cast<std::size_t>(g)][static_cast<std::size_t>(k)]];
      if (c.distance > apart_beyond) continue;
      bool ok = false;
      for (int s = 0; s < nchosen && !ok; ++s) ok = related(c, cs[chosen[s]]);
      if (!ok) return 2;
      worst = 1;
    }
    return worst;
  }

  // Whether plane g holds a contact that touches (within touch_distance_mm), that nothing
  // dominates and whose shape fits exactly (misfit below 1e-6 without the distance term): a
  // whole reading of some touch, which a reading that leaves it to an explanation loses.
  bool exact_touch(int g) const {
    const ContactSet& cs = res->contacts;
    for (int k = 0; k < count[static_cast<std::size_t>(g)]; ++k) {
      const ContactPc& c = cs[members[static_cast<std::size_t>(g)][static_cast<std::size_t>(k)]];
      // The misfit (dimensionless) is the distance's own share of epsilon, to rounding.
      constexpr double kMisfitRounding = 1e-6;
      if (!c.dominated && std::abs(c.distance) <= prm.touch_distance_mm &&
          c.misfit - std::abs(c.distance) / eps_mm < kMisfitRounding)
        return true;
    }
    return false;
  }

  // An interpretation that is a CF, with its rank keys (docs/runtime.md, Identification).
  struct Ranked {
    int tier = 2;   // 0: every skipped plane apart; 1: some explained
    int dom = 4;    // dominated PCs chosen
    int left = 64;  // skipped planes holding an exact, undominated touch (another reading)
    int cat = 3;    // 0 previous CF, 1 its neighbour, 2 other
    double misfit = 0;
    CfId id;
    int n = 0;
    bool partial = false;
    // Whole contact regions first (fewest dominated PCs: a fragment of a line or plane
    // contact read as points ranks below the whole), then planes accounted for, then the
    // history, then the fit (docs/runtime.md).
    bool better_than(const Ranked& o) const {
      return dom != o.dom     ? dom < o.dom
             : tier != o.tier ? tier < o.tier
             : left != o.left ? left < o.left
             : cat != o.cat   ? cat < o.cat
                              : misfit < o.misfit;
    }
    // Nothing can rank above: the previous CF is one PC set, so one interpretation.
    bool unbeatable() const { return tier == 0 && dom == 0 && left == 0 && cat == 0; }
  };

  // Ranks the interpretation `chosen` (contact indices; taken[g]: plane g has one of them).
  // False when a skipped plane is not accounted for, when it ranks below `bound` on the
  // first two keys (dominated PCs, then tier), or when no CF has this PC set.
  bool rank(const int* chosen, int n, const bool* taken, int G, const Ranked& bound,
            Ranked& r) const {
    const ContactSet& cs = res->contacts;
    r.partial = n < G;
    r.dom = 0;
    double farthest = 0;
    for (int i = 0; i < n; ++i) {
      farthest = std::max(farthest, cs[chosen[i]].distance);
      r.dom += cs[chosen[i]].dominated;
    }
    if (r.dom > bound.dom) return false;
    const double apart_beyond = farthest + prm.touch_distance_mm;
    r.tier = 0;
    r.left = 0;
    for (int g = 0; g < G && r.tier < 2 && r.partial; ++g) {
      if (taken[g]) continue;
      const int a = accounted(g, chosen, n, apart_beyond);
      r.tier = std::max(r.tier, a);
      if (a == 1 && exact_touch(g)) ++r.left;
    }
    if (r.tier >= 2 || (r.dom == bound.dom && r.tier > bound.tier)) return false;
    PcSet key;
    for (int i = 0; i < n; ++i) key.insert(cs[chosen[i]].pc);
    const std::optional<CfId> id = graph->find(key);
    if (!id) return false;
    r.id = *id;
    r.cat = (prev.valid() && *id == prev)                  ? 0
            : (prev.valid() && graph->adjacent(prev, *id)) ? 1
                                                           : 2;
    r.misfit = 0;
    for (int i = 0; i < n; ++i) r.misfit += cs[chosen[i]].misfit;
    r.n = n;
    return true;
  }

  // The previous CF, tried before the enumeration: when all its PCs are detected in
  // distinct planes and it ranks unbeatable (every other plane apart, nothing dominated),
  // the enumeration would end on it anyway (it is one interpretation), so it is the result.
  bool try_previous(int G) {
    if (!prev.valid()) return false;
    const ContactSet& cs = res->contacts;
    const PcSet& want = graph->cf(prev).pcs;
    int chosen[3];
    int n = 0;
    std::array<bool, kMaxGroups> taken{};
    for (const Pc& pc : want) {
      int found = -1;
      for (int i = 0; i < cs.size() && found < 0; ++i)
        if (cs[i].pc == pc) found = i;
      if (found < 0) return false;
      const auto g = static_cast<std::size_t>(cs[found].plane);
      if (taken[g]) return false;  // two PCs in one plane: not an interpretation
      taken[g] = true;
      chosen[n++] = found;
    }
    Ranked r;
    Ranked bound;
    bound.dom = 0;
    bound.tier = 0;
    if (!rank(chosen, n, taken.data(), G, bound, r) || !r.unbeatable()) return false;
    res->combinations = 1;
    set_result(IdStatus::kMatchedPrevious, r.id, chosen, n, r.misfit, r.partial);
    return true;
  }

  void set_result(IdStatus st, CfId id, const int* chosen, int n, double misfit, bool partial) {
    // The planes the CF leaves apart: their nearest contacts approach.
    const ContactSet& cs = res->contacts;
    double farthest = 0;
    std::array<bool, kMaxGroups> held{};
    for (int i = 0; i < n; ++i) {
      farthest = std::max(farthest, cs[chosen[i]].distance);
      held[static_cast<std::size_t>(cs[chosen[i]].plane)] = true;
    }
    res->num_approaching = 0;
    for (int g = 0; g < cs.num_planes() && partial; ++g) {
      if (held[static_cast<std::size_t>(g)] ||
          accounted(g, chosen, n, farthest + prm.touch_distance_mm) != 0)
        continue;
      // The plane's nearest contact that no other dominates: a face flush with the plane
      // reads as its f-f, not as whichever of its corners round-off puts nearest.
      int best = -1;
      for (int k = 0; k < count[static_cast<std::size_t>(g)]; ++k) {
        const int i = members[static_cast<std::size_t>(g)][static_cast<std::size_t>(k)];
        if (best < 0 || cs[i].dominated < cs[best].dominated ||
            (cs[i].dominated == cs[best].dominated && cs[i].distance < cs[best].distance))
          best = i;
      }
      if (best >= 0 && res->num_approaching < static_cast<int>(res->approaching.size()))
        res->approaching[static_cast<std::size_t>(res->num_approaching++)] = cs[best];
    }
    res->status = st;
    res->cf = id;
    res->misfit = misfit;
    res->partial_cover = partial;
    res->pcs = PcSet();
    for (int i = 0; i < n; ++i) res->pcs.insert(res->contacts[chosen[i]].pc);
    res->num_cf_pcs = 0;
    for (const Pc& pc : res->pcs)
      for (int i = 0; i < n; ++i)
        if (res->contacts[chosen[i]].pc == pc)
          res->cf_pcs[static_cast<std::size_t>(res->num_cf_pcs++)] = res->contacts[chosen[i]];
  }

  // The result before anything is found.
  void clear_result() {
    res->combinations = 0;
    res->capped = false;
    res->num_cf_pcs = 0;
    res->pcs = PcSet();
    res->cf = CfId();
    res->misfit = 0;
    res->partial_cover = false;
    res->num_approaching = 0;
  }

  // Members of each of the G planes, best fit first (ties: canonical PC order, as detected),
  // and those of them some CF holds (choosable).
  void sort_planes(int G) {
    const ContactSet& cs = res->contacts;
    count.fill(0);
    for (int i = 0; i < cs.size(); ++i) {
      const auto g = static_cast<std::size_t>(cs[i].plane);
      members[g][static_cast<std::size_t>(count[g]++)] = static_cast<std::int16_t>(i);
    }
    for (int g = 0; g < G; ++g) {
      auto& m = members[static_cast<std::size_t>(g)];
      // Sorted on (misfit, position) keys: stable, without std::stable_sort's allocation,
      // and without an insertion sort's quadratic reads of the contacts (a band of 70
      // contacts on one plane cost 11k instructions per tick).
      const int n = count[static_cast<std::size_t>(g)];
      for (int i = 0; i < n; ++i) {
        const std::int16_t v = m[static_cast<std::size_t>(i)];
        by_fit[static_cast<std::size_t>(i)] = {cs[v].misfit, v};
      }
      std::sort(by_fit.begin(), by_fit.begin() + n);
      for (int i = 0; i < n; ++i)
        m[static_cast<std::size_t>(i)] = by_fit[static_cast<std::size_t>(i)].second;
      auto& c = choosable[static_cast<std::size_t>(g)];
      int& nc = nchoose[static_cast<std::size_t>(g)];
      nc = 0;
      for (int i = 0; i < count[static_cast<std::size_t>(g)]; ++i)
        if (holds(cs[m[static_cast<std::size_t>(i)]].pc))
          c[static_cast<std::size_t>(nc++)] = m[static_cast<std::size_t>(i)];
    }
  }

  // Enumerate one choosable member or none per plane (none last), at most 3 chosen, every
  // skipped plane accounted for (apart or explained). Rank: no plane left to an
  // explanation (another reading of a chosen touch, closures meeting: loose, so only when
  // no CF holds a PC in that plane), then fewest dominated PCs (a v-f beside the e-f of its
  // edge is only taken when the e-f cannot form a CF), then previous / neighbour / other,
  // then total misfit (which favours the exact CF over one that also holds a pair 0.05 mm
  // away), then enumeration order. The best goes to best and best_chosen.
  void best_interpretation(int G, Ranked& best, int* best_chosen) {
    std::array<int, kMaxGroups> digit{};  // index into choosable, nchoose[g] means "none"
    std::array<bool, kMaxGroups> taken{};
    // Also bound the walk itself: combinations with more than 3 planes chosen are skipped
    // without counting.
    long walk = 0;
    const long walk_cap = 16L * prm.max_combinations;
    for (;;) {
      if (++walk > walk_cap) {
        res->capped = true;
        break;
      }
      int chosen[3];
      int n = 0;
      bool too_many = false;
      for (int g = 0; g < G && !too_many; ++g) {
        const int d = digit[static_cast<std::size_t>(g)];
        taken[static_cast<std::size_t>(g)] = d < nchoose[static_cast<std::size_t>(g)];
        if (taken[static_cast<std::size_t>(g)]) {
          if (n == 3)
            too_many = true;
          else
            chosen[n++] = choosable[static_cast<std::size_t>(g)][static_cast<std::size_t>(d)];
        }
      }
      if (!too_many && n > 0) {
        if (res->combinations >= prm.max_combinations) {
          res->capped = true;
          break;
        }
        ++res->combinations;
        Ranked r;
        if (rank(chosen, n, taken.data(), G, best, r) && r.better_than(best)) {
          best = r;
          std::copy(chosen, chosen + n, best_chosen);
          if (best.unbeatable()) break;
        }
      }
      // Next combination (mixed radix, last plane fastest).
      int g = G - 1;
      while (g >= 0 && ++digit[static_cast<std::size_t>(g)] > nchoose[static_cast<std::size_t>(g)])
        digit[static_cast<std::size_t>(g--)] = 0;
      if (g < 0) break;
    }
  }

  void run() {
    const ContactSet& cs = res->contacts;
    clear_result();
    if (cs.empty()) {
      res->status = IdStatus::kNoContact;
      return;
    }
    const int G = cs.num_planes();
    if (G > kMaxGroups) {
      res->status = IdStatus::kTooManyPlanes;
      return;
    }
    sort_planes(G);
    if (try_previous(G)) return;
    Ranked best;
    int best_chosen[3] = {-1, -1, -1};
    best_interpretation(G, best, best_chosen);
    if (!best.id.valid()) {
      res->status = G > 3 ? IdStatus::kTooManyPlanes : IdStatus::kOutsideGraph;
      return;
    }
    IdStatus st = best.cat == 0   ? IdStatus::kMatchedPrevious
                  : best.cat == 1 ? IdStatus::kMatchedNeighbour
                  : prev.valid()  ? IdStatus::kNonNeighbourJump
                                  : IdStatus::kMatchedByFit;
    set_result(st, best.id, best_chosen, best.n, best.misfit, best.partial);
  }
};

void IdentifyScratchDelete::operator()(IdentifyScratch* s) const { delete s; }
IdentifyScratchPtr make_identify_scratch() { return IdentifyScratchPtr(new IdentifyScratch()); }

void identify(const CfGraph& graph, const IdentificationParams& params, double epsilon_mm,
              CfId previous, IdentifyScratch& s, Identification& id) {
  s.graph = &graph;
  s.prm = params;
  s.eps_mm = epsilon_mm;
  s.res = &id;
  s.prev = previous;
  s.run();
  s.res = nullptr;
}

}  // namespace internal

}  // namespace cf

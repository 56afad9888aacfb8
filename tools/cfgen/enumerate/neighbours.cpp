// Failed sets near their neighbours (after each fixed point): a CF valid only in a sliver of
// orientations (a peg tilted across a hole's rim) is missed by the search's samples, but the
// CFs one change away (one PC replaced by a neighbouring PC, cf::neighbouring_pcs) hold on
// either side of it, at rotations a few hundredths of a radian from the one it needs, and so
// do the CFs that cover it (a face on the wall where the set has a vertex). Each failed set
// with such CFs is searched again near their witnesses (WitnessSearch::find, seeds_only): one
// member of an orbit a round, up to kOrbitTries members over the rounds, as the levels do, each
// member once. The rounds add CFs, never take one away, so a graph holds every CF the fixed point
// before them found.

#include "cfgen/enumerate/enumerator.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <string>
#include <utility>

namespace cf::gen::internal {
namespace {

// Witnesses of neighbouring CFs a failed set is searched again from.
constexpr std::size_t kNeighbourSeeds = 16;

// Sets or CFs a chunk of a round's screening: a few milliseconds of work.
constexpr std::size_t kScreenChunk = 4096;
// since[] for every CF, old or new (any_covering_cf).
constexpr std::size_t kAllCfs[3] = {0, 0, 0};

// The elements of m that hold (kind, i) in their closures, itself first.
std::vector<std::pair<ElementKind, int>> elements_over(const Polyhedron& m, ElementKind kind,
                                                       int i) {
  std::vector<std::pair<ElementKind, int>> out{{kind, i}};
  if (kind == ElementKind::kVertex) {
    for (EdgeId e : m.vertices()[i].edges) out.push_back({ElementKind::kEdge, e.value()});
    for (FaceId f : m.vertices()[i].faces) out.push_back({ElementKind::kFace, f.value()});
  } else if (kind == ElementKind::kEdge) {
    out.push_back({ElementKind::kFace, m.edges()[i].left.value()});
    out.push_back({ElementKind::kFace, m.edges()[i].right.value()});
  }
  return out;
}

// The PC type of an A element of kind ka against a B element of kind kb; none for the
// degenerate pairs (v-v, v-e, e-v).
std::optional<PcType> type_of(ElementKind ka, ElementKind kb) {
  for (PcType t : {PcType::kFF, PcType::kEF, PcType::kFE, PcType::kVF, PcType::kFV, PcType::kEE})
    if (a_kind(t) == ka && b_kind(t) == kb) return t;
  return std::nullopt;
}

// A PC as one number: the key of cfs_by_pc_.
std::uint64_t pc_key(const Pc& p) {
  return static_cast<std::uint64_t>(p.type) << 56 | static_cast<std::uint64_t>(p.a) << 28 |
         static_cast<std::uint64_t>(p.b);
}

// The PCs whose elements hold p's in their closures, p among them: a CF with such a PC holds
// p's contact, and lifting the rest of that PC's elements off leaves p.
std::vector<Pc> covering_pcs(const Pc& p, const Polyhedron& A, const Polyhedron& B) {
  std::vector<Pc> out;
  for (const auto& [ka, a] : elements_over(A, a_kind(p.type), p.a))
    for (const auto& [kb, b] : elements_over(B, b_kind(p.type), p.b))
      if (const auto t = type_of(ka, kb)) out.push_back({*t, a, b});
  return out;
}

}  // namespace

// The neighbouring PCs of every PC in `pcs` not known yet, computed on all threads and
// kept in pc_neighbours_.
void Enumerator::know_neighbours(const std::vector<Pc>& pcs) {
  std::vector<Pc> missing;
  for (const Pc& pc : pcs)
    if (!pc_neighbours_.count(pc)) missing.push_back(pc);
  std::sort(missing.begin(), missing.end());
  missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
  std::vector<std::vector<Pc>> nb(missing.size());
  runner_.for_each(missing.size(),
                   [&](std::size_t i) { nb[i] = cf::neighbouring_pcs(missing[i], A_, B_); });
  for (std::size_t i = 0; i < missing.size(); ++i)
    pc_neighbours_.emplace(missing[i], std::move(nb[i]));
}

// The sets one change away from s (one PC replaced by a neighbouring PC), in a fixed order,
// each with the position k of the PC replaced and the PC q that replaces it. Reads only:
// every PC of s must be in pc_neighbours_ (know_neighbours).
void Enumerator::changes_of(const PcSet& s, const ChangeFn<void>& fn) const {
  any_change(s, [&](const PcSet& n, int k, const Pc& q) {
    fn(n, k, q);
    return false;
  });
}

// Whether some set one change away from s satisfies `pred` (stops at the first).
bool Enumerator::any_change(const PcSet& s, const ChangeFn<bool>& pred) const {
  for (int k = 0; k < s.size(); ++k)
    for (const Pc& q : pc_neighbours_.at(s[k])) {
      PcSet n = without(s, k);
      if (n.insert(q) && pred(n, k, q)) return true;
    }
  return false;
}

// Whether a set is worth a neighbour search this round, judged on what the round starts
// with: never (valid, searched near before, or its orbit tried kOrbitTries times: each stays
// so, as witnesses, searches and tries only grow), not yet (no set one change away is
// valid), or yes, its orbit in `orbit`. `st` keeps what later rounds need not work out
// again: that a valid set is one change away (which stays true).
Enumerator::Near Enumerator::near_candidate(const PcSet& s, NearState& st,
                                            const PcSetMap<std::vector<Pc>>& new_by_rest,
                                            PcSet& orbit) const {
  if (witness_rot_.count(s) || near_searched_.count(s)) return Near::kNever;
  return near_unsearched(s, st, new_by_rest, orbit);
}

// near_candidate() for a set known to be neither valid nor searched near.
Enumerator::Near Enumerator::near_unsearched(const PcSet& s, NearState& st,
                                             const PcSetMap<std::vector<Pc>>& new_by_rest,
                                             PcSet& orbit) const {
  if (!st.valid_change) {
    // Checked before, or new_by_rest holds every CF (the first round): the CFs in new_by_rest
    // are the only ones that can have changed the answer.
    st.valid_change = st.checked || near_screened_none_
                          ? valid_change_among(s, new_by_rest)
                          : any_change(s, [&](const PcSet& n, int, const Pc&) {
                              return witness_rot_.count(n) > 0;
                            });
    st.checked = true;
    if (!st.valid_change) return Near::kNotYet;
  }
  orbit = sym_.canonical(s);
  auto it = near_tries_.find(orbit);
  return it == near_tries_.end() || it->second < kOrbitTries ? Near::kYes : Near::kNever;
}

// The CFs found since the last round's screening, by what is left of each when one PC is
// taken out, with the PC taken out: the changes they are of a set screened before.
PcSetMap<std::vector<Pc>> Enumerator::new_cfs_by_rest() const {
  PcSetMap<std::vector<Pc>> out;
  for (int l = 0; l < 3; ++l)
    for (std::size_t i = near_screened_cfs_[l]; i < valid_[l].size(); ++i) {
      const PcSet& c = valid_[l][i].first;
      for (int k = 0; k < c.size(); ++k) out[without(c, k)].push_back(c[k]);
    }
  return out;
}

// Whether one of the CFs in `new_by_rest` is one change away from s: s[j] replaced by a
// neighbouring PC.
bool Enumerator::valid_change_among(const PcSet& s,
                                    const PcSetMap<std::vector<Pc>>& new_by_rest) const {
  for (int j = 0; j < s.size(); ++j) {
    auto it = new_by_rest.find(without(s, j));
    if (it == new_by_rest.end()) continue;
    const std::vector<Pc>& nb = pc_neighbours_.at(s[j]);
    for (const Pc& q : it->second)
      if (std::find(nb.begin(), nb.end(), q) != nb.end()) return true;
  }
  return false;
}

// Extends cfs_by_pc_ with the CFs found since it was last extended.
void Enumerator::index_cfs_by_pc() {
  for (std::uint32_t l = 0; l < 3; ++l) {
    for (std::size_t i = by_pc_indexed_[l]; i < valid_[l].size(); ++i)
      for (const Pc& pc : valid_[l][i].first)
        cfs_by_pc_[pc_key(pc)].push_back(l << 30 | static_cast<std::uint32_t>(i));
    by_pc_indexed_[l] = valid_[l].size();
  }
}

// Calls fn with each CF t other than s, found at or after since[level], that covers s (each PC
// of s lies in the closures of a PC of t: t's witness realises s's contacts, and lifting the
// rest of t's elements off can leave exactly s), until fn returns true; whether it did. The
// CFs are looked up through the PC of s with the fewest covering PCs.
bool Enumerator::any_covering_cf(const PcSet& s, const std::size_t (&since)[3],
                                 const CoverFn& fn) const {
  std::vector<Pc> through;
  for (const Pc& p : s)
    if (std::vector<Pc> c = covering_pcs(p, A_, B_); through.empty() || c.size() < through.size())
      through = std::move(c);
  for (const Pc& q : through) {
    const auto it = cfs_by_pc_.find(pc_key(q));
    if (it == cfs_by_pc_.end()) continue;
    for (const std::uint32_t e : it->second) {
      const std::uint32_t l = e >> 30, i = e & ((1u << 30) - 1);
      if (i < since[l]) continue;
      const auto& [t, w] = valid_[l][i];
      if (t == s) continue;
      const bool covers = std::all_of(s.begin(), s.end(), [&](const Pc& p) {
        return covered_by(A_, B_, t, a_kind(p.type), p.a, b_kind(p.type), p.b);
      });
      if (covers && fn(t, w.pose.R_BA)) return true;
    }
  }
  return false;
}

// Screens one failed set into `kept`; marks it dead when it can never be worth a search. A
// CF that covers a failed single or pair counts as a set one change away: its witness is as
// near. Failed triples are left out: the triples on a pair found so are candidates of the next
// level, and screening the 12-gon peg and hole's 1.4 million failed triples took 25 s.
void Enumerator::screen_failed(std::size_t i, const PcSetMap<std::vector<Pc>>& new_by_rest,
                               std::vector<Kept>& kept) {
  NearState& st = failed_near_[i];
  if (!st.valid_change && !failed_dead_[i] && failed_[i].size() <= 2 &&
      any_covering_cf(failed_[i], st.checked ? near_since_ : kAllCfs,
                      [](const PcSet&, const Mat3&) { return true; }))
    st.valid_change = true;
  PcSet orbit;
  const Near r = near_candidate(failed_[i], failed_near_[i], new_by_rest, orbit);
  if (r == Near::kYes) kept.push_back({failed_[i], orbit});
  failed_dead_[i] = r == Near::kNever;
}

// Screens the changes of CF i of `level` into `kept`: the sets no level proposed (a subset of
// theirs is missing) and that the necessary conditions allow. The first time, each change is
// worked out; after, only those that were not passed by for good (kept in cf_near_), in the
// same order. Marks the CF dead when none is left.
void Enumerator::screen_cf(int level, std::size_t i, const PcSetMap<std::vector<Pc>>& new_by_rest,
                           std::vector<Kept>& kept) {
  const PcSet& s = valid_[level][i].first;
  std::vector<NearChange>& mine = cf_near_[level][i];
  auto keep = [&](const PcSet& n, const PcSet& orbit, Near r) {
    if (r == Near::kYes) kept.push_back({n, orbit});
    return r != Near::kNever;
  };
  PcSet orbit;
  if (!cf_screened_[level][i]) {
    cf_screened_[level][i] = 1;
    changes_of(s, [&](const PcSet& n, int k, const Pc& q) {
      if (witness_rot_.count(n) || near_searched_.count(n) || seen_.count(n) || !conditions_hold(n))
        return;
      // When s[k] neighbours q in turn, s is a change of n, and valid.
      const std::vector<Pc>& back = pc_neighbours_.at(q);
      NearChange c{q, static_cast<std::uint8_t>(k), {}};
      c.st.checked = c.st.valid_change = std::find(back.begin(), back.end(), s[k]) != back.end();
      if (keep(n, orbit, near_unsearched(n, c.st, new_by_rest, orbit))) mine.push_back(c);
    });
  } else {
    std::size_t left = 0;
    for (NearChange& c : mine) {
      PcSet n = without(s, c.k);
      n.insert(c.q);
      if (!seen_.count(n) && keep(n, orbit, near_candidate(n, c.st, new_by_rest, orbit)))
        mine[left++] = c;
    }
    mine.resize(left);
  }
  if (mine.empty()) {
    cf_dead_[level][i] = 1;
    std::vector<NearChange>().swap(mine);
  }
}

// The sets of a neighbour round, in order: the failed candidates, then the changes of the CFs
// (screen_cf). Screened in stages of the runner (on all threads; split between shards), taken
// in order on this thread: one member of an orbit a round.
std::vector<Task> Enumerator::neighbour_tasks() {
  // The PCs of the failed sets and of the CFs new since the last round, then those of the
  // new CFs' changes.
  std::vector<Pc> pcs, next;
  for (std::size_t i = failed_near_.size(); i < failed_.size(); ++i)
    pcs.insert(pcs.end(), failed_[i].begin(), failed_[i].end());
  for (int l = 0; l < 3; ++l)
    for (std::size_t i = near_screened_cfs_[l]; i < valid_[l].size(); ++i)
      next.insert(next.end(), valid_[l][i].first.begin(), valid_[l][i].first.end());
  pcs.insert(pcs.end(), next.begin(), next.end());
  know_neighbours(pcs);
  for (std::size_t i = 0, n = next.size(); i < n; ++i)
    for (const Pc& q : pc_neighbours_.at(next[i])) next.push_back(q);
  know_neighbours(next);
  const PcSetMap<std::vector<Pc>> new_by_rest = new_cfs_by_rest();
  index_cfs_by_pc();
  near_screened_none_ = near_screened_cfs_[0] + near_screened_cfs_[1] + near_screened_cfs_[2] == 0;
  std::copy(std::begin(near_screened_cfs_), std::end(near_screened_cfs_), near_since_);
  failed_dead_.resize(failed_.size(), 0);
  failed_near_.resize(failed_.size());
  for (int l = 0; l < 3; ++l) {
    cf_dead_[l].resize(valid_[l].size(), 0);
    cf_screened_[l].resize(valid_[l].size(), 0);
    cf_near_[l].resize(valid_[l].size());
    near_screened_cfs_[l] = valid_[l].size();
  }
  // The failed sets (list -1), then each level's CFs, each list a stage whose items keep their
  // chunk, and so their shard, from round to round. Screening reads only what the round
  // starts with; the sets taken go to `round` and count as searched once every list is done.
  RoundTake round;
  for (int list = -1; list < 3; ++list) {
    Stage st;
    st.size = list < 0 ? failed_.size() : valid_[list].size();
    st.chunk = kScreenChunk;
    st.owner_key = static_cast<std::size_t>(list + 1);
    st.make = [&, list](std::size_t i) {
      Task t;
      t.pcs = list < 0 ? failed_[i] : valid_[list][i].first;
      return t;
    };
    st.compute = [&, list](std::size_t i) {
      std::vector<Kept> kept;
      if (list < 0 && !failed_dead_[i])
        screen_failed(i, new_by_rest, kept);
      else if (list >= 0 && !cf_dead_[list][i])
        screen_cf(list, i, new_by_rest, kept);
      TaskResult r;
      for (const Kept& k : kept) r.sets.insert(r.sets.end(), {k.set, k.orbit});
      return r;
    };
    st.take = [&](std::size_t, TaskResult&& r) {
      for (std::size_t k = 0; k + 1 < r.sets.size(); k += 2)
        take_near(r.sets[k], r.sets[k + 1], round);
    };
    runner_.run(st);
  }
  for (const PcSet& orbit : round.orbits) ++near_tries_[orbit];
  near_searched_.insert(round.searched.begin(), round.searched.end());
  return std::move(round.tasks);
}

// A set the screening kept, made a task of the round unless it or another member of its orbit
// was taken this round or the orbit has had its tries.
void Enumerator::take_near(const PcSet& s, const PcSet& orbit, RoundTake& round) const {
  const auto tries = near_tries_.find(orbit);
  if (near_searched_.count(s) || round.orbits.count(orbit) ||
      (tries != near_tries_.end() && tries->second >= kOrbitTries))
    return;
  round.orbits.insert(orbit);
  round.searched.insert(s);
  Task t;
  t.kind = Task::Kind::kFindNear;
  t.pcs = s;
  // The witnesses of the valid changes and of the CFs that cover s, taken in turn.
  std::vector<Mat3> changed, covering;
  changes_of(s, [&](const PcSet& n, int, const Pc&) {
    if (auto it = witness_rot_.find(n);
        it != witness_rot_.end() && changed.size() < kNeighbourSeeds)
      changed.push_back(it->second);
  });
  any_covering_cf(s, kAllCfs, [&](const PcSet&, const Mat3& R) {
    covering.push_back(R);
    return covering.size() >= kNeighbourSeeds;
  });
  for (std::size_t k = 0; t.seeds.size() < kNeighbourSeeds && k < kNeighbourSeeds; ++k)
    for (const auto* from : {&changed, &covering})
      if (k < from->size() && t.seeds.size() < kNeighbourSeeds) t.seeds.push_back((*from)[k]);
  round.tasks.push_back(std::move(t));
}

// The rounds' memory, once they are over: the records and the transitions need it more.
void Enumerator::release_neighbour_rounds() {
  PcSetSet().swap(near_searched_);
  PcSetMap<std::size_t>().swap(near_tries_);
  std::vector<char>().swap(failed_dead_);
  std::vector<NearState>().swap(failed_near_);
  for (int l = 0; l < 3; ++l) {
    std::vector<char>().swap(cf_dead_[l]);
    std::vector<char>().swap(cf_screened_[l]);
    std::vector<std::vector<NearChange>>().swap(cf_near_[l]);
  }
  std::map<Pc, std::vector<Pc>>().swap(pc_neighbours_);
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>>().swap(cfs_by_pc_);
}

// One round; returns the number of CFs found.
std::size_t Enumerator::neighbour_round() {
  const auto t0 = Clock::now();
  std::vector<Task> tasks = neighbour_tasks();
  ProgressEvent ev{"neighbour round " + std::to_string(++neighbour_rounds_),
                   "failed sets",
                   0,
                   tasks.size(),
                   0,
                   false,
                   {}};
  const std::vector<TaskResult> r = run_tasks(runner_, tasks, &ev, t0);
  prefetch_found(tasks, r);
  std::size_t found = 0;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (!r[i].witness.found || witness_rot_.count(tasks[i].pcs)) continue;
    const int level = tasks[i].pcs.size() - 1;
    const std::size_t before = valid_[level].size();
    accept(level, tasks[i].pcs, r[i].witness);
    ++out_.levels[level].by_neighbours;  // its images count under by_symmetry
    found += valid_[level].size() - before;
  }
  prefetched_.clear();
  finished(ev, t0, std::to_string(found) + " new CFs");
  return found;
}

}  // namespace cf::gen::internal

// The candidate levels: every single PC that local convexity allows, the pairs of single PCs
// (valid, or open: failed, and no rule refutes them) that the necessary conditions allow, and
// the triples whose three pairs are valid; each level searched one orbit at a time.

#include "cfgen/enumerate/enumerator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>

namespace cf::gen::internal {
namespace {

int element_count(const Polyhedron& m, ElementKind k) {
  return static_cast<int>(k == ElementKind::kVertex ? m.num_vertices()
                          : k == ElementKind::kEdge ? m.num_edges()
                                                    : m.num_faces());
}

// Rejects only pairs that no pose verify accepts can make hold (pair_conditions.hpp): ranges
// widened by far more than rounding (1e-9 rad: the slack's effect on the angle between two
// edges' normals is second order, 2.5e-7 rad for the default angle margin); normal cones
// shrunk by verify's local slack. Contact points range over the points min_margin inside
// their elements; half of it, as the LP's margin is checked only to its rounding.
constexpr double kAngleTol = 1e-9;

}  // namespace

PairConditions pair_conditions_for(const WitnessSearch& search) {
  const SearchParams& p = search.params();
  return PairConditions(search.a(), search.b(), 1e-9 * search.scale() + p.touch_tol, kAngleTol,
                        std::asin(search.verified_local_slack()) - kAngleTol, 0.5 * p.min_margin);
}

// A set found valid, and the images of it that are not known yet, each verified at the image
// of the witness (symmetric to rounding). Only the set found is explored by motion: its
// images' motions are the images of its own.
void Enumerator::accept(int level, const PcSet& s, const Witness& w) {
  valid_[level].push_back({s, w});
  witness_rot_.emplace(s, w.pose.R_BA);
  frontier_.push_back({s, w.pose});
  const auto pre = prefetched_.find(s);
  const bool have = pre != prefetched_.end() && pre->second.first.R_BA == w.pose.R_BA &&
                    pre->second.first.t_BA == w.pose.t_BA;
  for (std::size_t k = 1; k < sym_.size(); ++k) {
    const PcSet t = sym_.image(s, k);
    if (witness_rot_.count(t)) continue;
    const Witness v =
        have ? pre->second.second[k] : search_.image_witness(t, sym_.image(w.pose, k));
    if (!v.found) continue;
    valid_[level].push_back({t, v});
    witness_rot_.emplace(t, v.pose.R_BA);
    mark_searched(t);
    ++out_.levels[level].by_symmetry;
  }
}

// Verifies every image of each set found at the image of its witness, for the accept()
// calls that follow (in order, on this thread): the same witnesses accept() would compute,
// as a stage of tasks (kVerify), so that threads, shards and ranks share them and a
// checkpoint keeps them. Images already valid are skipped, as accept() skips them; a set
// whose witness differs from the one given is verified by accept() itself.
void Enumerator::prefetch_images(const std::vector<std::pair<PcSet, Pose>>& found) {
  prefetched_.clear();
  if (sym_.size() == 1 || found.empty()) return;
  std::vector<Task> tasks;
  std::vector<std::pair<std::size_t, std::size_t>> of;  // (found, symmetry) of each task
  for (std::size_t i = 0; i < found.size(); ++i)
    for (std::size_t k = 1; k < sym_.size(); ++k) {
      Task t;
      t.kind = Task::Kind::kVerify;
      t.pcs = sym_.image(found[i].first, k);
      if (witness_rot_.count(t.pcs)) continue;
      t.pose = sym_.image(found[i].second, k);
      tasks.push_back(std::move(t));
      of.emplace_back(i, k);
    }
  const std::vector<TaskResult> r = run_tasks(runner_, tasks, nullptr, Clock::now());
  std::vector<std::vector<Witness>> clear(found.size(), std::vector<Witness>(sym_.size()));
  for (std::size_t j = 0; j < tasks.size(); ++j) clear[of[j].first][of[j].second] = r[j].witness;
  for (std::size_t i = 0; i < found.size(); ++i)
    prefetched_.emplace(found[i].first, std::make_pair(found[i].second, std::move(clear[i])));
}

// prefetch_images for the tasks whose result found a witness.
void Enumerator::prefetch_found(const std::vector<Task>& tasks,
                                const std::vector<TaskResult>& results) {
  std::vector<std::pair<PcSet, Pose>> batch;
  for (std::size_t i = 0; i < tasks.size(); ++i)
    if (results[i].witness.found) batch.emplace_back(tasks[i].pcs, results[i].witness.pose);
  prefetch_images(batch);
}

// The candidates grouped by orbit, each orbit's members in candidate order, the orbits in the
// order of their first member. Flat (members, and where each orbit starts), and built from
// the candidates it takes with one copy: a large pair has tens of millions of them, hundreds
// of MB.
OrbitGroups Enumerator::orbits_of(std::vector<PcSet> cands) const {
  OrbitGroups g;
  if (sym_.size() == 1) {
    g.members = std::move(cands);
    g.first.resize(g.members.size() + 1);
    for (std::size_t i = 0; i < g.first.size(); ++i) g.first[i] = i;
    return g;
  }
  // Each candidate's orbit, numbered as first met. Every image of each orbit met so far is
  // entered with its number: one pass over the symmetries per orbit, not per candidate.
  std::vector<std::size_t> orbit(cands.size());
  std::size_t orbits = 0;
  PcSetMap<std::size_t> orbit_of;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    auto it = orbit_of.find(cands[i]);
    if (it == orbit_of.end()) {
      for (std::size_t k = 0; k < sym_.size(); ++k)
        orbit_of.emplace(sym_.image(cands[i], k), orbits);
      ++orbits;
      it = orbit_of.find(cands[i]);
    }
    orbit[i] = it->second;
  }
  // Counting sort by orbit, stable: the members of orbit o at [first[o], first[o + 1]).
  g.first.assign(orbits + 1, 0);
  for (std::size_t o : orbit) ++g.first[o + 1];
  for (std::size_t o = 1; o <= orbits; ++o) g.first[o] += g.first[o - 1];
  std::vector<std::size_t> next(g.first.begin(), g.first.end() - 1);
  g.members.resize(cands.size());
  for (std::size_t i = 0; i < cands.size(); ++i) g.members[next[orbit[i]]++] = cands[i];
  return g;
}

// One search per orbit: the others follow from its witness. The search samples, and an
// orbit's members meet its samples differently, so a failed orbit is searched again at its
// next members, up to kOrbitTries. Returns the sets searched.
std::size_t Enumerator::search_orbits(int level, const OrbitGroups& orbits, const SeedsOf& seeds_of,
                                      std::vector<char>& done, ProgressEvent& ev,
                                      Clock::time_point t0) {
  std::size_t searched = 0;
  for (std::size_t attempt = 0; attempt < kOrbitTries; ++attempt) {
    std::vector<std::size_t> open;
    for (std::size_t o = 0; o < orbits.size(); ++o) {
      if (done[o] || attempt >= orbits.count(o)) continue;
      // One member of an orbit with an open subset: those sets are many, nearly all invalid.
      if (attempt > 0 && level_seeds_.count(orbits.member(o, 0))) continue;
      if (witness_rot_.count(orbits.member(o, attempt))) {
        done[o] = 1;  // an image of a CF found meanwhile
        continue;
      }
      open.push_back(o);
    }
    if (open.empty()) break;
    // Taken once the stage has run, their images verified together (prefetch_images).
    std::vector<std::pair<std::size_t, Witness>> found;
    auto take = [&](std::size_t i, const Witness& w) {
      mark_searched(orbits.member(open[i], attempt));
      if (w.found) found.emplace_back(i, w);
    };
    // Seeds come from the sets below this level, which the results of this stage do not
    // change: the tasks are the same whenever they are made.
    ev.total = open.size();
    Stage stage;
    stage.size = open.size();
    stage.make = [&](std::size_t i) {
      Task t;
      t.kind = Task::Kind::kFind;
      t.pcs = orbits.member(open[i], attempt);
      t.seeds = seeds_of(t.pcs);
      return t;
    };
    stage.take = [&](std::size_t i, TaskResult&& r) {
      take(i, r.witness);
      forced_.insert(forced_.end(), r.met.begin(), r.met.end());
    };
    stage.progress = attempt == 0 ? &ev : nullptr;
    stage.started = t0;
    runner_.run(stage);
    std::vector<std::pair<PcSet, Pose>> batch;
    for (const auto& [i, w] : found) batch.emplace_back(orbits.member(open[i], attempt), w.pose);
    prefetch_images(batch);
    for (const auto& [i, w] : found)
      accept(level, orbits.member(open[i], attempt), w), done[open[i]] = 1;
    prefetched_.clear();
    searched += open.size();
  }
  return searched;
}

// Members of found orbits whose image witness did not verify (rounding at a borderline
// pose): searched like any other set. Returns the sets searched.
std::size_t Enumerator::search_rest(int level, const OrbitGroups& orbits, const SeedsOf& seeds_of,
                                    const std::vector<char>& done, Clock::time_point t0) {
  std::vector<Task> rest;
  for (std::size_t o = 0; o < orbits.size(); ++o)
    if (done[o])
      for (std::size_t k = 0; k < orbits.count(o); ++k)
        if (const PcSet& m = orbits.member(o, k); !witness_rot_.count(m) && !seen_.count(m)) {
          Task t;
          t.pcs = m;
          t.seeds = seeds_of(m);
          rest.push_back(t);
        }
  if (rest.empty()) return 0;
  const std::vector<TaskResult> r = run_tasks(runner_, rest, nullptr, t0);
  prefetch_found(rest, r);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    mark_searched(rest[i].pcs);
    forced_.insert(forced_.end(), r[i].met.begin(), r[i].met.end());
    if (r[i].witness.found && !witness_rot_.count(rest[i].pcs))
      accept(level, rest[i].pcs, r[i].witness);
  }
  prefetched_.clear();
  return rest.size();
}

void Enumerator::run_level(int level, std::vector<PcSet> all, const SeedsOf& seeds_of) {
  const auto t0 = Clock::now();
  const OrbitGroups orbits = orbits_of(std::move(all));
  std::vector<char> done(orbits.size(), 0);
  const std::size_t before = valid_[level].size();
  ProgressEvent ev{
      "level " + std::to_string(level + 1), "candidate sets", 0, orbits.size(), 0, false, {}};
  std::size_t searched = search_orbits(level, orbits, seeds_of, done, ev, t0);
  searched += search_rest(level, orbits, seeds_of, done, t0);
  const std::size_t found = valid_[level].size() - before;
  ev.total = searched;
  // The other members: valid as images above, or failed with their orbit.
  for (const PcSet& m : orbits.members) {
    if (witness_rot_.count(m)) continue;
    mark_searched(m);
    if (!retrying_.count(m)) failed_.push_back(m);  // a retry is in failed_ already
  }
  LevelStats& st = out_.levels[level];
  st.candidates += searched;
  st.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  finished(ev, t0, std::to_string(found) + " valid");
}

// Level 1: every element pair that local convexity allows.
void Enumerator::singles_level() {
  run_level(0, single_candidates(), [](const PcSet&) { return std::vector<Mat3>{}; });
}

std::vector<PcSet> Enumerator::single_candidates() const {
  const ModelInfo& Ai = search_.a();
  const ModelInfo& Bi = search_.b();
  std::vector<PcSet> c1;
  const PcType types[] = {PcType::kFF, PcType::kEF, PcType::kFE,
                          PcType::kVF, PcType::kFV, PcType::kEE};
  for (PcType t : types) {
    const int na = element_count(A_, a_kind(t)), nb = element_count(B_, b_kind(t));
    for (int a = 0; a < na; ++a)
      for (int b = 0; b < nb; ++b) {
        if ((t == PcType::kEF || t == PcType::kEE) && !A_.edges()[a].convex) continue;
        if ((t == PcType::kFE || t == PcType::kEE) && !B_.edges()[b].convex) continue;
        if (t == PcType::kVF && !Ai.cones[a].pointed) continue;
        if (t == PcType::kFV && !Bi.cones[b].pointed) continue;
        c1.push_back(PcSet({Pc{t, a, b}}));
      }
  }
  return c1;
}

// The witness rotations of the set's subsets one PC smaller that are valid.
std::vector<Mat3> Enumerator::seeds_from_subsets(const PcSet& s) const {
  std::vector<Mat3> seeds;
  for (int k = 0; k < s.size(); ++k) {
    auto it = witness_rot_.find(without(s, k));
    if (it != witness_rot_.end()) seeds.push_back(it->second);
  }
  return seeds;
}

// How many of s's subsets one PC smaller are valid: the witnesses that seed its search.
int Enumerator::valid_subsets(const PcSet& s) const {
  int n = 0;
  for (int k = 0; k < s.size(); ++k) n += static_cast<int>(witness_rot_.count(without(s, k)));
  return n;
}

// The failed single PCs that no rule refutes (WitnessSearch::refuted_by) are open: a pose may
// realise them with the other contacts of a pair (a face against one wall of a slot exactly
// the part's width touches the other too). Each one's rule is kept for find_undecided. The
// valid single PCs found since join singles_, the single PCs pairs are built from, and so do
// the open ones once admitted (admit_open_singles).
void Enumerator::update_open_singles() {
  std::vector<std::size_t> todo;
  for (std::size_t i = failed_classified_; i < failed_.size(); ++i)
    if (failed_[i].size() == 1) todo.push_back(i);
  failed_classified_ = failed_.size();
  std::vector<RuleVerdict> rule(todo.size());
  runner_.for_each(todo.size(),
                   [&](std::size_t k) { rule[k] = search_.refuted_by(failed_[todo[k]]); });
  for (std::size_t k = 0; k < todo.size(); ++k) {
    failed_rule_.emplace(todo[k], rule[k]);
    if (rule[k].rule == Rule::kNone) open_singles_.push_back(failed_[todo[k]][0]);
  }
  for (const auto& [s, w] : valid_[0])
    if (single_at_.emplace(s[0], singles_.size()).second) singles_.push_back(s[0]);
  if (open_admitted_)
    for (const Pc& pc : open_singles_)
      if (single_at_.emplace(pc, singles_.size()).second) singles_.push_back(pc);
}

// Admits the open single PCs to the pairs, once the levels and motion have reached a fixed
// point without them: pairs of open PCs are many and nearly all invalid, and searched before
// that point they change the order in which the search meets the rest (on the hexagonal peg
// and hole it then finds 432 CFs fewer). True when there are any to admit.
bool Enumerator::admit_open_singles() {
  if (open_admitted_) return false;
  open_admitted_ = true;
  return !open_singles_.empty();
}

// Adds s to `cands`, once, when it was searched while some of its subsets one PC smaller were
// open and more of them are valid now: searched again, seeded with the new witnesses.
void Enumerator::retry_if_seeded(const PcSet& s, std::vector<PcSet>& cands) {
  const auto it = seen_.find(s);
  if (it == seen_.end() || it->second >= s.size() || witness_rot_.count(s) ||
      valid_subsets(s) <= it->second)
    return;
  if (retrying_.insert(s).second) cands.push_back(s);
}

// Notes how many of each candidate's subsets one PC smaller are valid, for those with fewer
// than all (level_seeds_), for mark_searched.
void Enumerator::note_seeds(const std::vector<PcSet>& cands) {
  std::vector<std::uint8_t> n(cands.size());
  runner_.for_each(cands.size(), [&](std::size_t i) {
    n[i] = static_cast<std::uint8_t>(valid_subsets(cands[i]));
  });
  level_seeds_.clear();
  for (std::size_t i = 0; i < cands.size(); ++i)
    if (n[i] < cands[i].size()) level_seeds_.emplace(cands[i], n[i]);
}

// Marks s searched (seen_), with how many of its subsets seeded it (level_seeds_; kAllSeeds for
// a set searched with all of them, or met outside the levels).
void Enumerator::mark_searched(const PcSet& s) {
  const auto it = level_seeds_.find(s);
  seen_.insert_or_assign(s, it == level_seeds_.end() ? kAllSeeds : it->second);
}

// Level 2 over the single PCs (valid or open) not paired yet, each with every one before it.
std::vector<PcSet> Enumerator::build_pairs() {
  const std::size_t n = singles_.size();
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw Error("level 2: " + std::to_string(n) + " single PCs, more than the pairs' indices hold");
  // Each new single PC against the ones before it, on all cores (the conditions cost
  // microseconds a pair, and big models have millions of pairs); joined in order. Each
  // partner is kept as its index (a tenth of a set's size) until the sets are built, so that
  // tens of millions of candidates are not held twice.
  std::vector<std::vector<std::uint32_t>> by_j(n - singles_paired_);
  runner_.for_each(by_j.size(), [&](std::size_t k) {
    const std::size_t j = singles_paired_ + k;
    const Pc& y = singles_[j];
    for (std::size_t i = 0; i < j; ++i) {
      const Pc& x = singles_[i];
      // The table lookups first: they reject most pairs, for less than the set and its hash.
      if (!pair_ok_.compatible(x, y)) continue;
      PcSet s({x, y});
      if (seen_.count(s) || !search_.plausible(s)) continue;
      by_j[k].push_back(static_cast<std::uint32_t>(i));
    }
  });
  std::size_t total = 0;
  for (const auto& v : by_j) total += v.size();
  std::vector<PcSet> c2;
  c2.reserve(total);
  for (std::size_t k = 0; k < by_j.size(); ++k) {
    const Pc& y = singles_[singles_paired_ + k];
    for (std::uint32_t i : by_j[k]) c2.push_back(PcSet({singles_[i], y}));
    std::vector<std::uint32_t>().swap(by_j[k]);
  }
  singles_paired_ = n;
  return c2;
}

void Enumerator::pairs_level() {
  update_open_singles();
  std::vector<PcSet> c2 = build_pairs();
  // The pairs of a single PC found valid since the last time, searched before without it.
  for (std::size_t i = singles_valid_; i < valid_[0].size(); ++i)
    for (const Pc& y : singles_) {
      PcSet s = valid_[0][i].first;
      if (s.insert(y)) retry_if_seeded(s, c2);
    }
  singles_valid_ = valid_[0].size();
  note_seeds(c2);
  run_level(1, std::move(c2), [this](const PcSet& s) { return seeds_from_subsets(s); });
  retrying_.clear();
  level_seeds_.clear();
}

// Level 3 over every set whose three pairs are valid and that was not searched yet.
void Enumerator::triples_level() {
  // The valid pairs as partners: for each single PC x, the single PCs z (by index in singles_)
  // with {x, z} valid. A pair's third PCs are the partners of both.
  std::map<Pc, std::vector<std::size_t>> partners;
  for (const auto& [s, w] : valid_[1])
    for (int k = 0; k < 2; ++k)
      if (auto it = single_at_.find(s[1 - k]); it != single_at_.end())
        partners[s[k]].push_back(it->second);
  for (auto& [pc, v] : partners) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  std::vector<PcSet> c3;
  std::vector<std::size_t> common;
  for (const auto& [s, w] : valid_[1]) {
    const auto x = partners.find(s[0]), y = partners.find(s[1]);
    if (x == partners.end() || y == partners.end()) continue;
    common.clear();
    std::set_intersection(x->second.begin(), x->second.end(), y->second.begin(), y->second.end(),
                          std::back_inserter(common));
    for (std::size_t i : common) {  // in singles_'s order
      const Pc& z = singles_[i];
      if (!(s[1] < z)) continue;  // z beyond both, so each triple is built once
      PcSet t;
      t.insert(s[0]);
      t.insert(s[1]);
      t.insert(z);
      if (!seen_.count(t) && search_.plausible(t)) c3.push_back(t);
    }
  }
  pairs_tripled_ = valid_[1].size();
  run_level(2, std::move(c3), [this](const PcSet& s) { return seeds_from_subsets(s); });
}

// Sets the necessary conditions reject cannot be verified: not searched (most sets that
// motion meets have a contact on an element's boundary).
bool Enumerator::conditions_hold(const PcSet& t) const {
  for (int x = 0; x < t.size(); ++x)
    for (int y = x + 1; y < t.size(); ++y)
      if (!pair_ok_.compatible(t[x], t[y])) return false;
  return search_.plausible(t);
}

}  // namespace cf::gen::internal

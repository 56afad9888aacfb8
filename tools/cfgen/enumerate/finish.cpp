// The steps after the fixed point: the orbit closure (--thorough), the proofs of invalidity
// of the failed candidates, and the CF records.

#include "cfgen/enumerate/enumerator.hpp"

#include "cfgen/decide/cell_search.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace cf::gen::internal {

void Enumerator::finished(ProgressEvent& ev, Clock::time_point t0, const std::string& result) {
  ev.done = ev.total;
  ev.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  ev.finished = true;
  ev.result = result;
  runner_.report(ev);
}

// Orbit closure (--thorough): every member of every orbit met, at the image of the witness
// found. The search found each CF on its own, from its own seeds and motions; the images add
// the members it missed. Verified on all cores, added in a fixed order.
void Enumerator::close_orbits() {
  const PairSymmetries full(A_, B_, kSymmetryTol * search_.scale(), true);
  out_.symmetries_a = full.size_a();
  out_.symmetries_b = full.size_b();
  // A set's images from several CFs: the first in canonical order, and where that one does
  // not verify (rounding at a borderline pose), the next, up to kClosureTries.
  constexpr std::size_t kClosureTries = 4;
  for (int l = 0; l < 3; ++l) {
    const std::size_t found = valid_[l].size();
    for (std::size_t attempt = 0; attempt < kClosureTries; ++attempt) {
      std::vector<std::pair<PcSet, Witness>> images;
      PcSetMap<std::size_t> sources;  // images met so far, by set
      for (std::size_t i = 0; i < found; ++i) {
        const auto& [s, w] = valid_[l][i];
        for (std::size_t k = 1; k < full.size(); ++k) {
          const PcSet t = full.image(s, k);
          if (witness_rot_.count(t) || sources[t]++ != attempt) continue;
          Witness v = w;
          v.pose = full.image(w.pose, k);
          images.push_back({t, v});
        }
      }
      runner_.for_each(images.size(), [&](std::size_t i) {
        images[i].second = search_.image_witness(images[i].first, images[i].second.pose);
      });
      bool refused = false;
      for (auto& [t, v] : images) {
        if (!v.found) {
          refused = true;
          continue;
        }
        witness_rot_.emplace(t, v.pose.R_BA);
        valid_[l].push_back({t, v});
        ++out_.levels[l].by_symmetry;
      }
      if (!refused) break;
    }
  }
}

namespace {

// Cells the set searched for an orbit over arcs may take: kArcCellsPerSet for each open
// member of the orbit, at most kArcCellsPerOrbit, so that the search costs about what 64
// cells a set would while a set of a symmetric pair gets up to 4,000. Most sets refuted over
// arcs fail their rotational conditions or local slack in the first cells; a set whose
// relaxation holds over a face's worth of translations (refuted, if at all, by an obstacle)
// takes many more, and the n-gon pairs have many (docs/generator.md, "What the search could
// not decide").
constexpr std::size_t kArcCellsPerSet = 64;
constexpr std::size_t kArcCellsPerOrbit = 4000;

// What became of a failed set in find_undecided.
enum : char { kDecided, kOpen, kOverCells, kFound, kKnown, kImage };

bool has_ff(const PcSet& s) {
  for (const Pc& pc : s)
    if (pc.type == PcType::kFF) return true;
  return false;
}

}  // namespace

// Cells a set refuted by the finite-rotations rule may take when its certificate is asked
// for: the rule rests on rotations found in floating point, so the certificate file carries
// the cells' refutation instead when they give one.
constexpr std::size_t kCertificateCells = 4096;

// What the search could not decide: failed candidates that motion did not find either and
// that no proof rules out (WitnessSearch::refuted). Those on an f-f's circle of rotations go
// to the branch and bound over its arcs (search_cells), and with opt_.cube_cells the others
// over cubes of rotation space, with the verifier's margins: it refutes a set (no witness
// exists) or finds a witness. One set of each orbit of the pair's symmetries is searched, with
// tolerances loosened by how far the maps miss, so that its refutation covers the others
// (docs/certificates.md, "Images"). With opt_.certificates, every failed set's decision and
// evidence go to out_.decisions.
void Enumerator::find_undecided() {
  PcSetSet known;
  for (int l = 0; l < 3; ++l)
    for (const auto& [s, w] : valid_[l]) known.insert(s);
  const bool keep = opt_.certificates;
  std::vector<char> state(failed_.size(), kDecided);
  std::vector<SetDecision> decisions(keep ? failed_.size() : 0);
  const auto t0 = Clock::now();
  ProgressEvent ev{
      "proofs of invalidity", "failed candidate sets", 0, failed_.size(), 0, false, {}};
  const CellSearchLimits limits = decision_limits(search_, kArcCellsPerSet, opt_.resolution);
  runner_.for_each(
      failed_.size(),
      [&](std::size_t i) {
        const PcSet& s = failed_[i];
        if (known.count(s)) {
          state[i] = kKnown;
          return;
        }
        const auto ruled = failed_rule_.find(i);
        const RuleVerdict rule =
            ruled != failed_rule_.end() ? ruled->second : search_.refuted_by(s);
        if (keep) decisions[i] = certified(s, rule, limits);
        if (rule.rule == Rule::kNone) state[i] = kOpen;
      },
      &ev, t0);
  std::vector<std::pair<std::size_t, Witness>> found;  // (set, witness) the cells found
  decide_over_cells(state, found, decisions);
  std::vector<PcSet> open;
  for (std::size_t i = 0; i < failed_.size(); ++i) {
    if (state[i] == kOpen) open.push_back(failed_[i]);
    if (state[i] == kOverCells || state[i] == kImage) ++out_.refuted_over_cells;
  }
  for (const auto& [i, w] : found) add_with_images(failed_[i], w, known);
  std::sort(open.begin(), open.end(), pcset_less);
  finished(ev, t0, std::to_string(open.size()) + " without a proof");
  PcSetSet thin_sets;
  const auto thin = find_thin(open);
  for (const auto& [s, w] : thin)  // as clear as a witness: valid after all, with its images
    if (w.clearance >= search_.params().min_clearance && w.margin >= search_.params().min_margin)
      add_with_images(s, w, known);
  for (const auto& [s, w] : thin) {
    if (known.count(s)) continue;  // a CF, or the image of one
    thin_sets.insert(s);
    out_.thin.push_back({s, w});
  }
  open.erase(std::remove_if(open.begin(), open.end(),
                            [&](const PcSet& s) { return thin_sets.count(s) || known.count(s); }),
             open.end());
  out_.undecided = std::move(open);  // sorted, as found

  if (!keep) return;
  // Sets the cells found witnesses for, or made CFs as their images, are in the graph.
  for (std::size_t i = 0; i < failed_.size(); ++i) {
    if (known.count(failed_[i])) continue;
    decisions[i].pcs = failed_[i];
    decisions[i].invalid = state[i] != kOpen;
    if (thin_sets.count(failed_[i])) decisions[i].thin = true;
    out_.decisions.push_back(std::move(decisions[i]));
  }
  auto less = [](const SetDecision& x, const SetDecision& y) { return pcset_less(x.pcs, y.pcs); };
  std::sort(out_.decisions.begin(), out_.decisions.end(), less);
  out_.decisions.erase(
      std::unique(out_.decisions.begin(), out_.decisions.end(),
                  [](const SetDecision& x, const SetDecision& y) { return x.pcs == y.pcs; }),
      out_.decisions.end());
}

// The open sets (state kOpen) the cells take: those with an f-f and another PC over arcs of
// its circle (a single f-f's relaxation holds wherever its faces overlap: only obstacles
// refute it), the others over cubes when opt_.cube_cells asks. The first set of each orbit
// in failed_'s order is searched; the other open members of its orbit follow it: kImage
// when it is refuted, CFs when it has a witness (add_with_images, later), else open.
void Enumerator::decide_over_cells(std::vector<char>& state,
                                   std::vector<std::pair<std::size_t, Witness>>& found,
                                   std::vector<SetDecision>& decisions) {
  const CellSearchLimits arcs = decision_limits(search_, kArcCellsPerOrbit, opt_.resolution);
  const CellSearchLimits cubes = decision_limits(search_, opt_.cube_cells, opt_.resolution);
  // Cubes only for sets whose subsets one PC smaller are CFs: those with an open subset are
  // most of the failed triples, and a set's cubes cost up to opt_.cube_cells programs.
  auto takes_cells = [&](std::size_t i) {
    const PcSet& s = failed_[i];
    if (state[i] != kOpen) return false;
    if (has_ff(s)) return s.size() >= 2;
    return opt_.cube_cells > 0 && (s.size() == 1 || valid_subsets(s) == s.size());
  };
  // Each open set that takes cells, with the first member of its orbit; the first members.
  std::vector<std::pair<std::size_t, std::size_t>> member_of;  // (set, its orbit's first)
  std::vector<std::size_t> searched, members;                  // first members, orbit sizes
  PcSetMap<std::size_t> orbit;                                 // canonical set -> in searched
  for (std::size_t i = 0; i < failed_.size(); ++i) {
    if (!takes_cells(i)) continue;
    const auto [it, fresh] = orbit.emplace(sym_.canonical(failed_[i]), searched.size());
    if (fresh) {
      searched.push_back(i);
      members.push_back(0);
    }
    ++members[it->second];
    member_of.push_back({i, searched[it->second]});
  }
  const auto t0 = Clock::now();
  ProgressEvent ev{"cells", "orbits of open sets", 0, searched.size(), 0, false, {}};
  std::vector<Witness> witness(searched.size());
  runner_.for_each(
      searched.size(),
      [&](std::size_t j) {
        const std::size_t i = searched[j];
        const PcSet& s = failed_[i];
        const bool ff = has_ff(s);
        CellSearchLimits lim = ff ? arcs : cubes;
        if (ff) lim.max_cells = std::min(kArcCellsPerOrbit, kArcCellsPerSet * members[j]);
        if (members[j] > 1) lim = loosened(lim, sym_.error());
        auto tree = decisions.empty() ? nullptr : std::make_shared<CellTree>();
        const CellSearchResult r =
            search_cells(search_.a(), search_.b(), s, lim, &search_, tree.get());
        if (r.outcome == CellSearchResult::Outcome::kRefuted) {
          state[i] = kOverCells;
          if (tree) {
            decisions[i].cells = std::move(tree);
            decisions[i].cell_limits = lim;
          }
        }
        if (r.outcome == CellSearchResult::Outcome::kWitness) {
          state[i] = kFound;
          witness[j] = r.witness;
        }
      },
      &ev, t0);
  for (std::size_t j = 0; j < searched.size(); ++j)
    if (state[searched[j]] == kFound) found.emplace_back(searched[j], witness[j]);
  std::size_t refuted = 0;
  for (std::size_t i : searched) refuted += state[i] == kOverCells;
  finished(ev, t0, std::to_string(refuted) + " refuted");
  for (const auto& [i, rep] : member_of) {
    if (rep == i || state[rep] != kOverCells) continue;
    state[i] = kImage;
    if (decisions.empty()) continue;
    SetDecision& d = decisions[i];
    d.image_of = failed_[rep];
    for (std::size_t k = 0; k < sym_.size(); ++k)
      if (sym_.image(failed_[rep], k) == failed_[i]) {
        d.H = sym_.map_a(k).R;
        d.c_A = sym_.map_a(k).c;
        d.G = sym_.map_b(k).R;
        d.c_B = sym_.map_b(k).c;
        break;
      }
  }
}

// THIN sets (docs/generator.md, "Thin sets"): of the open sets (sorted), those a pose
// realises exactly, though only with a smaller clearance or margin than a witness has. One
// set of each orbit of the pair's symmetries is searched with thin_params; the others are
// taken at the images of its pose, and searched on their own where an image does not verify.
// Returns the sets found with their poses, in canonical order.
std::vector<std::pair<PcSet, Witness>> Enumerator::find_thin(const std::vector<PcSet>& open) {
  const WitnessSearch thin(search_.a(), search_.b(), thin_params(search_.params()));
  std::vector<std::pair<PcSet, Witness>> out;
  // `open` is sorted: a set's index by binary search, and flags by index instead of hash
  // sets (a large pair has millions of open sets).
  auto index_of = [&](const PcSet& t) {
    const auto it = std::lower_bound(open.begin(), open.end(), t, pcset_less);
    return it != open.end() && *it == t ? static_cast<std::size_t>(it - open.begin()) : open.size();
  };
  std::vector<PcSet> todo;                  // one set per orbit, then the members no image reached
  std::vector<char> taken(open.size(), 0);  // in todo, or an image of a set in it
  for (std::size_t i = 0; i < open.size(); ++i) {
    if (taken[i]) continue;
    todo.push_back(open[i]);
    for (std::size_t k = 0; k < sym_.size(); ++k)
      if (const std::size_t j = index_of(sym_.image(open[i], k)); j < open.size()) taken[j] = 1;
  }
  const auto t0 = Clock::now();
  ProgressEvent ev{"thin sets", "open candidate sets", 0, todo.size(), 0, false, {}};
  std::vector<char> done(open.size(), 0);  // searched, or an image of a set found
  for (int pass = 0; pass < 2 && !todo.empty(); ++pass) {
    std::vector<Witness> w(todo.size());
    runner_.for_each(
        todo.size(), [&](std::size_t i) { w[i] = thin.find(todo[i], {}); },
        pass == 0 ? &ev : nullptr, t0);
    for (const PcSet& t : todo) done[index_of(t)] = 1;
    std::vector<std::pair<PcSet, Witness>> images;
    for (std::size_t i = 0; i < todo.size(); ++i) {
      if (!w[i].found) continue;
      out.push_back({todo[i], w[i]});
      for (std::size_t k = 1; k < sym_.size() && pass == 0; ++k) {
        const PcSet t = sym_.image(todo[i], k);
        const std::size_t j = index_of(t);
        if (j == open.size() || done[j]) continue;
        done[j] = 1;
        Witness v = w[i];
        v.pose = sym_.image(w[i].pose, k);
        images.push_back({t, v});
      }
    }
    runner_.for_each(images.size(), [&](std::size_t i) {
      auto& [t, v] = images[i];
      const Witness image = thin.image_witness(t, v.pose);
      v = image.found ? image : Witness{};
    });
    todo.clear();
    for (auto& [t, v] : images)
      if (v.found)
        out.push_back({t, v});
      else
        todo.push_back(t);
  }
  // The searches report the margin their translation program reached, 0 where none ran: the
  // set's margin is the verifier's own measure at the pose.
  runner_.for_each(out.size(), [&](std::size_t i) {
    out[i].second.margin = search_.contact_margin(out[i].first, out[i].second.pose);
  });
  finished(ev, t0, std::to_string(out.size()) + " realised thin");
  std::sort(out.begin(), out.end(),
            [](const auto& x, const auto& y) { return pcset_less(x.first, y.first); });
  return out;
}

// The evidence for a set `rule` decided: the rule, or for the finite-rotations rule (rotations
// found in floating point, not a proof) a refutation over the arcs of its f-f's circle when
// one comes within kCertificateCells. Three e-f and f-e PCs keep the rule: cubes of rotation
// space refute none of the hexagonal peg and hole's 1,424 such sets within kCertificateCells
// each (a cube must shrink to the local slack around each of up to eight rotations), and
// trying took four minutes.
SetDecision Enumerator::certified(const PcSet& s, const RuleVerdict& rule,
                                  CellSearchLimits limits) const {
  SetDecision d;
  d.rule = rule;
  if (rule.rule != Rule::kFiniteRotations || !has_ff(s)) return d;
  limits.max_cells = kCertificateCells;
  auto tree = std::make_shared<CellTree>();
  const CellSearchResult r =
      search_cells(search_.a(), search_.b(), s, limits, &search_, tree.get());
  if (r.outcome == CellSearchResult::Outcome::kRefuted) {
    d.rule = {};
    d.cells = std::move(tree);
    d.cell_limits = limits;
  }
  d.contradicted = r.outcome == CellSearchResult::Outcome::kWitness;
  return d;
}

// A CF the decision found, and its images under the pair's symmetries that verify.
void Enumerator::add_with_images(const PcSet& s, const Witness& w, PcSetSet& known) {
  const int l = s.size() - 1;
  for (std::size_t k = 0; k < sym_.size(); ++k) {
    const PcSet t = sym_.image(s, k);
    if (known.count(t)) continue;
    const Witness v = search_.image_witness(t, sym_.image(w.pose, k));
    if (!v.found) continue;
    known.insert(t);
    valid_[l].push_back({t, v});
    ++out_.levels[l].valid;
    ++out_.levels[l].by_cells;
  }
}

// Each CF's record (its witness, freedoms and contact planes), in canonical order, and the
// smallest clearance and margin of the witnesses.
void Enumerator::build_records() {
  out_.min_clearance = std::numeric_limits<double>::infinity();
  out_.min_margin = std::numeric_limits<double>::infinity();
  for (int l = 0; l < 3; ++l) {
    std::sort(valid_[l].begin(), valid_[l].end(),
              [](const auto& x, const auto& y) { return pcset_less(x.first, y.first); });
    std::vector<CfRecord> records(valid_[l].size());
    std::vector<double> margins(valid_[l].size());
    runner_.for_each(valid_[l].size(), [&](std::size_t i) {
      const auto& [s, w] = valid_[l][i];
      CfRecord& r = records[i];
      r.pcs = s;
      r.witness = w.pose;
      search_.freedoms(s, w.pose, r);
      for (int k = 0; k < s.size(); ++k) {
        const auto [n, d] = search_.contact_plane(s[k], w.pose);
        r.planes[static_cast<std::size_t>(k)] = {n.x(), n.y(), n.z(), d};
      }
      r.num_planes = s.size();
      margins[i] = search_.contact_margin(s, w.pose);
    });
    for (std::size_t i = 0; i < records.size(); ++i) {
      out_.cfs.push_back(records[i]);
      out_.min_clearance = std::min(out_.min_clearance, valid_[l][i].second.clearance);
      out_.min_margin = std::min(out_.min_margin, margins[i]);
    }
  }
}

}  // namespace cf::gen::internal

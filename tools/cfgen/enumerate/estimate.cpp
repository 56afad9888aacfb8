// A run predicted without running it (enumerate.hpp, RunEstimate): the level-1 candidates
// counted, a few sets of each level decided on this machine, and the levels' sizes and the
// run's cost extrapolated from them (docs/generator.md, "Estimates").
//
// Level 1's candidates and orbits are counted exactly. Its sample (an orbit searched as the
// run searches one: up to kOrbitTries members) gives the fraction valid and the cost of an
// orbit. Levels 2 and 3 from the level below: its valid sets known (the sample's, with their
// images), each with every level-1 candidate the necessary conditions allow, give the sets
// one PC larger; the share of those whose subsets are all valid (decided for a few hundred)
// scales them to the level's candidates, and a sample of those, searched, gives the fraction
// valid and the cost. The closure by motion's cost per witness explored is sampled on the
// CFs the samples found, and so are the levels it sets off again: the single PCs those
// explorations meet that the level-1 search fails, paired and searched. The rest of what follows
// the levels (neighbour rounds, the work done per set rather than per orbit, records, transitions)
// is not sampled: it is taken from the sets the levels find and fail, their orbits and the cost of
// their searches, with constants measured on the pairs in docs/performance.md.

#include "cfgen/enumerate/enumerator.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include <sys/resource.h>
#include <time.h>

namespace cf::gen::internal {
namespace {

// Sets whose partners are counted to predict the next level's candidates.
constexpr std::size_t kRows = 256;
// CFs explored per set sampled a level: the single PCs that only motion reaches are met by
// few explorations, and their pairs' cost weighs heavily where they are many (CGAL's cross
// and U: with one, the prediction of its run varied by a fifth from one estimate to the next).
constexpr std::size_t kExploresPerSample = 2;
// Batches of samples_ sets, at most, whose unknown subsets are decided to find a level's
// candidates to sample.
constexpr std::size_t kGrowRounds = 8;

// Constants that turn the levels into a run, fitted (least worst ratio) on the bundled pairs,
// the n-gon pegs and holes n = 3..12 and CGAL's star, cross and U and three.js's emerald
// (star against cross and against itself, cross against U, emerald against itself) at one thread
// (scripts/estimate-errors.sh); docs/performance.md ("Estimates") gives the errors that remain.
//
// CFs in the graph per CF the levels find, and per candidate they fail: the rounds after the
// levels (motion, neighbours, the images of sets found there) find CFs among the sets the
// levels' searches missed, more where more failed (a peg tilted across a hole's rim), but
// few of a pair whose failed sets are most of its candidates (the emerald against itself:
// 2.2 million failed, 168,000 CFs found after the levels).
constexpr double kCfsPerLevelCf = 1.48;
constexpr double kCfsPerFailed = 0.038;
// CPU time after the levels' searches: the closure by motion, per witness it explores (up to
// kWitnessesPerOrbit an orbit found), as long as the sampled exploration (explore_seconds);
// per CF the levels find (its images verified, its changes screened, its record and
// transitions); per candidate they fail, searches of the levels' mean cost (a failed set is
// screened in every neighbour round); and per member of a failed orbit a neighbour round may
// search again (up to kOrbitTries an orbit), searches of that cost. The last two are
// fitted apart because pairs with few symmetries (CGAL's cross and U) have many more failed
// orbits per failed set than the symmetric n-gon pairs.
constexpr double kExploresPerWitness = 1.0;
constexpr double kFoundSeconds = 40e-6;  // s, on the machine of docs/performance.md
constexpr double kSearchesPerFailed = 0.06;
constexpr double kSearchesPerFailedTry = 1.5;
// Single PCs the closure by motion finds per level-1 candidate the level fails: on CGAL's
// cross against its U (the one pair measured whose levels run again at a cost), about 1,900
// of 5,200 (1,934 single-PC CFs beyond level 1's 4,368 at b7ecb18). Their pairs' count per
// single and search cost are sampled (motion_single_pairs); their number is not, as the
// explorations that meet them are too few in a sample to count them.
constexpr double kMotionSinglesPerFailed = 0.40;
// Of a run's time on one thread, the part that runs on one thread whatever the count.
constexpr double kSerial = 0.25;
// Transitions per CF: 15.5-25 on the pairs measured.
constexpr double kTransitionsPerCf = 18;
// Resident bytes at the run's peak above what the models take: per CF (records, the search's
// sets, the transitions built and sorted), and per member of a failed orbit a neighbour round
// may search (the rounds' memory of what they screened and searched: CGAL's cross and U
// peaked at 1.3-1.8 GB for 420,843 CFs, the emerald against itself at 2.6 GB for 537,872,
// with 0.4 and 2.2 million such members predicted; docs/performance.md).
constexpr double kBytesPerCf = 1650;
constexpr double kBytesPerFailedTry = 1300;

// k indices spread evenly over [0, n).
std::vector<std::size_t> spread(std::size_t n, std::size_t k) {
  std::vector<std::size_t> idx;
  k = std::min(k, n);
  for (std::size_t i = 0; i < k; ++i) idx.push_back(i * n / k);
  return idx;
}

// s of CPU this thread has used: a search's cost, whatever else the machine runs.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double peak_resident_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return 1024.0 * static_cast<double>(u.ru_maxrss);  // Linux: kB
}

}  // namespace

struct Enumerator::Sample {
  std::size_t decided = 0;                // orbits sampled
  std::size_t found = 0;                  // of them, found at one of up to kOrbitTries members
  double inv_orbit = 0;                   // mean of 1 / orbit size
  double members = 0, found_members = 0;  // orbit sizes summed over those sampled, the found
  double found_explored = 0;              // witnesses motion explores, summed over the found orbits
  double failed_tries = 0;  // members a failed orbit can have searched, summed over them
  double searches = 0;      // mean searches an orbit took
  double seconds = 0;       // s of CPU, mean an orbit took (all its searches)
  double valid_fraction() const { return decided ? double(found) / double(decided) : 0; }
};

// A found set and its images, taken as valid without verifying them (accept() verifies
// each): an estimate needs to know which sets are valid, not to prove it.
void Enumerator::take_unverified(int level, const PcSet& s, const Witness& w) {
  for (std::size_t g = 0; g < sym_.size(); ++g) {
    const PcSet t = sym_.image(s, g);
    if (witness_rot_.count(t)) continue;
    Witness v = w;
    v.pose = sym_.image(w.pose, g);
    witness_rot_.emplace(t, v.pose.R_BA);
    valid_[level].push_back({t, v});
  }
}

// The orbits of up to `count` sets spread over `pool`, searched as the run searches an
// orbit: the set, then, while none is found, up to `tries` of its images in all. Each
// search timed in CPU seconds of its thread, on the runner's threads.
Enumerator::Sample Enumerator::sample_sets(int level, const std::vector<PcSet>& pool,
                                           const SeedsOf& seeds_of, std::size_t count,
                                           std::size_t tries) {
  struct Orbit {
    std::vector<PcSet> members;  // the set sampled first, then its other images in order
    std::size_t tried = 0;
    bool found = false;
    double seconds = 0;
  };
  std::vector<Orbit> orbits;
  for (std::size_t i : spread(pool.size(), count)) {
    std::vector<PcSet> images;
    for (std::size_t g = 0; g < sym_.size(); ++g) images.push_back(sym_.image(pool[i], g));
    std::sort(images.begin(), images.end(), pcset_less);
    images.erase(std::unique(images.begin(), images.end()), images.end());
    Orbit o;
    o.members.push_back(pool[i]);
    for (const PcSet& m : images)
      if (m != pool[i]) o.members.push_back(m);
    orbits.push_back(std::move(o));
  }
  for (std::size_t attempt = 0; attempt < tries; ++attempt) {
    std::vector<std::size_t> open;
    for (std::size_t k = 0; k < orbits.size(); ++k) {
      Orbit& o = orbits[k];
      if (o.found || attempt >= o.members.size()) continue;
      if (witness_rot_.count(o.members[attempt]))
        o.found = true;  // found meanwhile
      else
        open.push_back(k);
    }
    std::vector<TaskResult> res(open.size());
    std::vector<double> sec(open.size());
    runner_.for_each(open.size(), [&](std::size_t j) {
      Task t;
      t.pcs = orbits[open[j]].members[attempt];
      t.seeds = seeds_of(t.pcs);
      const double c0 = thread_cpu_seconds();
      res[j] = decide(search_, t);
      sec[j] = thread_cpu_seconds() - c0;
    });
    for (std::size_t j = 0; j < open.size(); ++j) {
      Orbit& o = orbits[open[j]];
      ++o.tried;
      o.seconds += sec[j];
      if (res[j].witness.found)
        o.found = true, take_unverified(level, o.members[attempt], res[j].witness);
    }
  }
  Sample s;
  for (const Orbit& o : orbits) {
    const auto size = double(o.members.size());
    ++s.decided;
    s.inv_orbit += 1 / size;
    s.members += size;
    s.searches += double(o.tried);
    s.seconds += o.seconds;
    if (o.found) {
      ++s.found, s.found_members += size;
      s.found_explored += std::min(double(kWitnessesPerOrbit), size);
    } else {
      s.failed_tries += std::min(double(kOrbitTries), size);
    }
  }
  if (s.decided) {
    const auto n = double(s.decided);
    s.inv_orbit /= n, s.searches /= n, s.seconds /= n;
  }
  return s;
}

// The sets one PC larger than up to kRows valid sets of `level` - 1 known (spread over
// them): each with every level-1 candidate the necessary conditions allow with all of its
// PCs, shuffled with a fixed seed so that no set and no added PC comes first. mean_added:
// such PCs per set.
std::vector<PcSet> Enumerator::grown_sets(int level, const std::vector<PcSet>& singles,
                                          double& mean_added) {
  const auto& below = valid_[level - 1];
  const std::vector<std::size_t> rows = spread(below.size(), kRows);
  std::vector<std::vector<PcSet>> found(rows.size());
  runner_.for_each(rows.size(), [&](std::size_t r) {
    const PcSet& p = below[rows[r]].first;
    for (const PcSet& single : singles) {
      const Pc& z = single[0];
      bool ok = !p.contains(z);
      for (int k = 0; k < p.size() && ok; ++k) ok = pair_ok_.compatible(p[k], z);
      if (!ok) continue;
      PcSet t = p;
      t.insert(z);
      if (search_.plausible(t)) found[r].push_back(t);
    }
  });
  std::vector<PcSet> pool;
  for (const auto& f : found) pool.insert(pool.end(), f.begin(), f.end());
  mean_added = rows.empty() ? 0 : double(pool.size()) / double(rows.size());
  std::sort(pool.begin(), pool.end(), pcset_less);
  pool.erase(std::unique(pool.begin(), pool.end()), pool.end());
  std::mt19937_64 rng(0x5eed);
  std::shuffle(pool.begin(), pool.end(), rng);
  return pool;
}

// Of `pool`, the sets whose subsets one PC smaller are all valid (a pair's single PCs valid or
// open: failed, and no rule refutes them), as the run's candidates are: their unknown subsets
// searched once each (a candidate is not worth a level's retries), samples_ sets at a time,
// until samples_ such sets are found or kGrowRounds batches have been tried. fraction: the
// share of the sets tried that are candidates.
std::vector<PcSet> Enumerator::with_candidate_subsets(const std::vector<PcSet>& pool,
                                                      double& fraction) {
  std::vector<PcSet> out;
  std::size_t tried = 0;
  auto subsets = [](const PcSet& s) {
    std::vector<PcSet> subs;
    for (int k = 0; k < s.size(); ++k) subs.push_back(without(s, k));
    return subs;
  };
  for (std::size_t b = 0; b < pool.size() && b < kGrowRounds * samples_ && out.size() < samples_;
       b += samples_) {
    const std::size_t e = std::min(pool.size(), b + samples_);
    std::vector<PcSet> unknown;
    for (std::size_t i = b; i < e; ++i)
      for (const PcSet& sub : subsets(pool[i]))
        if (!witness_rot_.count(sub) && !known_failed_.count(sub)) unknown.push_back(sub);
    std::sort(unknown.begin(), unknown.end(), pcset_less);
    unknown.erase(std::unique(unknown.begin(), unknown.end()), unknown.end());
    if (!unknown.empty())
      sample_sets(
          unknown[0].size() - 1, unknown, [this](const PcSet& x) { return seeds_from_subsets(x); },
          unknown.size(), 1);
    std::vector<char> open(unknown.size(), 0);
    runner_.for_each(unknown.size(), [&](std::size_t i) {
      open[i] =
          unknown[i].size() == 1 && !witness_rot_.count(unknown[i]) && !search_.refuted(unknown[i]);
    });
    for (std::size_t i = 0; i < unknown.size(); ++i)
      if (!witness_rot_.count(unknown[i])) known_failed_.emplace(unknown[i], open[i] != 0);
    auto candidate = [&](const PcSet& sub) {  // valid, or an open single PC
      if (witness_rot_.count(sub)) return true;
      const auto it = known_failed_.find(sub);
      return it != known_failed_.end() && it->second;
    };
    for (std::size_t i = b; i < e; ++i) {
      ++tried;
      bool all = true;
      for (const PcSet& sub : subsets(pool[i])) all = all && candidate(sub);
      if (all) out.push_back(pool[i]);
    }
  }
  fraction = tried ? double(out.size()) / double(tried) : 0;
  return out;
}

// s of CPU the closure by motion takes to explore one CF, on the mean over up to `count`
// of the CFs the samples found (spread over the levels' lists): it varies with the models
// far more than a search does, as it follows the first contact of every element pair along
// each direction tried.
double Enumerator::explore_seconds(std::size_t count, std::vector<Discovery>& singles) {
  std::vector<Task> tasks;
  std::size_t total = 0;
  for (const auto& v : valid_) total += v.size();
  for (std::size_t i : spread(total, count)) {
    std::size_t level = 0;
    while (i >= valid_[level].size()) i -= valid_[level++].size();
    Task t;
    t.kind = Task::Kind::kExplore;
    t.pcs = valid_[level][i].first;
    t.pose = valid_[level][i].second.pose;
    tasks.push_back(t);
  }
  if (tasks.empty()) return 0;
  std::vector<double> sec(tasks.size());
  std::vector<TaskResult> res(tasks.size());
  runner_.for_each(tasks.size(), [&](std::size_t j) {
    const double c0 = thread_cpu_seconds();
    res[j] = decide(search_, tasks[j]);
    sec[j] = thread_cpu_seconds() - c0;
  });
  // The single PCs met that no sample found, one per orbit.
  PcSetSet orbits;
  for (const TaskResult& r : res)
    for (const Discovery& d : r.met)
      if (d.pcs.size() == 1 && !witness_rot_.count(d.pcs) && conditions_hold(d.pcs) &&
          orbits.insert(sym_.canonical(d.pcs)).second)
        singles.push_back(d);
  double sum = 0;
  for (double x : sec) sum += x;
  return sum / double(tasks.size());
}

// The levels after the closure by motion pair each single PC it finds with every valid
// single PC the necessary conditions allow; few of those pairs are valid (a single that only
// motion reaches holds in a sliver of poses), and their failed searches cost more than a
// level's (seeded at that sliver, they climb further). Sampled as the run meets them: of the
// single PCs the sampled explorations met (`met`), those whose orbit the level-1 search
// fails (up to kOrbitTries members) and whose met pose refines to a witness, up to `count`,
// each paired with up to kPartnersPerSingle valid singles spread over those it allows,
// searched as level 2 searches them.
Enumerator::PairSample Enumerator::motion_single_pairs(const std::vector<Discovery>& met,
                                                       std::size_t count) {
  constexpr std::size_t kPartnersPerSingle = 4;
  // Each met single: its orbit's first kOrbitTries members searched, then its met pose.
  std::vector<std::vector<Task>> level1(met.size());
  std::vector<Task> flat;
  for (std::size_t i = 0; i < met.size(); ++i) {
    std::vector<PcSet> members;
    for (std::size_t g = 0; g < sym_.size(); ++g) members.push_back(sym_.image(met[i].pcs, g));
    std::sort(members.begin(), members.end(), pcset_less);
    members.erase(std::unique(members.begin(), members.end()), members.end());
    for (std::size_t k = 0; k < members.size() && k < kOrbitTries; ++k) {
      Task t;
      t.pcs = members[k];
      flat.push_back(t);
    }
    Task r;
    r.kind = Task::Kind::kFindOrRefine;
    r.pcs = met[i].pcs;
    r.pose = met[i].pose;
    flat.push_back(r);
  }
  std::vector<TaskResult> res(flat.size());
  runner_.for_each(flat.size(), [&](std::size_t j) { res[j] = decide(search_, flat[j]); });
  // The motion-only singles, their witnesses known to seed their pairs.
  std::vector<Pc> only;
  for (std::size_t j = 0, i = 0; j < flat.size(); ++i) {
    bool by_level = false;
    for (; flat[j].kind == Task::Kind::kFind; ++j) by_level = by_level || res[j].witness.found;
    if (!by_level && res[j].witness.found && only.size() < count) {
      witness_rot_.emplace(flat[j].pcs, res[j].witness.pose.R_BA);
      only.push_back(flat[j].pcs[0]);
    }
    ++j;
  }
  std::vector<Task> tasks;
  double partners = 0;
  for (const Pc& p : only) {
    std::vector<PcSet> pairs;
    for (const auto& [q, w] : valid_[0]) {
      if (!pair_ok_.compatible(p, q[0])) continue;
      PcSet t = q;
      if (t.insert(p) && search_.plausible(t)) pairs.push_back(t);
    }
    partners += double(pairs.size());
    for (std::size_t k : spread(pairs.size(), kPartnersPerSingle)) {
      Task t;
      t.pcs = pairs[k];
      t.seeds = seeds_from_subsets(t.pcs);
      tasks.push_back(std::move(t));
    }
  }
  std::vector<double> sec(tasks.size());
  std::vector<char> found(tasks.size(), 0);
  runner_.for_each(tasks.size(), [&](std::size_t j) {
    const double c0 = thread_cpu_seconds();
    found[j] = decide(search_, tasks[j]).witness.found;
    sec[j] = thread_cpu_seconds() - c0;
  });
  PairSample out;
  out.singles = only.size();
  out.searched = tasks.size();
  if (!only.empty() && !valid_[0].empty())
    out.partner_share = partners / double(only.size()) / double(valid_[0].size());
  for (std::size_t j = 0; j < tasks.size(); ++j) out.seconds += sec[j], out.found += found[j];
  if (out.searched) out.seconds /= double(out.searched), out.found /= double(out.searched);
  return out;
}

namespace {

// A level's size and cost from its candidates and its sample. `by_orbit`: the sample took
// one set of each orbit (orbits weigh by their size), else sets (orbits as often as they
// have members).
template <class Sample>
void extrapolate(LevelEstimate& l, const Sample& s, bool by_orbit) {
  l.sampled = s.decided;
  if (!l.exact) l.orbits = l.candidates * s.inv_orbit;
  const double q =
      by_orbit ? (s.members > 0 ? s.found_members / s.members : 0) : s.valid_fraction();
  l.valid = l.candidates * q;
  l.explored = s.found_members > 0 ? l.valid * s.found_explored / s.found_members : 0;
  const double failed_members = s.members - s.found_members;
  l.failed_tries =
      failed_members > 0 ? (l.candidates - l.valid) * s.failed_tries / failed_members : 0;
  l.tasks = l.orbits * s.searches;
  l.cpu_seconds = l.orbits * s.seconds;
}

}  // namespace

// s of CPU the levels take again after the closure by motion: the single PCs it finds (a
// share of level 1's failed sets), each paired with the share of the valid single PCs the
// sample's such singles pair with (they pair with more than a valid single does: about twice
// as many on CGAL's cross and U), the failed pairs searched as a failed level-2 orbit's
// members are, at the cost sampled on such pairs (none when the sample meets no such single).
double Enumerator::after_motion_seconds(const RunEstimate& e, const std::vector<Discovery>& met) {
  if (opt_.max_pcs < 2) return 0;
  const LevelEstimate& l1 = e.levels[0];
  const LevelEstimate& l2 = e.levels[1];
  const double l2_failed = l2.candidates - l2.valid;
  const double tries = l2_failed > 0 ? l2.failed_tries / l2_failed : 0;
  const PairSample ps = motion_single_pairs(met, samples_);
  const double singles = kMotionSinglesPerFailed * std::max(0.0, l1.candidates - l1.valid);
  const double pairs = singles * ps.partner_share * l1.valid;
  if (std::getenv("CF_ESTIMATE_DEBUG"))
    std::fprintf(stderr,
                 "CAL after_motion pairs %g tries %g pair_s %g pair_found %g n %zu singles %zu "
                 "partner_share %g\n",
                 pairs, tries, ps.seconds, ps.found, ps.searched, ps.singles, ps.partner_share);
  return pairs * (1 - ps.found) * tries * ps.seconds;
}

RunEstimate Enumerator::estimate(int threads, std::size_t samples) {
  samples_ = std::max<std::size_t>(1, samples);
  const auto t0 = Clock::now();
  RunEstimate e;
  e.threads = std::max(1, threads);
  const double base_bytes = peak_resident_bytes();
  auto subsets = [this](const PcSet& s) { return seeds_from_subsets(s); };
  const std::vector<PcSet> c1 = single_candidates();
  LevelEstimate& l1 = e.levels[0];
  l1.candidates = double(c1.size());
  // Level 1's orbits are known: one set of each (spread over them) is decided, and the
  // fraction valid weighs each by its orbit's size.
  const OrbitGroups g1 = orbits_of(c1);
  l1.orbits = double(g1.size());
  l1.exact = true;
  std::vector<PcSet> firsts;
  for (std::size_t o = 0; o < g1.size(); ++o) firsts.push_back(g1.member(o, 0));
  const Sample s1 = sample_sets(
      0, firsts, [](const PcSet&) { return std::vector<Mat3>{}; }, samples_, kOrbitTries);
  extrapolate(l1, s1, true);
  // Levels 2 and 3: a valid set of the level below and a level-1 candidate the necessary
  // conditions allow with it make a candidate when its subsets one PC smaller are valid.
  for (int level = 1; level < opt_.max_pcs && level < 3; ++level) {
    const LevelEstimate& below = e.levels[level - 1];
    if (valid_[level - 1].empty() || below.valid <= 0) break;
    double added = 0, fraction = 0;
    const std::vector<PcSet> pool = with_candidate_subsets(grown_sets(level, c1, added), fraction);
    LevelEstimate& l = e.levels[level];
    l.candidates = below.valid * added * fraction / (level + 1);  // each counted by its PCs
    const Sample sample = sample_sets(level, pool, subsets, samples_, kOrbitTries);
    extrapolate(l, sample, false);
  }
  double level_cpu = 0, found = 0, failed = 0, searches = 0, explored = 0, failed_tries = 0;
  for (const LevelEstimate& l : e.levels) {
    explored += l.explored;
    failed_tries += l.failed_tries;
    level_cpu += l.cpu_seconds;
    found += l.valid;
    failed += std::max(0.0, l.candidates - l.valid);
    searches += l.tasks;
  }
  // s of CPU a search takes, on the mean over the levels' searches.
  const double search_seconds = searches > 0 ? level_cpu / searches : 0;
  std::vector<Discovery> met_singles;
  const double explore_s = explore_seconds(kExploresPerSample * samples_, met_singles);
  if (std::getenv("CF_ESTIMATE_DEBUG"))
    std::fprintf(stderr, "CAL met_singles %zu\n", met_singles.size());
  const double after_motion = after_motion_seconds(e, met_singles);
  e.cfs = kCfsPerLevelCf * found + kCfsPerFailed * failed;
  e.transitions = e.cfs * kTransitionsPerCf;
  e.cpu_seconds =
      level_cpu + kExploresPerWitness * explore_s * explored + kFoundSeconds * found +
      search_seconds * (kSearchesPerFailed * failed + kSearchesPerFailedTry * failed_tries) +
      after_motion;
  e.seconds = e.cpu_seconds * (kSerial + (1 - kSerial) / e.threads);
  e.peak_bytes = base_bytes + kBytesPerCf * e.cfs + kBytesPerFailedTry * failed_tries;
  if (std::getenv("CF_ESTIMATE_DEBUG"))
    for (const LevelEstimate& l : e.levels)
      std::fprintf(stderr,
                   "CAL level candidates %g orbits %g valid %g tasks %g cpu %g sampled %zu\n",
                   l.candidates, l.orbits, l.valid, l.tasks, l.cpu_seconds, l.sampled);
  if (std::getenv("CF_ESTIMATE_DEBUG"))
    std::fprintf(stderr,
                 "CAL level_cpu %g found %g failed %g search_s %g base %g explore_s %g explored %g "
                 "failed_tries %g after_motion %g\n",
                 level_cpu, found, failed, search_seconds, base_bytes, explore_s, explored,
                 failed_tries, after_motion);
  e.sample_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return e;
}

}  // namespace cf::gen::internal

// A run predicted without running it (enumerate.hpp, RunEstimate): the level-1 candidates
// counted, a few sets of each level decided on this machine, and the levels' sizes and the
// run's cost extrapolated from them (docs/generator.md, "Estimates").
//
// Level 1's candidates and orbits are counted exactly. Its sample gives the fraction valid
// and the cost of a search. The valid single PCs the sample found (with their images) stand
// for all of them: the pairs the necessary conditions allow among them, scaled to the
// predicted number of valid singles, give level 2's candidates; a sample of those pairs,
// decided, gives its fraction valid and cost. Level 3 the same way from the valid pairs
// found. What follows the levels (motion, neighbour rounds, records, transitions) is not
// sampled: its cost is taken in proportion to the orbits the levels search and the CFs they
// find, with constants measured on the pairs in docs/performance.md.

#include "cfgen/enumerate/enumerator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include <sys/resource.h>
#include <time.h>

namespace cf::gen::internal {
namespace {

// Sets decided per level: enough for the fraction valid to about +-15% (binomial at 32), a
// second or two on the slowest pairs measured.
constexpr std::size_t kSamples = 32;
// Sets whose partners are counted to predict the next level's candidates.
constexpr std::size_t kRows = 256;
// Batches of kSamples triples whose unknown pairs are decided, at most, to find level-3
// candidates to sample.
constexpr std::size_t kTripleRounds = 4;

// Constants that turn the levels into a run, fitted (least worst ratio) on the bundled pairs
// and the n-gon pegs and holes n = 3..9 at one thread; docs/performance.md ("Estimates")
// gives the errors that remain.
//
// CFs found after the levels (motion and neighbour rounds), per CF the levels find.
constexpr double kGrowth = 0.35;
// CPU time after the levels (motion, neighbour rounds), per orbit the levels search, in
// searches of the sample's mean cost.
constexpr double kRestPerOrbit = 28.5;
// CPU time per CF for what is done per member, not per orbit (images verified, records,
// transitions).
constexpr double kSecondsPerCf = 300e-6;
// Of a run's time on one thread, the part that runs on one thread whatever the count (a
// hexagonal pair's run at two threads used 1.2-1.3 of them).
constexpr double kSerial = 0.4;
// Transitions per CF: 15.5-25 on the pairs measured.
constexpr double kTransitionsPerCf = 18;
// Resident bytes per CF and per transition at the run's peak (records, the search's sets,
// the transitions built and sorted): 1.3-1.8 kB per CF in all on the n-gon pairs.
constexpr double kBytesPerCf = 1200;
constexpr double kBytesPerTransition = 24;

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
  std::size_t decided = 0, found = 0;
  double inv_orbit = 0;  // mean of 1 / orbit size over the sets decided
  double tries = 1;      // mean of min(kOrbitTries, orbit size) over the failed ones
  double t_found = 0;    // s of CPU, mean of a search that found a witness
  double t_failed = 0;   // s of CPU, mean of a search that did not
  double members = 0, found_members = 0;  // orbit sizes summed over the sets decided, the found
  double valid_fraction() const { return decided ? double(found) / double(decided) : 0; }
  double mean_seconds() const {
    return decided
               ? (double(found) * t_found + double(decided - found) * t_failed) / double(decided)
               : 0;
  }
};

// Decides up to `count` sets spread over `pool` (on the runner's threads, each timed), and
// accepts those found as the run would.
Enumerator::Sample Enumerator::sample_sets(int level, const std::vector<PcSet>& pool,
                                           const SeedsOf& seeds_of, std::size_t count) {
  const std::vector<std::size_t> idx = spread(pool.size(), count);
  std::vector<Task> tasks(idx.size());
  for (std::size_t k = 0; k < idx.size(); ++k) {
    tasks[k].pcs = pool[idx[k]];
    tasks[k].seeds = seeds_of(tasks[k].pcs);
  }
  std::vector<TaskResult> res(tasks.size());
  std::vector<double> sec(tasks.size());
  runner_.for_each(tasks.size(), [&](std::size_t k) {
    const double c0 = thread_cpu_seconds();
    res[k] = decide(search_, tasks[k]);
    sec[k] = thread_cpu_seconds() - c0;
  });
  Sample s;
  double tries = 0;
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    std::vector<PcSet> images;
    for (std::size_t g = 0; g < sym_.size(); ++g) images.push_back(sym_.image(tasks[k].pcs, g));
    std::sort(images.begin(), images.end(), pcset_less);
    const auto size = double(std::unique(images.begin(), images.end()) - images.begin());
    ++s.decided;
    s.inv_orbit += 1 / size;
    s.members += size;
    if (res[k].witness.found) s.found_members += size;
    if (res[k].witness.found) {
      ++s.found;
      s.t_found += sec[k];
      // Its images taken as valid without verifying them (accept() verifies each): an
      // estimate needs to know which sets are valid, not to prove it.
      for (std::size_t g = 0; g < sym_.size(); ++g) {
        const PcSet t = sym_.image(tasks[k].pcs, g);
        if (witness_rot_.count(t)) continue;
        Witness v = res[k].witness;
        v.pose = sym_.image(v.pose, g);
        witness_rot_.emplace(t, v.pose.R_BA);
        valid_[level].push_back({t, v});
      }
    } else {
      s.t_failed += sec[k];
      tries += std::min(double(kOrbitTries), size);
    }
  }
  const std::size_t failed = s.decided - s.found;
  if (s.decided) s.inv_orbit /= double(s.decided);
  if (s.found) s.t_found /= double(s.found);
  if (failed) s.t_failed /= double(failed), s.tries = tries / double(failed);
  return s;
}

// Pairs of the valid single PCs known that the necessary conditions allow: those of up to
// kRows of them, each with every other. mean_degree: the partners a single PC has among them.
std::vector<PcSet> Enumerator::pair_pool(double& mean_degree) {
  const auto& w = valid_[0];
  const std::vector<std::size_t> rows = spread(w.size(), kRows);
  std::vector<std::vector<PcSet>> found(rows.size());
  runner_.for_each(rows.size(), [&](std::size_t r) {
    const Pc& y = w[rows[r]].first[0];
    for (std::size_t i = 0; i < w.size(); ++i) {
      const Pc& x = w[i].first[0];
      if (i == rows[r] || !pair_ok_.compatible(x, y)) continue;
      PcSet s({x, y});
      if (search_.plausible(s)) found[r].push_back(s);
    }
  });
  std::vector<PcSet> pool;
  for (const auto& f : found) pool.insert(pool.end(), f.begin(), f.end());
  mean_degree = rows.empty() ? 0 : double(pool.size()) / double(rows.size());
  std::sort(pool.begin(), pool.end(), pcset_less);
  pool.erase(std::unique(pool.begin(), pool.end()), pool.end());
  return pool;
}

// Triples over up to kRows of the valid pairs known, each with every valid single PC known
// that the necessary conditions allow with both of its PCs (spread over the pairs).
// mean_thirds: such third PCs per pair.
std::vector<PcSet> Enumerator::triple_pool(double& mean_thirds) {
  const auto& w = valid_[0];
  const std::vector<std::size_t> rows = spread(valid_[1].size(), kRows);
  std::vector<std::vector<PcSet>> found(rows.size());
  runner_.for_each(rows.size(), [&](std::size_t r) {
    const PcSet& p = valid_[1][rows[r]].first;
    for (const auto& [single, witness] : w) {
      const Pc& z = single[0];
      if (p.contains(z) || !pair_ok_.compatible(p[0], z) || !pair_ok_.compatible(p[1], z)) continue;
      PcSet t = p;
      t.insert(z);
      if (search_.plausible(t)) found[r].push_back(t);
    }
  });
  std::vector<PcSet> pool;
  for (const auto& f : found) pool.insert(pool.end(), f.begin(), f.end());
  mean_thirds = rows.empty() ? 0 : double(pool.size()) / double(rows.size());
  // In an order that favours no pair and no third PC (each pair's thirds come in the order
  // of the valid singles, by type): shuffled with a fixed seed.
  std::mt19937_64 rng(0x5eed);
  std::shuffle(pool.begin(), pool.end(), rng);
  return pool;
}

// Of the triples in `pool` (one pair of each known valid), those whose other pairs are valid
// too, as the run's level-3 candidates are: the unknown pairs decided, kSamples triples at a
// time, until kSamples such triples are found or kTripleRounds have been tried. `fraction`:
// the share of the triples tried whose pairs are all valid.
std::vector<PcSet> Enumerator::triples_with_valid_pairs(const std::vector<PcSet>& pool,
                                                        double& fraction) {
  std::vector<PcSet> out;
  PcSetSet invalid;
  std::size_t tried = 0;
  for (std::size_t b = 0; b < pool.size() && b < kTripleRounds * kSamples && out.size() < kSamples;
       b += kSamples) {
    const std::size_t e = std::min(pool.size(), b + kSamples);
    std::vector<PcSet> unknown;
    for (std::size_t i = b; i < e; ++i)
      for (int k = 0; k < 3; ++k) {
        PcSet pair;
        for (int j = 0; j < 3; ++j)
          if (j != k) pair.insert(pool[i][j]);
        if (!witness_rot_.count(pair) && !invalid.count(pair)) unknown.push_back(pair);
      }
    std::sort(unknown.begin(), unknown.end(), pcset_less);
    unknown.erase(std::unique(unknown.begin(), unknown.end()), unknown.end());
    sample_sets(
        1, unknown, [this](const PcSet& x) { return seeds_from_subsets(x); }, unknown.size());
    for (const PcSet& pair : unknown)
      if (!witness_rot_.count(pair)) invalid.insert(pair);
    for (std::size_t i = b; i < e; ++i) {
      ++tried;
      bool all = true;
      for (int k = 0; k < 3 && all; ++k) {
        PcSet pair;
        for (int j = 0; j < 3; ++j)
          if (j != k) pair.insert(pool[i][j]);
        all = witness_rot_.count(pair) > 0;
      }
      if (all) out.push_back(pool[i]);
    }
  }
  fraction = tried ? double(out.size()) / double(tried) : 0;
  return out;
}

namespace {

// A level's searches and cost from its candidates and its sample: one search per orbit, a
// failed orbit searched again at up to kOrbitTries members.
template <class Sample>
void extrapolate(LevelEstimate& l, const Sample& s) {
  const double q = s.valid_fraction();
  l.sampled = s.decided;
  if (!l.exact) l.orbits = l.candidates * s.inv_orbit;
  l.valid = l.candidates * q;
  l.tasks = l.orbits * (q + (1 - q) * s.tries);
  l.cpu_seconds = l.orbits * (q * s.t_found + (1 - q) * s.tries * s.t_failed);
}

}  // namespace

RunEstimate Enumerator::estimate(int threads) {
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
      0, firsts, [](const PcSet&) { return std::vector<Mat3>{}; }, kSamples);
  extrapolate(l1, s1);
  if (s1.members > 0) l1.valid = l1.candidates * s1.found_members / s1.members;
  double searches = s1.mean_seconds() * double(s1.decided), decided = double(s1.decided);
  if (opt_.max_pcs >= 2 && !valid_[0].empty()) {
    // The valid singles known stand for l1.valid of them: partners scale with their number.
    const double scale = l1.valid / double(valid_[0].size());
    double degree = 0;
    const std::vector<PcSet> pool2 = pair_pool(degree);
    LevelEstimate& l2 = e.levels[1];
    l2.candidates = l1.valid * degree * scale / 2;
    const Sample s2 = sample_sets(1, pool2, subsets, kSamples);
    extrapolate(l2, s2);
    searches += s2.mean_seconds() * double(s2.decided), decided += double(s2.decided);
    if (opt_.max_pcs >= 3 && !valid_[1].empty() && l2.candidates > 0) {
      double thirds = 0, all_valid = 0;
      const std::vector<PcSet> pool3 = triples_with_valid_pairs(triple_pool(thirds), all_valid);
      // A third PC makes a candidate when both of its new pairs are valid.
      LevelEstimate& l3 = e.levels[2];
      l3.candidates = l2.valid * thirds * scale * all_valid / 3;
      const Sample s3 = sample_sets(2, pool3, subsets, kSamples);
      extrapolate(l3, s3);
      searches += s3.mean_seconds() * double(s3.decided), decided += double(s3.decided);
    }
  }
  double level_cpu = 0, orbits = 0, found = 0;
  for (const LevelEstimate& l : e.levels) {
    level_cpu += l.cpu_seconds;
    orbits += l.orbits;
    found += l.valid;
  }
  const double mean_search = decided > 0 ? searches / decided : 0;
  e.cfs = found * (1 + kGrowth);
  e.transitions = e.cfs * kTransitionsPerCf;
  e.cpu_seconds = level_cpu + kRestPerOrbit * orbits * mean_search + kSecondsPerCf * e.cfs;
  e.seconds = e.cpu_seconds * (kSerial + (1 - kSerial) / e.threads);
  e.peak_bytes = base_bytes + kBytesPerCf * e.cfs + kBytesPerTransition * e.transitions;
  e.sample_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return e;
}

}  // namespace cf::gen::internal

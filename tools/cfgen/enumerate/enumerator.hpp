#pragma once
// The enumeration's state and its steps (private to cfgen/enumerate): one object a run, its
// steps in levels.cpp (the candidate levels), motion.cpp (closure by motion), neighbours.cpp
// (neighbour rounds), finish.cpp (orbit closure, proofs, records) and enumerate.cpp (the
// order of the steps).

#include "cfgen/decide/pair_conditions.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/enumerate/symmetry.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace cf::gen::internal {

// Members of an orbit searched before it counts as failed: each meets the search's fixed
// samples differently. On the hexagonal peg and hole 2 find 13 orbits more than 1 (4 no more
// than 2); on the square pair 4 find 2 more than 2.
constexpr std::size_t kOrbitTries = 4;
// Witnesses explored by motion per orbit a round adds (motion.cpp): the one found, and those
// found by their own searches for up to three more members, spread over the orbit. Motion
// from one witness reaches what its place in the CF's region allows; the images of that
// witness reach the images of the same. On the hexagonal pair 4 find 13 orbits more than 1
// at 17% more time, 16 one more than 4.
constexpr std::size_t kWitnessesPerOrbit = 4;
// seen_'s value for a set searched with every subset's witness, or met outside the levels.
constexpr std::uint8_t kAllSeeds = 0xff;

struct PcSetHash {
  std::size_t operator()(const PcSet& s) const { return s.hash(); }
};
using PcSetSet = std::unordered_set<PcSet, PcSetHash>;
template <class T>
using PcSetMap = std::unordered_map<PcSet, T, PcSetHash>;

/// s without its PC at position k: a subset one PC smaller.
inline PcSet without(const PcSet& s, int k) {
  PcSet out;
  for (int j = 0; j < s.size(); ++j)
    if (j != k) out.insert(s[j]);
  return out;
}

// Candidate sets grouped by orbit: orbit o is members[first[o], first[o + 1]).
struct OrbitGroups {
  std::vector<PcSet> members;
  std::vector<std::size_t> first;
  std::size_t size() const { return first.empty() ? 0 : first.size() - 1; }
  std::size_t count(std::size_t o) const { return first[o + 1] - first[o]; }
  const PcSet& member(std::size_t o, std::size_t k) const { return members[first[o] + k]; }
};

/// The necessary conditions on pairs of PCs that the enumeration applies with `search`.
PairConditions pair_conditions_for(const WitnessSearch& search);

using SeedsOf = std::function<std::vector<Mat3>(const PcSet&)>;

class Enumerator {
 public:
  Enumerator(const WitnessSearch& search, const EnumerateOptions& opt, StageRunner& runner);
  Enumeration run();
  /// The run's size and cost predicted from samples (estimate.cpp); the enumerator is spent.
  RunEstimate estimate(int threads, std::size_t samples);

 private:
  // levels.cpp
  void accept(int level, const PcSet& s, const Witness& w);
  void prefetch_images(const std::vector<std::pair<PcSet, Pose>>& found);
  void prefetch_found(const std::vector<Task>& tasks, const std::vector<TaskResult>& results);
  OrbitGroups orbits_of(std::vector<PcSet> cands) const;
  void run_level(int level, std::vector<PcSet> all, const SeedsOf& seeds_of);
  std::size_t search_orbits(int level, const OrbitGroups& orbits, const SeedsOf& seeds_of,
                            std::vector<char>& done, ProgressEvent& ev, Clock::time_point t0);
  std::size_t search_rest(int level, const OrbitGroups& orbits, const SeedsOf& seeds_of,
                          const std::vector<char>& done, Clock::time_point t0);
  void singles_level();
  std::vector<PcSet> single_candidates() const;
  std::vector<Mat3> seeds_from_subsets(const PcSet& s) const;
  int valid_subsets(const PcSet& s) const;
  void update_open_singles();
  bool admit_open_singles();
  void retry_if_seeded(const PcSet& s, std::vector<PcSet>& cands);
  void note_seeds(const std::vector<PcSet>& cands);
  void mark_searched(const PcSet& s);
  std::vector<PcSet> build_pairs();
  void pairs_level();
  void triples_level();
  bool conditions_hold(const PcSet& t) const;
  // estimate.cpp
  struct Sample;
  void take_unverified(int level, const PcSet& s, const Witness& w);
  Sample sample_sets(int level, const std::vector<PcSet>& pool, const SeedsOf& seeds_of,
                     std::size_t count, std::size_t tries);
  std::vector<PcSet> grown_sets(int level, const std::vector<PcSet>& singles, double& mean_added);
  std::vector<PcSet> with_candidate_subsets(const std::vector<PcSet>& pool, double& fraction);
  double explore_seconds(std::size_t count, std::vector<Discovery>& singles);
  struct PairSample {
    std::size_t singles = 0;  // motion-only single PCs sampled
    std::size_t searched = 0;
    double seconds = 0;  // s of CPU, mean a search took
    double found = 0;    // share of the pairs found valid
    // Of the valid single PCs known (the samples', with their images), the share a
    // motion-only single makes a candidate pair with, on the mean over those sampled.
    double partner_share = 0;
  };
  PairSample motion_single_pairs(const std::vector<Discovery>& met, std::size_t count);
  double after_motion_seconds(const RunEstimate& e, const std::vector<Discovery>& met);
  // motion.cpp
  void motion_closure();
  void more_witnesses(Clock::time_point t0);
  void explore_frontier(Clock::time_point t0);
  std::size_t search_met(const std::vector<Discovery>& met, Clock::time_point t0);
  // neighbours.cpp
  void know_neighbours(const std::vector<Pc>& pcs);
  template <class R>
  using ChangeFn = std::function<R(const PcSet& n, int k, const Pc& q)>;
  void changes_of(const PcSet& s, const ChangeFn<void>& fn) const;
  bool any_change(const PcSet& s, const ChangeFn<bool>& pred) const;
  enum class Near { kNever, kNotYet, kYes };
  // What the screening of a set learned that stays true (neighbours.cpp).
  struct NearState {
    bool checked = false;       // valid_change was worked out against every CF at the time
    bool valid_change = false;  // a set one change away is valid
  };
  // A change of a CF still worth screening: its PC at position k replaced by q.
  struct NearChange {
    Pc q;
    std::uint8_t k = 0;
    NearState st;
  };
  struct Kept {
    PcSet set;
    PcSet orbit;
  };
  Near near_candidate(const PcSet& s, NearState& st, const PcSetMap<std::vector<Pc>>& new_by_rest,
                      PcSet& orbit) const;
  Near near_unsearched(const PcSet& s, NearState& st, const PcSetMap<std::vector<Pc>>& new_by_rest,
                       PcSet& orbit) const;
  PcSetMap<std::vector<Pc>> new_cfs_by_rest() const;
  bool valid_change_among(const PcSet& s, const PcSetMap<std::vector<Pc>>& new_by_rest) const;
  void screen_failed(std::size_t i, const PcSetMap<std::vector<Pc>>& new_by_rest,
                     std::vector<Kept>& kept);
  void index_cfs_by_pc();
  using CoverFn = std::function<bool(const PcSet& t, const Mat3& R_witness)>;
  bool any_covering_cf(const PcSet& s, const std::size_t (&since)[3], const CoverFn& fn) const;
  void screen_cf(int level, std::size_t i, const PcSetMap<std::vector<Pc>>& new_by_rest,
                 std::vector<Kept>& kept);
  // A neighbour round's tasks as its screening takes them (neighbours.cpp).
  struct RoundTake {
    std::vector<Task> tasks;
    PcSetSet searched;  // the sets of `tasks`
    PcSetSet orbits;    // their orbits
  };
  void take_near(const PcSet& s, const PcSet& orbit, RoundTake& round) const;
  std::vector<Task> neighbour_tasks();
  std::size_t neighbour_round();
  void release_neighbour_rounds();
  // finish.cpp
  void close_orbits();
  void find_undecided();
  void decide_over_cells(std::vector<char>& state,
                         std::vector<std::pair<std::size_t, Witness>>& found,
                         std::vector<SetDecision>& decisions);
  std::vector<std::pair<PcSet, Witness>> find_thin(const std::vector<PcSet>& open);
  SetDecision certified(const PcSet& s, const RuleVerdict& rule, CellSearchLimits limits) const;
  void add_with_images(const PcSet& s, const Witness& w, PcSetSet& known);
  void build_records();
  void finished(ProgressEvent& ev, Clock::time_point t0, const std::string& result);

  const WitnessSearch& search_;
  const Polyhedron& A_;
  const Polyhedron& B_;
  const EnumerateOptions& opt_;
  StageRunner& runner_;
  // The models' symmetries: a valid set's images are valid, at the image of its witness.
  const PairSymmetries sym_;
  // The necessary conditions on pairs of PCs (pair_conditions.hpp).
  const PairConditions pair_ok_;

  Enumeration out_;
  std::vector<std::pair<PcSet, Witness>> valid_[3];
  std::vector<PcSet> failed_;  // candidates the search found no witness for
  // Every set that reached the witness search or was found valid, with how many of its
  // subsets one PC smaller were valid when it was searched (kAllSeeds: all of them, or a set
  // met outside the levels): nothing is searched twice with the same seeds.
  PcSetMap<std::uint8_t> seen_;
  PcSetMap<Mat3> witness_rot_;                    // seeds for the sets above them
  std::vector<std::pair<PcSet, Pose>> frontier_;  // valid sets not explored by motion yet
  // Contact sets the levels' failed searches met where their contacts were placed (TaskResult::
  // met of kFind), for motion_closure.
  std::vector<Discovery> forced_;
  // The single PCs pairs are built from, valid or open (update_open_singles), in the order met,
  // with each one's index; singles_[0, singles_paired_) have been paired.
  std::vector<Pc> singles_;
  std::map<Pc, std::size_t> single_at_;
  std::size_t singles_paired_ = 0;
  // The rule (refuted_by) of each failed single PC, by index in failed_, worked out for
  // failed_[0, failed_classified_).
  std::unordered_map<std::size_t, RuleVerdict> failed_rule_;
  std::size_t failed_classified_ = 0;
  // The failed single PCs no rule refutes, and whether they are paired yet.
  std::vector<Pc> open_singles_;
  bool open_admitted_ = false;
  // This level's candidates with fewer valid subsets one PC smaller than all, with how many;
  // those it searches again (already in failed_).
  PcSetMap<std::uint8_t> level_seeds_;
  PcSetSet retrying_;
  std::size_t singles_valid_ = 0;  // valid single PCs when the pairs were last built
  std::size_t pairs_tripled_ = 0;  // valid pairs when the triples were last built
  int motion_rounds_ = 0;
  int neighbour_rounds_ = 0;
  // The neighbour rounds' memory: members searched so far, tries per orbit, PC neighbours.
  PcSetSet near_searched_;
  PcSetMap<std::size_t> near_tries_;
  // Marks, by index in failed_ and valid_: nothing the set screens can be worth a neighbour
  // search any more (screen()).
  std::vector<char> failed_dead_;
  std::vector<char> cf_dead_[3];
  // What the screening learned of each failed set, and the changes of each CF that are
  // still worth screening (in the order first screened; 16 bytes each, the orbits worked
  // out again each round, as a large pair has millions); the CFs screened at least once; how
  // many CFs of each level the last round's screening saw.
  std::vector<NearState> failed_near_;
  std::vector<std::vector<NearChange>> cf_near_[3];
  std::vector<char> cf_screened_[3];
  std::size_t near_screened_cfs_[3] = {0, 0, 0};
  bool near_screened_none_ = true;  // this round's new_cfs_by_rest() holds every CF
  std::map<Pc, std::vector<Pc>> pc_neighbours_;
  // The CFs by PC, each entry its level (top two bits) and index in valid_, extended at the
  // start of each round; the CFs of each level that the round's screening counts as old.
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cfs_by_pc_;  // by pc_key
  std::size_t by_pc_indexed_[3] = {0, 0, 0};
  std::size_t near_since_[3] = {0, 0, 0};
  // The images' witnesses of the sets about to be accepted, by set, with the witness pose
  // they were computed from (prefetch_images); cleared after each batch.
  PcSetMap<std::pair<Pose, std::vector<Witness>>> prefetched_;
  // The estimate's sets searched and not found, each with whether it is an open single PC:
  // no rule refutes it (estimate.cpp).
  PcSetMap<bool> known_failed_;
  std::size_t samples_ = kEstimateSamples;  // estimate(): orbits searched per level
};

}  // namespace cf::gen::internal

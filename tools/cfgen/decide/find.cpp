// WitnessSearch::find (witness.hpp): the stages of the search for one candidate set, each
// tried when the ones before it found no witness. One FindRun per call holds what the stages
// share: the best witness so far, the rotations where the contacts held, the poses blocked by
// another pair of elements, and the pairs recent poses failed on.

#include "cfgen/decide/rotation_family.hpp"
#include "cfgen/decide/witness.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace cf::gen::internal {

class FindRun {
 public:
  FindRun(const WitnessSearch& s, const PcSet& pcs, const std::vector<Mat3>& seeds, bool seeds_only)
      : s_(s),
        p_(s.params()),
        pcs_(pcs),
        seeds_(seeds),
        seeds_only_(seeds_only),
        slot_sizes_(s.piece_slots(pcs)) {}
  Witness run();
  /// The poses the last stage climbs from (Blocked) whose obstacle touches, in the order met.
  std::vector<Pose> blocked_poses() const {
    std::vector<Pose> out;
    for (const Blocked& b : blocked_)
      if (const Pose pose{b.R, b.t}; s_.obstacle_touches(pose, b.obstacle)) out.push_back(pose);
    return out;
  }

 private:
  using FailedPair = Verifier::FailedPair;
  using Obstacle = Verifier::Obstacle;
  // A pose where the contacts held and the centred translation met another pair of elements.
  struct Blocked {
    Mat3 R;
    std::vector<int> pieces;
    Vec3 t;
    Obstacle obstacle;
  };
  using Score = std::pair<int, double>;

  void remember(const FailedPair& f);
  double verify_remembering(const Pose& pose, std::string* why, FailedPair& f);
  double verify_unless_failing(const Pose& pose);
  bool cut_obstacles(const Mat3& R, const std::vector<int>& choice, Vec3 t, Obstacle obstacle);
  bool try_rotation(const Mat3& R);
  int try_pass(const Mat3& R, const std::vector<int>& choice, int pass,
               WitnessSearch::TranslationMemo& memo);
  bool try_all(const std::vector<Mat3>& rots);
  Witness past_obstacles();
  bool climb_past(const Blocked& b);
  Score score(const Mat3& R) const;
  std::vector<std::pair<Score, Mat3>> climb_starts(const std::vector<Mat3>& rots) const;
  int climb(Mat3& R, Score& m, const std::function<Score(const Mat3&)>& score_of,
            const std::function<bool(const Score&)>& done, double first_step, double last_step,
            int max_evals) const;
  bool climb_margin(const std::vector<Mat3>& rots);
  bool climb_local(const Mat3& start);
  std::vector<Mat3> family_ends() const;
  std::vector<Mat3> consistent_rotations(const std::vector<Mat3>& rots) const;

  const WitnessSearch& s_;
  const SearchParams& p_;
  const PcSet& pcs_;
  const std::vector<Mat3>& seeds_;
  const bool seeds_only_;
  // Face-piece slots, in the order solve_translation consumes them.
  const std::vector<int> slot_sizes_;
  const double min_local_ = std::sin(p_.angle_margin);
  Witness best_;
  std::vector<Mat3> near_;  // rotations where the contacts held but the pose failed
  std::vector<Blocked> blocked_;
  // The pairs recent poses failed on, newest first. A pose whose verdict matters only if it
  // is a witness (every translation but the first of a rotation's pass or of a cut, whose
  // obstacle steers the cuts and the skipping of the pass's other translations) is refused
  // without a verification when one of them still fails there: most poses of a set that has
  // no witness fail on a pair met before.
  static constexpr std::size_t kRecent = 8;
  std::array<FailedPair, kRecent> recent_{};
};

void FindRun::remember(const FailedPair& f) {
  if (f.kind == FailedPair::Kind::kNone) return;
  auto same = [&](const FailedPair& g) {
    return g.kind == f.kind && g.ka == f.ka && g.kb == f.kb && g.a == f.a && g.b == f.b;
  };
  auto it = std::find_if(recent_.begin(), recent_.end(), same);
  if (it == recent_.end()) it = recent_.end() - 1;
  std::rotate(recent_.begin(), it, it + 1);
  recent_.front() = f;
}

// verify, keeping the pair the pose failed on (in f) among the recent ones.
double FindRun::verify_remembering(const Pose& pose, std::string* why, FailedPair& f) {
  const double clearance = s_.verify(pcs_, pose, why, &f);
  remember(f);
  return clearance;
}

// verify for a pose only a witness would change anything at: -1 when a recent pair proves it
// fails.
double FindRun::verify_unless_failing(const Pose& pose) {
  for (const FailedPair& f : recent_) {
    if (f.kind == FailedPair::Kind::kNone) break;
    if (s_.still_fails(pcs_, pose, f)) return -1.0;
  }
  FailedPair f;
  return verify_remembering(pose, nullptr, f);
}

// The contacts were placed but the centred translation ran into another pair of elements:
// move away from it (a half-space of translations where the pair is apart) and place the
// contacts again, a few obstacles deep. Returns true when a good witness was found.
bool FindRun::cut_obstacles(const Mat3& R, const std::vector<int>& choice, Vec3 t,
                            Obstacle obstacle) {
  constexpr int kMaxCuts = 4;  // obstacles avoided in turn before giving up on a rotation
  std::vector<LinearProgram::Row> cuts;
  for (int k = 0; k < kMaxCuts && obstacle.set; ++k) {
    LinearProgram::Row cut;
    if (!s_.separating_cut(R, t, obstacle, cut)) return false;
    cuts.push_back(cut);
    double margin = 0;
    const std::vector<Vec3> ts = s_.translations(pcs_, R, choice, margin, false, cuts);
    if (s_.debug_)
      std::cerr << "  cut " << k + 1 << ": " << ts.size() << " translations, margin " << margin
                << "\n";
    if (ts.empty()) return false;
    obstacle = Obstacle();
    for (const Vec3& tt : ts) {
      Pose pose;
      pose.R_BA = R;
      pose.t_BA = tt;
      double clearance = -1;
      if (&tt == &ts.front()) {
        FailedPair f;
        std::string why;
        clearance = verify_remembering(pose, s_.debug_ ? &why : nullptr, f);
        if (s_.debug_)
          std::cerr << "    t " << tt.transpose() << " clearance " << clearance << " " << why
                    << "\n";
        obstacle = f.obstacle();
        t = tt;
      } else {
        if (s_.still_blocked(pcs_, pose, obstacle)) continue;
        clearance = verify_unless_failing(pose);
      }
      if (clearance >= p_.min_clearance && clearance > best_.clearance) {
        best_.found = true;
        best_.pose = pose;
        best_.clearance = clearance;
        best_.margin = margin;
        return clearance >= p_.good_clearance;
      }
    }
  }
  return false;
}

// One pass of a rotation and a choice of pieces. Pass 0: centred translations; pass 1:
// translations close to the elements' boundaries. Returns 1 when a good witness was found,
// -1 when the rotation's passes end here (nothing placed, or a witness found), 0 to go on.
int FindRun::try_pass(const Mat3& R, const std::vector<int>& choice, int pass,
                      WitnessSearch::TranslationMemo& memo) {
  constexpr std::size_t kMaxBlocked = 4;  // blocked poses the last stage climbs from
  double margin = 0;
  const std::vector<Vec3> ts = s_.translations(pcs_, R, choice, margin, pass == 1, {}, &memo);
  if (pass == 0 && !ts.empty() && near_.size() < 4) near_.push_back(R);
  if (s_.debug_)
    std::cerr << "  rotation, pass " << pass << ": " << ts.size() << " translations, margin "
              << margin << "\n";
  Obstacle first_obstacle;
  for (const Vec3& t : ts) {
    Pose pose;
    pose.R_BA = R;
    pose.t_BA = t;
    // Nearby translations are often blocked by the same pair: one distance decides.
    if (&t != &ts.front() && s_.still_blocked(pcs_, pose, first_obstacle)) continue;
    std::string why;
    double clearance = -1;
    if (&t == &ts.front() || s_.debug_) {
      FailedPair f;
      clearance = verify_remembering(pose, s_.debug_ ? &why : nullptr, f);
      if (&t == &ts.front()) first_obstacle = f.obstacle();
    } else {
      clearance = verify_unless_failing(pose);
    }
    if (s_.debug_)
      std::cerr << "    t " << t.transpose() << " clearance " << clearance << " " << why << "\n";
    if (clearance >= p_.min_clearance && clearance > best_.clearance) {
      best_.found = true;
      best_.pose = pose;
      best_.clearance = clearance;
      best_.margin = margin;
      if (clearance >= p_.good_clearance) return 1;
    }
    if (clearance >= p_.min_clearance) break;  // a witness for this rotation; try others
  }
  if (ts.empty() || best_.found) return -1;
  if (pass == 0 && first_obstacle.set && blocked_.size() < kMaxBlocked)
    blocked_.push_back({R, choice, ts.front(), first_obstacle});
  if (pass == 0 && first_obstacle.set && cut_obstacles(R, choice, ts.front(), first_obstacle))
    return 1;
  return best_.found ? -1 : 0;
}

// Returns true when a good witness was found.
bool FindRun::try_rotation(const Mat3& R) {
  std::vector<int> choice(slot_sizes_.size(), 0);
  for (int combo = 0; combo < p_.max_piece_combinations; ++combo) {
    // Pass 1 only when pass 0 placed the contacts but found no witness.
    WitnessSearch::TranslationMemo memo;
    for (int pass = 0; pass < 2; ++pass) {
      const int r = try_pass(R, choice, pass, memo);
      if (r == 1) return true;
      if (r == -1) break;
    }
    // Next combination of pieces (odometer); stop when all tried.
    std::size_t i = 0;
    while (i < choice.size() && ++choice[i] == slot_sizes_[i]) choice[i++] = 0;
    if (i == choice.size()) break;
  }
  return false;
}

// try_rotation on each; true when a good witness was found.
bool FindRun::try_all(const std::vector<Mat3>& rots) {
  for (const Mat3& R : rots)
    if (try_rotation(R)) return true;
  return false;
}

// Past the obstacles: a set whose contacts hold only in a thin range of orientations (a peg
// tilted across a hole's rim, its corner near the far wall) is blocked at every rotation
// sampled above, by pairs of elements that a small turn would clear. From each blocked pose,
// climb over the rotations the conditions leave free, with the translation chosen by a
// program that keeps the contacts inside their elements and pushes every obstacle met so far
// beyond its separating cut (obstacle_margin); where that margin reaches min_margin, try the
// program's translations, and when one meets a new pair, add it and climb on.
Witness FindRun::past_obstacles() {
  for (const Blocked& b : blocked_)
    if (climb_past(b)) return best_;
  return best_;
}

// The climb from one blocked pose; true when it found a witness.
bool FindRun::climb_past(const Blocked& b) {
  constexpr int kMaxObstacles = 8;      // pairs pushed apart at once
  constexpr int kMaxEvaluations = 160;  // programs solved per blocked pose
  constexpr double kFirstTurn = 0.02;   // rad, the largest turn about an axis
  constexpr double kLastTurn = 1e-3;    // rad
  std::vector<Obstacle> obstacles{b.obstacle};
  auto known = [&](const Obstacle& o) {
    return std::any_of(obstacles.begin(), obstacles.end(), [&](const Obstacle& x) {
      return x.ka == o.ka && x.kb == o.kb && x.a == o.a && x.b == o.b;
    });
  };
  Mat3 R = b.R;
  LpVector x, xq;
  std::vector<LinearProgram::Row> cuts, cq;
  std::vector<std::vector<Vec3>> cut_points, cpq;
  double m = s_.obstacle_margin(pcs_, R, b.pieces, obstacles, b.t, x, cuts, cut_points);
  if (!std::isfinite(m)) return false;
  double turn = kFirstTurn;
  // A climb that stalls after meeting new obstacles starts again from the blocked pose with
  // all of them: the first climbs turned without knowing them.
  std::size_t obstacles_at_start = 1;
  for (int evals = 1; evals < kMaxEvaluations;) {
    if (turn < kLastTurn && obstacles.size() > obstacles_at_start) {
      obstacles_at_start = obstacles.size();
      R = b.R;
      m = s_.obstacle_margin(pcs_, R, b.pieces, obstacles, b.t, x, cuts, cut_points);
      ++evals;
      if (!std::isfinite(m)) break;
      turn = kFirstTurn;
    }
    if (m >= p_.min_margin) {
      double margin = 0;
      const std::vector<Vec3> ts = s_.translations(pcs_, R, b.pieces, margin, false, cuts);
      if (s_.debug_)
        std::cerr << "  past obstacles: " << obstacles.size() << " cleared, " << ts.size()
                  << " translations\n";
      Obstacle next;
      for (const Vec3& tt : ts) {
        Pose pose;
        pose.R_BA = R;
        pose.t_BA = tt;
        FailedPair f;
        const double clearance = verify_remembering(pose, nullptr, f);
        if (&tt == &ts.front()) next = f.obstacle();
        if (clearance >= p_.min_clearance) {
          best_.found = true;
          best_.pose = pose;
          best_.clearance = clearance;
          best_.margin = margin;
          return true;
        }
      }
      if (!next.set || known(next) || static_cast<int>(obstacles.size()) >= kMaxObstacles) break;
      obstacles.push_back(next);
      const Vec3 t = x.head<3>();
      m = s_.obstacle_margin(pcs_, R, b.pieces, obstacles, t, x, cuts, cut_points);
      ++evals;
      if (!std::isfinite(m)) break;
      turn = kFirstTurn;
      continue;
    }
    if (turn < kLastTurn) break;
    // The step of the program linearised in the turn first; where it does not raise the
    // margin (at a kink of the smallest margin, or where a cut's best axis changes), the
    // turns about each axis the conditions leave free.
    std::vector<Mat3> tries;
    if (Mat3 Q; s_.obstacle_step(pcs_, R, b.pieces, x, cuts, cut_points, turn, Q))
      tries.push_back(Q);
    for (const Mat3& Q : s_.rotation_steps(pcs_, R, turn)) tries.push_back(Q);
    bool moved = false;
    for (const Mat3& Q : tries) {
      if (evals >= kMaxEvaluations) break;
      ++evals;
      if (s_.local_margin(pcs_, Q) <= min_local_) continue;
      const double mq = s_.obstacle_margin(pcs_, Q, b.pieces, obstacles, x.head<3>(), xq, cq, cpq);
      if (mq > m) {
        m = mq;
        R = Q;
        x = xq;
        cuts.swap(cq);
        cut_points.swap(cpq);
        moved = true;
        break;
      }
    }
    if (s_.debug_)
      std::cerr << "    turn " << turn << (moved ? " gained, margin " : " no gain, margin ") << m
                << "\n";
    turn = moved ? std::min(2 * turn, kFirstTurn) : 0.5 * turn;
  }
  if (s_.debug_) {
    std::cerr << "  past obstacles: margin " << m << " with " << obstacles.size() << " obstacles:";
    for (const Obstacle& o : obstacles)
      std::cerr << " " << kind_name(o.ka) << o.a << "-" << kind_name(o.kb) << o.b;
    std::cerr << "\n";
  }
  return false;
}

// Lexicographic: first the local non-penetration slack (a cosine) until it is positive, then
// the contacts' margin inside their elements (mm).
FindRun::Score FindRun::score(const Mat3& R) const {
  const double local = s_.local_margin(pcs_, R);
  if (local <= min_local_) return std::make_pair(0, local);
  return std::make_pair(1, s_.signed_margin(pcs_, R, std::vector<int>(slot_sizes_.size(), 0)));
}

// The rotations that come closest to placing the contacts, best first.
std::vector<std::pair<FindRun::Score, Mat3>> FindRun::climb_starts(
    const std::vector<Mat3>& rots) const {
  constexpr std::size_t kStarts = 2;  // closest rotations climbed from
  std::vector<std::pair<Score, Mat3>> starts;
  auto by_score = [](const auto& x, const auto& y) { return x.first > y.first; };
  for (const Mat3& R : rots) starts.push_back({score(R), R});
  std::stable_sort(starts.begin(), starts.end(), by_score);
  if (starts.size() > kStarts) starts.resize(kStarts);
  if (starts.size() < kStarts) {
    // Too few rotations hold locally: climb also from the locally penetrating ones that come
    // closest.
    std::vector<std::pair<Score, Mat3>> more;
    for (const Mat3& R :
         s_.family_samples(pcs_, s_.spread_rotations(pcs_, seeds_), p_.theta_samples)) {
      const double local = s_.local_margin(pcs_, R);
      if (local <= min_local_) more.push_back({{0, local}, R});
    }
    std::stable_sort(more.begin(), more.end(), by_score);
    for (std::size_t i = 0; i < more.size() && starts.size() < kStarts; ++i)
      starts.push_back(more[i]);
  }
  return starts;
}

// A pattern search over rotations: from R, scored m, the steps of +-h about each axis the
// rotational conditions leave free (rotation_steps), taking the first that raises the score,
// h halving after a round without one down to last_step; at most max_evals scores, or until
// done. R and m receive where it ended; returns the scores evaluated.
int FindRun::climb(Mat3& R, Score& m, const std::function<Score(const Mat3&)>& score_of,
                   const std::function<bool(const Score&)>& done, double first_step,
                   double last_step, int max_evals) const {
  double h = first_step;
  int evals = 0;
  while (evals < max_evals && h >= last_step && !done(m)) {
    bool moved = false;
    for (const Mat3& Q : s_.rotation_steps(pcs_, R, h)) {
      const Score mq = score_of(Q);
      ++evals;
      if (mq > m) {
        m = mq;
        R = Q;
        moved = true;
        break;
      }
    }
    if (!moved) h *= 0.5;
  }
  return evals;
}

// Where no rotation tried could place the contacts, climb the margin: from the rotations that
// came closest, step along the rotations the conditions leave free while the (possibly
// negative) margin grows, and try each rotation that reaches min_margin. Narrow CFs, e.g. a
// vertex of A reaching a riser of B while an edge of A lies on the tread, live in a small
// region of such rotations that a fixed sample misses. True when it found a witness.
bool FindRun::climb_margin(const std::vector<Mat3>& rots) {
  constexpr int kMaxSteps = 32;       // evaluations per climb
  constexpr double kFirstStep = 0.2;  // rad
  constexpr double kLastStep = 1e-2;  // rad
  const auto done = [&](const Score& m) { return m.first == 1 && m.second >= p_.min_margin; };
  for (auto [m, R] : climb_starts(rots)) {
    if (!std::isfinite(m.second)) continue;
    if (s_.debug_) std::cerr << "  climb from " << m.first << " / " << m.second << "\n";
    const int evals = climb(
        R, m, [&](const Mat3& Q) { return score(Q); }, done, kFirstStep, kLastStep, kMaxSteps);
    if (s_.debug_)
      std::cerr << "  climbed to " << m.first << " / " << m.second << " in " << evals
                << " evaluations\n";
    if (done(m) && try_rotation(R)) return true;
    if (best_.found) return true;
  }
  return false;
}

// Where no anchored rotation was locally admissible, climb from the nearest miss, a rotation
// that places the contacts with some PC locally penetrating by a little: first keep the
// contacts placed (their margin, while below min_margin), then raise the local margin, and
// try the rotation once it is admissible. Two vertices of a wedge on two walls of an L hold
// in a sliver of rotations a few hundredths of a radian across, beside such a miss. True
// when it found a witness.
bool FindRun::climb_local(const Mat3& start) {
  constexpr int kMaxSteps = 64;        // evaluations
  constexpr double kFirstStep = 0.05;  // rad: about the slivers' width
  constexpr double kLastStep = 1e-3;   // rad
  const std::vector<int> first_pieces(slot_sizes_.size(), 0);
  auto placed = [&](const Mat3& R) -> Score {
    const double m = s_.signed_margin(pcs_, R, first_pieces);
    if (m < p_.min_margin) return {0, m};
    return {1, s_.local_margin(pcs_, R)};
  };
  const auto done = [&](const Score& m) { return m.first == 1 && m.second > min_local_; };
  Mat3 R = start;
  Score m = placed(R);
  const int evals = climb(R, m, placed, done, kFirstStep, kLastStep, kMaxSteps);
  if (s_.debug_)
    std::cerr << "  local climb to " << m.first << " / " << m.second << " in " << evals
              << " evaluations\n";
  return done(m) && (try_rotation(R) || best_.found);
}

// A one-parameter family: a part leaning in a gap (a peg tilted in a hole, an edge resting on
// one wall and the rim on its face) holds in a narrow range of the parameter, a few
// hundredths of a radian wide, just inside the end of the range where its contacts are
// locally admissible. Walks the family from the rotations where the contacts held to each
// such end and returns the rotations just inside it. (Where the two conditions are one, e.g.
// an edge on a face and a face parallel to that edge on an edge parallel to that face, the
// rotations form a surface and the walk follows curves on it; it still finds such ends, not
// all of them.)
std::vector<Mat3> FindRun::family_ends() const {
  constexpr double kWalkStep = 0.03;  // rad
  constexpr int kWalkSteps = 60;      // up to 1.8 rad each way
  constexpr int kInside = 4;          // rotations tried inside each end, kWalkStep apart
  const RotConstraints c = rotation_constraints(pcs_, s_.a(), s_.b());
  std::vector<Mat3> ends;
  for (const Mat3& R : near_)
    for (const std::vector<Mat3>& path : walk_family(c, R, kWalkStep, kWalkSteps)) {
      std::size_t k = 0;
      while (k < path.size() && s_.local_margin(pcs_, path[k]) > min_local_) ++k;
      if (s_.debug_) std::cerr << "  walk: " << path.size() << " steps, end at " << k << "\n";
      if (k == path.size()) continue;  // no end within reach
      for (int i = 1; i <= kInside && static_cast<int>(k) - i >= 0; ++i)
        add_unique(ends, path[k - i]);
    }
  return ends;
}

// Where the PCs' planes are dependent at every rotation of the family (translation_residual:
// two parallel edges of A on two parallel faces of B, alone or with a third PC), the LP is
// infeasible except on a curve of rotations where the planes meet, which samples never hit.
// Projects the family's samples onto that curve, walks it from the first locally admissible ones,
// and returns along each walk the locally admissible rotation that places the contacts deepest,
// where that reaches min_margin.
std::vector<Mat3> FindRun::consistent_rotations(const std::vector<Mat3>& rots) const {
  constexpr std::size_t kStarts = 4;  // projected rotations walked from
  constexpr double kWalkStep = 0.01;  // rad: below the admissible arcs' width
  constexpr int kWalkSteps = 200;     // up to 2 rad each way
  const Polyhedron& A = *s_.a().model;
  const Polyhedron& B = *s_.b().model;
  std::vector<Mat3> out;
  const RotConstraints c = rotation_constraints(pcs_, s_.a(), s_.b());
  const double dependent = direction_tol(s_.a(), s_.b());
  // Whether the planes are dependent holds along the whole family: the rotations tried
  // already tell, before the samples are made again.
  if (!c.align.empty() ||
      (!rots.empty() && !translation_residual(A, B, pcs_, rots.front(), dependent)))
    return out;
  const std::vector<Mat3> samples =
      s_.family_samples(pcs_, s_.spread_rotations(pcs_, seeds_), p_.theta_samples);
  if (samples.empty() || !translation_residual(A, B, pcs_, samples.front(), dependent)) return out;
  std::vector<Mat3> starts;
  for (Mat3 R : samples)
    if (starts.size() < kStarts && project_consistent(A, B, pcs_, c, R, dependent) &&
        s_.local_margin(pcs_, R) > min_local_)
      add_unique(starts, R);
  const std::vector<int> first_pieces(slot_sizes_.size(), 0);
  for (const Mat3& R0 : starts)
    for (const std::vector<Mat3>& path :
         walk_consistent(A, B, pcs_, c, R0, kWalkStep, kWalkSteps, dependent)) {
      double best = p_.min_margin;
      std::optional<Mat3> best_R;
      for (const Mat3& R : path) {
        if (s_.local_margin(pcs_, R) <= min_local_) continue;
        const double m = s_.signed_margin(pcs_, R, first_pieces);
        if (m >= best) best = m, best_R = R;
      }
      if (best_R) add_unique(out, *best_R);
    }
  if (s_.debug_) std::cerr << "  " << out.size() << " rotations where the planes meet\n";
  return out;
}

Witness FindRun::run() {
  if (!s_.plausible(pcs_)) return best_;
  const std::vector<Mat3> rots = s_.rotation_candidates(pcs_, seeds_, !seeds_only_);
  if (s_.debug_) std::cerr << "find " << to_string(pcs_) << ": " << rots.size() << " rotations\n";
  if (try_all(rots) || best_.found) return best_;
  if (seeds_only_) {
    // The neighbours' witnesses are a few hundredths of a radian from where the set holds:
    // look that close around each, then climb past the obstacles met.
    if (try_all(s_.rotation_candidates(pcs_, turned_about_axes(seeds_, {0.01, 0.025}), false)) ||
        best_.found)
      return best_;
    return past_obstacles();
  }
  // Two point PCs: rotations built to place both contacts inside their elements, where the
  // spread above left too few locally admissible ones (two e-e crossings) or none that fits
  // (a peg's corner just inside a hole's rim).
  std::optional<Mat3> miss;
  if (try_all(s_.anchored_rotations(pcs_, &miss)) || best_.found) return best_;
  if (miss && climb_local(*miss)) return best_;
  if (near_.empty() && climb_margin(rots)) return best_;
  if (near_.empty() && (try_all(consistent_rotations(rots)) || best_.found)) return best_;
  if (best_.found || near_.empty()) return best_;
  // The contacts could be placed but the pose touched something else: look closer around
  // those rotations, where valid sets with a narrow range of orientations live.
  if (try_all(s_.rotation_candidates(pcs_, turned_about_axes(near_, {0.04, 0.12, 0.3}), false)) ||
      best_.found)
    return best_;
  if (try_all(family_ends()) || best_.found) return best_;
  return past_obstacles();
}

}  // namespace cf::gen::internal

namespace cf::gen {

Witness WitnessSearch::find(const PcSet& pcs, const std::vector<Mat3>& seeds, bool seeds_only,
                            std::vector<Pose>* blocked) const {
  internal::FindRun run(*this, pcs, seeds, seeds_only);
  const Witness w = run.run();
  if (blocked && !w.found) *blocked = run.blocked_poses();
  return w;
}

}  // namespace cf::gen

#pragma once
// Independent test oracle: a sampler of valid CFs by exact first contacts.
//
// Each round picks an orientation of A from a family (random; a face of A antiparallel to a
// face of B, spun about the normal; an edge of A parallel to a face of B with the face's
// normal inside the edge's normal cone; a face of A parallel to an edge of B likewise; those
// with a second condition solved in closed form on the spin angle; two or three such
// conditions solved by Gauss-Newton on SO(3)), places A free near a target element of B, and
// translates it along an approach direction to the exact first contact. From there a random
// walk of compliant motions (translations in the null space of the contact normals, rotations
// about axes through the contact points, along contacting edges or contact normals, and small
// hops) reaches further first contacts. Every reached pose is classified; it counts only when
// interiors are disjoint, every PC is one of the six non-degenerate types, there are 1-3 PCs
// on pairwise distinct planes, nothing is near-degenerate, and the clearance is above the
// gap tolerance. For each CF the pose with the largest clearance is kept.

#include "classify.hpp"
#include "motion.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <string>

namespace oracle {

struct SamplerOptions {
  double budget_s = 3.0;
  std::uint64_t seed = 1;
  int max_walk = 10;
  long max_rounds = 0;  // stop after this many rounds (0: only the time budget); with a budget
                        // that is not reached first, the run is deterministic for a seed
  // Called at every accepted pose (every pose that counts, not only each CF's best), with
  // its classification and how the sampler got there; it does not steer the sampler.
  std::function<void(const Pose&, const Verdict&, const std::string& how)> on_accept;
};

struct Sample {
  Pose pose;
  double clearance = 0;
  std::string how;  // orientation family and motion that reached it
};

struct SamplerStats {
  long rounds = 0, poses = 0, accepted = 0, penetrating = 0, free = 0, uncertain = 0,
       low_clearance = 0, degenerate = 0, too_many = 0, same_plane = 0;
  double seconds = 0;
  std::string str() const;
};

class Sampler {
 public:
  Sampler(const Classifier& C, SamplerOptions o);
  void run();
  const std::map<CfKey, Sample>& samples() const { return found_; }
  const SamplerStats& stats() const { return st_; }

 private:
  struct Target {
    int kind_b = 2, b = 0;  // element of B to approach
    int kind_a = 2, a = 0;  // element of A that should meet it
  };
  bool orientation(Mat3* R, Target* T, std::string* fam);
  bool approach(const Mat3& R, const Target& T, Pose* out);
  Verdict record(const Pose& X, const std::string& how);
  void walk(Pose X, Verdict V, const std::string& fam);
  Vec3 point_on_b(int kind, int idx);
  Vec3 point_on_a(int kind, int idx);
  Vec3 outward_b(int kind, int idx);
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int I(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng_); }
  Vec3 unit();

  const Classifier& C_;
  const Poly& A_;
  const Poly& B_;
  SamplerOptions o_;
  std::mt19937_64 rng_;
  std::map<CfKey, Sample> found_;
  SamplerStats st_;
  std::vector<int> convex_a_, convex_b_;
};

}  // namespace oracle

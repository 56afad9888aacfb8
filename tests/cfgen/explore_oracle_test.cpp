// cfgen's exact first contacts (tools/cfgen/decide/explore.cpp) against the independent oracle's
// (tests/oracle/motion.cpp, which shares no code with tools/ or libcf/), on the oracle's shape
// families with random proportions and placements: A starts clear of B and is translated
// towards it, or turned about an axis that swings it into B. The two must find the same first
// contact. This is what keeps the generator's culling of element pairs (ranges across the
// direction of a translation, heights and distances about the axis of a rotation) exact.

#include "cfgen/decide/explore.hpp"
#include "motion.hpp"
#include "oracle_pair.hpp"
#include "oracle_pose.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace {

// Both sides solve the same linear (translation) or closed-form trigonometric (vertex-face
// rotation) equations from coordinates of tens of mm, and refine edge-edge rotation events by
// bisection to double precision: they agree to rounding, far below this (mm or rad).
constexpr double kSameEvent = 1e-6;
// Events count within this distance of an element (mm): the generator's touch tolerance for
// parts of this size (1e-9 of their size) would do; both sides take the same value.
constexpr double kTol = 1e-7;

using Pair = cf::test::OraclePair;
using cf::test::clear_pose;
using cf::test::random_unit;

Pair make(std::uint64_t seed) { return cf::test::make_oracle_pair(seed); }

bool same(double a, double b) {
  if (std::isinf(a) || std::isinf(b)) return std::isinf(a) && std::isinf(b);
  return std::abs(a - b) <= kSameEvent;
}

}  // namespace

TEST_CASE("first contact of a translation: the same event as the oracle's", "[explore][oracle]") {
  int hits = 0, cases = 0;
  for (std::uint64_t seed = 1; seed <= 2 * oracle::kPairings; ++seed) {
    const Pair p = make(seed);
    std::mt19937_64 rng(1000 + seed);
    std::uniform_real_distribution<double> spread(-0.5, 0.5);
    for (int k = 0; k < 40; ++k) {
      cf::Vec3 away;
      const cf::Pose X = clear_pose(p, rng, away);
      // Towards B, turned off its centre by up to about half a radian: some miss it.
      const cf::Vec3 d = (-away + spread(rng) * random_unit(rng)).normalized();
      const double s_max = 2 * (p.rA + p.rB) + 2;
      const double mine = cf::gen::first_contact_translation(p.A, p.B, X, d, 0.0, s_max, kTol, {});
      oracle::Motion m;
      m.u = d;
      const double theirs =
          oracle::time_of_impact(p.oA, p.oB, cf::test::to_oracle(X), m, s_max, kTol);
      INFO("seed " << seed << " ("
                   << oracle::pairing_name(static_cast<int>(seed % oracle::kPairings))
                   << "), motion " << k << ": cfgen " << mine << " mm, oracle " << theirs << " mm");
      CHECK(same(mine, theirs));
      ++cases;
      if (!std::isinf(mine)) ++hits;
    }
  }
  // Most motions meet B, so the events, not only the misses, are compared.
  CHECK(hits > cases / 2);
}

TEST_CASE("first contact of a rotation: the same event as the oracle's", "[explore][oracle]") {
  int hits = 0, cases = 0, differ = 0;
  for (std::uint64_t seed = 1; seed <= 2 * oracle::kPairings; ++seed) {
    const Pair p = make(seed);
    std::mt19937_64 rng(2000 + seed);
    for (int k = 0; k < 40; ++k) {
      cf::Vec3 away;
      const cf::Pose X = clear_pose(p, rng, away);
      // The axis through a point between the two, across the line joining them: A swings
      // around it into B's side.
      const cf::Vec3 c = p.cB + (p.rB + 0.5) * away;
      cf::Vec3 u = random_unit(rng);
      u = (u - u.dot(away) * away).normalized();
      const double phi_max = M_PI;
      const double mine =
          cf::gen::first_contact_rotation(p.A, p.B, X, c, u, 0.0, phi_max, kTol, {});
      oracle::Motion m;
      m.rotation = true;
      m.c = c;
      m.w = u;
      const double theirs =
          oracle::time_of_impact(p.oA, p.oB, cf::test::to_oracle(X), m, phi_max, kTol);
      ++cases;
      if (!std::isinf(mine)) ++hits;
      if (!same(mine, theirs)) {
        ++differ;
        UNSCOPED_INFO("seed " << seed << ", motion " << k << ": cfgen " << mine << " rad, oracle "
                              << theirs << " rad");
      }
    }
  }
  CHECK(hits > cases / 2);
  CHECK(differ == 0);
}

// cfgen's exact first contacts (tools/cfgen/explore.cpp) against the independent oracle's
// (tests/oracle/motion.cpp, which shares no code with tools/ or libcf/), on the oracle's shape
// families with random proportions and placements: A starts clear of B and is translated
// towards it, or turned about an axis that swings it into B. The two must find the same first
// contact. This is what keeps the generator's culling of element pairs (ranges across the
// direction of a translation, heights and distances about the axis of a rotation) exact.

#include "cfgen/explore.hpp"
#include "mesh/model_loader.hpp"
#include "motion.hpp"
#include "oracle_pose.hpp"
#include "poly.hpp"
#include "scratch.hpp"
#include "shapes.hpp"

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

// The oracle's own polyhedron, rebuilt from the vertices, edges and face loops cfgen read
// (the oracle derives everything else itself).
oracle::Poly to_oracle(const cf::Polyhedron& m, const std::string& name) {
  std::vector<oracle::Vec3> verts;
  for (const cf::Vertex& v : m.vertices()) verts.push_back(v.p);
  std::vector<std::array<int, 2>> edges;
  for (const cf::Edge& e : m.edges())
    edges.push_back({static_cast<int>(e.v0.index()), static_cast<int>(e.v1.index())});
  std::vector<std::vector<std::vector<int>>> faces;
  for (const cf::Face& f : m.faces()) {
    std::vector<std::vector<int>> loops;
    for (const auto& loop : f.loops) {
      loops.emplace_back();
      for (cf::VertexId v : loop) loops.back().push_back(static_cast<int>(v.index()));
    }
    faces.push_back(loops);
  }
  return oracle::build_poly(verts, edges, faces, name);
}

struct Pair {
  cf::Polyhedron A, B;
  oracle::Poly oA, oB;
  cf::Vec3 cA, cB;        // bounding-box centres (own frames)
  double rA = 0, rB = 0;  // half diagonals
};

Pair make(std::uint64_t seed) {
  const oracle::ShapePair sp = oracle::make_pair(seed);
  const std::string tag = std::to_string(seed);
  oracle::write_off(sp.A, (cf::test::scratch() / ("A" + tag + ".off")).string());
  oracle::write_off(sp.B, (cf::test::scratch() / ("B" + tag + ".off")).string());
  Pair p;
  p.A = cf::tools::load_model((cf::test::scratch() / ("A" + tag + ".off")).string());
  p.B = cf::tools::load_model((cf::test::scratch() / ("B" + tag + ".off")).string());
  p.oA = to_oracle(p.A, "A");
  p.oB = to_oracle(p.B, "B");
  p.cA = 0.5 * (p.A.bbox_min() + p.A.bbox_max());
  p.cB = 0.5 * (p.B.bbox_min() + p.B.bbox_max());
  p.rA = 0.5 * (p.A.bbox_max() - p.A.bbox_min()).norm();
  p.rB = 0.5 * (p.B.bbox_max() - p.B.bbox_min()).norm();
  return p;
}

cf::Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  cf::Vec3 v(g(rng), g(rng), g(rng));
  return v.normalized();
}

// A posed with its bounding sphere clear of B's, along a random direction from B's centre:
// no pair touches at the start.
cf::Pose clear_pose(const Pair& p, std::mt19937_64& rng, cf::Vec3& away) {
  cf::Pose X;
  X.R_BA = oracle::random_rotation(rng);
  away = random_unit(rng);
  X.t_BA = p.cB + (p.rA + p.rB + 1.0) * away - X.R_BA * p.cA;
  return X;
}

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

// Independent tests of the CF graph generator (tools/cfgen; docs/spec.md, sections 3-5b).
//
// What a contact *is* is decided by the independent oracle (tests/oracle, written from the
// specification; it shares no code with tools/ or libcf/): open-set touching of two elements,
// domination, PC types, contact planes, interior disjointness, the first contact of a
// translated polyhedron, the rules of transitions, and the shapes built in memory. The oracle
// reads cfgen's models as plain data only, their vertices, edges and face loops
// (cf::test::to_oracle), so that both number the elements alike. The generator's own
// WitnessSearch appears only in failure messages (what its verify() says about a pose the
// oracle found) and for the U-channel's two-PC sets (see that test).
//
// Sections:
//  0. the oracle, as this file uses it, on poses with known answers;
//  1. hand-derived CF sets, with hand-made witnesses: cube on a big box, cube vs L-block,
//     cube vs corner block, cube vs a U-channel whose inner walls face each other 40 mm apart;
//  2. every witness of every generated graph re-verified;
//  3. recall: random guarded and sliding motions; every clean CF reached must be in the
//     graph (plus the poses earlier runs found missing, kept as fixed cases);
//  4. transitions (gain/lose/change) against the rules of docs/spec.md, section 4, both directions;
//  5. determinism: the whole cube/L-block graph with 1 and 2 threads, and cfgen's file.
//
// Each model pair is generated once per process (the tests of one pair are SECTIONs of one
// TEST_CASE, so ctest's one-process-per-test-case does not regenerate it).

#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/generate.hpp"
#include "classify.hpp"
#include "mesh/model_loader.hpp"
#include "motion.hpp"
#include "oracle_pair.hpp"
#include "oracle_pose.hpp"
#include "shapes.hpp"
#include "transitions.hpp"

#include <cf/graph.hpp>
#include <cf/polyhedron.hpp>

#include <catch2/catch.hpp>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace fs = std::filesystem;
using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Polyhedron;
using cf::Pose;
using cf::Vec3;
using K = cf::ElementKind;

namespace {

// ---------------------------------------------------------------------------------------
// Tolerances
// ---------------------------------------------------------------------------------------

// Two elements touch when their closed distance is below this (mm). The oracle classifies
// with it, not with its own default (1e-7 of the smaller model's diagonal: 5e-6 mm for the
// 30 mm cube). The generator's own touch tolerance is 1e-9 and its witnesses keep every other
// pair >= 1e-2 mm apart, so 1e-7 separates "touching" from "apart" by five orders of
// magnitude either way.
constexpr double kTouchTol = 1e-7;
// A second, coarser tolerance: a random pose whose classification changes between kTouchTol
// and this is too close to a boundary case to be judged, and is skipped in the recall test.
constexpr double kCoarseTol = 1e-5;
// The oracle's other tolerances (tests/oracle/README.md) replace those of this file's earlier
// in-file checks:
//  - two contact planes are one when their normals are within 1e-6 rad and their offsets
//    within 4 x kTouchTol (before: 1e-5 mm); between that and 1e-4 rad or 100 x kTouchTol the
//    oracle calls the pose near-degenerate, and the recall test skips it like a disagreement
//    of the two tolerances;
//  - interiors intersect when the tangent cones of some touching pair overlap, decided
//    exactly up to an angular slack of 1e-6 rad (2 kTouchTol over a line contact's length,
//    4 kTouchTol over the root of a face contact's area: the tilt the touch tolerance itself
//    allows); before, points more than 1e-6 mm inside a solid were looked for within 1e-3 mm
//    of each contact, which missed shallower or narrower overlaps;
//  - a translation's first contact counts events within kTouchTol of an element (before:
//    1e-9 mm off a face, 1e-12 of an edge's length): looser, but a pose that close to a
//    contact touches at kTouchTol anyway, and every pose reached is classified before it
//    counts.

// How far along a translation (mm) a pose is classified to see whether the translation
// pushes into a contact held at its start (or half-way to its first contact when that is
// nearer): far above kTouchTol, far below any feature of the models.
constexpr double kProbeStep = 1e-3;

const std::string kModels = std::string(CF_SOURCE_DIR) + "/data/models/";

Mat3 align(const Vec3& from, const Vec3& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}
Mat3 axis_angle(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}
// The pose after rotating A by Q about the world point c.
Pose rotate_about(const Pose& p, const Mat3& Q, const Vec3& c) {
  Pose out;
  out.R_BA = Q * p.R_BA;
  out.t_BA = Q * (p.t_BA - c) + c;
  return out;
}
Pose translated(const Pose& p, const Vec3& d) {
  Pose out = p;
  out.t_BA += d;
  return out;
}

std::string vec_str(const Vec3& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}
std::string pose_str(const Pose& p) { return oracle::pose_string(cf::test::to_oracle(p)); }

// ---------------------------------------------------------------------------------------
// The oracle on one model pair
// ---------------------------------------------------------------------------------------

oracle::Tolerances tolerances(double len) {
  oracle::Tolerances t;  // angular slack: the oracle's, 1e-6 rad
  t.len = len;
  t.gap = 100 * len;  // the oracle's sampler's; unused here
  return t;
}

// The oracle's verdict at a pose, with its PCs in the project's types.
struct Analysis {
  oracle::Verdict v;
  PcSet pcs;  // the PCs, unless penetrating, degenerate or more than 3
  bool contact() const { return !v.touches.empty(); }
  bool clean() const { return v.valid_cf(); }
  std::string describe() const { return v.describe(); }
};

// Number of PCs of a degenerate type (v-v, v-e, e-v, collinear e-e).
int degenerate_pcs(const Analysis& an) {
  int n = 0;
  for (int i : an.v.pcs)
    if (!oracle::nondegenerate(an.v.touches[static_cast<std::size_t>(i)].type)) ++n;
  return n;
}

// The oracle's polyhedra rebuilt from cfgen's models, and its classifier at both tolerances.
struct Oracle {
  Oracle(const Polyhedron& a, const Polyhedron& b)
      : A(cf::test::to_oracle(a, a.name())),
        B(cf::test::to_oracle(b, b.name())),
        fine(A, B, tolerances(kTouchTol)),
        coarse(A, B, tolerances(kCoarseTol)) {}
  Oracle(const Oracle&) = delete;
  Oracle& operator=(const Oracle&) = delete;

  // `clearance`: also the distance to the nearest pair that does not touch (costs a pass
  // over every pair).
  Analysis analyse(const Pose& p, const oracle::Classifier& at, bool clearance = false) const {
    Analysis an;
    an.v = at.classify(cf::test::to_oracle(p), clearance);
    if (!an.v.penetrating && !an.v.degenerate && !an.v.too_many && !an.v.pcs.empty())
      an.pcs = cf::test::to_cf(an.v.key());
    return an;
  }
  Analysis analyse(const Pose& p) const { return analyse(p, fine); }

  const oracle::Poly A, B;
  const oracle::Classifier fine, coarse;  // at kTouchTol, at kCoarseTol
};

// ---------------------------------------------------------------------------------------
// Generated graphs, once per process
// ---------------------------------------------------------------------------------------

struct Generated {
  std::unique_ptr<Polyhedron> A, B;  // stable addresses: ModelInfo points at them
  std::unique_ptr<Oracle> oracle;
  cf::gen::ModelInfo ai, bi;
  cf::gen::Enumeration e;
  std::unique_ptr<cf::CfGraph> graph;
  double seconds = 0;
};

const Generated& generated(const std::string& key, const std::function<Polyhedron()>& make_a,
                           const std::function<Polyhedron()>& make_b, int max_pcs = 3) {
  static std::map<std::string, std::unique_ptr<Generated>> cache;
  auto it = cache.find(key);
  if (it != cache.end()) return *it->second;
  auto g = std::make_unique<Generated>();
  g->A = std::make_unique<Polyhedron>(make_a());
  g->B = std::make_unique<Polyhedron>(make_b());
  g->oracle = std::make_unique<Oracle>(*g->A, *g->B);
  const auto t0 = std::chrono::steady_clock::now();
  g->ai = cf::gen::analyse_model(*g->A);
  g->bi = cf::gen::analyse_model(*g->B);
  cf::gen::EnumerateOptions opt;
  opt.max_pcs = max_pcs;
  cf::gen::ExecuteOptions exec;
  exec.threads = 2;
  g->e = cf::gen::enumerate_pair(g->ai, g->bi, {}, opt, exec);
  g->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // from_parts is the graph's own consistency check (ranges, distinct faces, transition kinds).
  g->graph = std::make_unique<cf::CfGraph>(
      cf::CfGraph::from_parts(*g->A, *g->B, g->e.cfs, g->e.transitions));
  return *cache.emplace(key, std::move(g)).first->second;
}

Polyhedron load(const std::string& file) { return cf::tools::load_model(kModels + file); }

const Generated& cube_l_block() {
  return generated(
      "cube/l_block", [] { return load("cube.off"); }, [] { return load("l_block.off"); });
}
const Generated& cube_corner_block() {
  return generated(
      "cube/corner_block", [] { return load("cube.off"); },
      [] { return load("corner_block.off"); });
}

// The oracle's box [0, 200]^3 and its U-channel, 80 x 80 x 80 mm: floor 20 thick, two arms 20
// thick; the slot between the arms is 40 mm wide (x in 20..60), more than the 30 mm cube.
Polyhedron big_box() { return cf::test::from_oracle(oracle::make_box(200, 200, 200), "big_box"); }
Polyhedron u_channel() {
  return cf::test::from_oracle(oracle::make_u_channel(40, 20, 20, 80, 80), "u_channel");
}

// ---------------------------------------------------------------------------------------
// Section 2: witnesses
// ---------------------------------------------------------------------------------------

void check_witnesses(const Generated& g, const std::string& label) {
  std::size_t ok = 0, bad = 0;
  std::size_t by_size[4] = {0, 0, 0, 0};
  std::ostringstream failures;
  for (std::size_t i = 0; i < g.graph->num_cfs(); ++i) {
    const cf::CfRecord& r = g.graph->cf(cf::CfId(static_cast<int>(i)));
    const Analysis an = g.oracle->analyse(r.witness);
    std::string why;
    if (!an.contact())
      why = "no contact at the witness";
    else if (an.v.penetrating)
      why = "interiors intersect";
    else if (an.v.degenerate)
      why = "degenerate undominated touch";
    else if (an.v.same_plane)
      why = "two PCs share a contact plane";
    else if (an.v.too_many)
      why = "more than 3 PCs";
    else if (an.pcs != r.pcs)
      why = "PCs differ: geometry gives {" + cf::to_string(an.pcs) + "}";
    if (why.empty()) {
      ++ok;
      ++by_size[r.pcs.size()];
    } else {
      if (++bad <= 10)
        failures << "  CF " << i << " {" << cf::to_string(r.pcs) << "}: " << why << "; "
                 << an.describe() << "; witness " << pose_str(r.witness) << "\n";
    }
  }
  WARN(label << ": " << g.graph->num_cfs() << " witnesses re-verified independently: " << ok
             << " confirmed (" << by_size[1] << " one-PC, " << by_size[2] << " two-PC, "
             << by_size[3] << " three-PC), " << bad << " rejected");
  INFO("first rejected witnesses:\n" << failures.str());
  CHECK(bad == 0);
}

// ---------------------------------------------------------------------------------------
// Section 3: recall by random guarded and sliding motions
// ---------------------------------------------------------------------------------------

struct RecallStats {
  int trials = 0, missed_b = 0, poses = 0, no_contact = 0, penetrating = 0, ambiguous = 0,
      degenerate = 0, shared_plane = 0, too_many = 0, clean = 0, clean_found = 0;
  std::map<std::vector<Pc>, Pose> reached;  // distinct clean CFs, with the first pose
  std::map<std::vector<Pc>, std::pair<Pose, std::string>> missing;
  std::vector<std::string> penetrations;
};

// What the classification says, for comparing it at the two tolerances.
std::string signature(const Analysis& an) {
  std::ostringstream os;
  os << an.v.penetrating << an.v.degenerate << an.v.same_plane << an.v.too_many << ":"
     << oracle::key_string(an.v.key());
  return os.str();
}

class Explorer {
 public:
  Explorer(const Generated& g, std::uint32_t seed)
      : g_(g), o_(*g.oracle), A_(o_.A), B_(o_.B), rng_(seed) {
    for (std::size_t e = 0; e < B_.E.size(); ++e)
      if (!B_.E[e].convex) reflex_.push_back(static_cast<int>(e));
    center_a_ = 0.5 * (A_.box.lo + A_.box.hi);
    radius_a_ = 0.5 * A_.diag;
    radius_b_ = 0.5 * B_.diag;
    reach_ = 4 * (radius_a_ + radius_b_) + 10;
  }

  RecallStats run(int trials) {
    for (int i = 0; i < trials; ++i) trial();
    return st_;
  }

 private:
  // A non-degenerate PC, with its contact plane's normal (from B into A) and a contact point
  // (the middle of a line contact).
  struct Contact {
    oracle::PcType type;
    int a, b;
    Vec3 n, point;
  };
  std::vector<Contact> contacts(const Analysis& an) const {
    std::vector<Contact> out;
    for (int i : an.v.pcs) {
      const oracle::Touch& t = an.v.touches[static_cast<std::size_t>(i)];
      if (!oracle::nondegenerate(t.type)) continue;
      const bool line = t.type == oracle::PcType::EF || t.type == oracle::PcType::FE;
      out.push_back({t.type, t.a, t.b, oracle::normal_into_a(B_, t),
                     line ? Vec3(0.5 * (t.p0 + t.p1)) : t.p0});
    }
    return out;
  }

  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  int pick(std::size_t n) { return pick(static_cast<int>(n)); }
  Vec3 random_unit() {
    std::normal_distribution<double> nd;
    Vec3 v;
    do v = Vec3(nd(rng_), nd(rng_), nd(rng_));
    while (v.norm() < 1e-6);
    return v.normalized();
  }
  Mat3 random_rotation() {
    std::normal_distribution<double> nd;
    Eigen::Quaterniond q(nd(rng_), nd(rng_), nd(rng_), nd(rng_));
    q.normalize();
    return q.toRotationMatrix();
  }
  // Spin about an axis: a multiple of 90 degrees half the time (the default models are
  // axis-aligned, so this lines edges up and reaches f-f pairs), else any angle.
  Mat3 spin(const Vec3& axis) {
    const double angle = pick(2) == 0 ? pick(4) * M_PI / 2 : uni(0, 2 * M_PI);
    return axis_angle(axis, angle);
  }
  Vec3 point_on_edge(const oracle::Poly& P, int e, double s) const {
    const oracle::Edge& E = P.E[static_cast<std::size_t>(e)];
    return (1 - s) * P.V[static_cast<std::size_t>(E.v0)].p +
           s * P.V[static_cast<std::size_t>(E.v1)].p;
  }
  Vec3 random_point_on_edge(int e) { return point_on_edge(B_, e, uni(0.05, 0.95)); }
  // The sum of the normals of an edge's two faces, normalized.
  static Vec3 bisector(const oracle::Poly& P, int e) {
    const oracle::Edge& E = P.E[static_cast<std::size_t>(e)];
    return (P.F[static_cast<std::size_t>(E.face[0])].n + P.F[static_cast<std::size_t>(E.face[1])].n)
        .normalized();
  }
  Vec3 point_on_b_face(int f) {
    const oracle::Face& F = B_.F[static_cast<std::size_t>(f)];
    double u0 = 1e300, u1 = -1e300, w0 = 1e300, w1 = -1e300;
    for (const auto& loop : F.loops2)
      for (const oracle::Vec2& p : loop) {
        u0 = std::min(u0, p.x()), u1 = std::max(u1, p.x());
        w0 = std::min(w0, p.y()), w1 = std::max(w1, p.y());
      }
    for (int k = 0; k < 100; ++k) {
      const oracle::Vec2 q(uni(u0, u1), uni(w0, w1));
      if (oracle::inside_loops(F.loops2, q) && oracle::dist_to_loops(F.loops2, q) > 0.5)
        return F.to3(q);
    }
    return F.centroid;
  }

  // Classifies a pose, counts it, and checks the graph.
  Analysis record(const Pose& pose) {
    ++st_.poses;
    const Analysis fine = o_.analyse(pose);
    history_ += " -> {" + fine.describe() + "} at " + pose_str(pose) + "\n";
    if (!fine.contact()) {
      ++st_.no_contact;
      return fine;
    }
    const Analysis coarse = o_.analyse(pose, o_.coarse);
    if (fine.v.penetrating && coarse.v.penetrating) {
      ++st_.penetrating;
      if (st_.penetrations.size() < 5)
        st_.penetrations.push_back(fine.describe() + " at " + pose_str(pose) + " after " +
                                   history_);
      return fine;
    }
    // Includes slivers (nearly coplanar faces, a tilt of 1e-4 rad, that cross over less than
    // the fine tolerance's worth of depth), and the poses the oracle itself calls
    // near-degenerate (an e-e crossing next to an edge's end, a line contact of tiny length,
    // two contact planes nearly one, a sliver of f-f overlap).
    if (signature(coarse) != signature(fine) || !fine.v.uncertain.empty()) {
      ++st_.ambiguous;
      return fine;
    }
    if (fine.v.degenerate)
      ++st_.degenerate;
    else if (fine.v.too_many)
      ++st_.too_many;
    else if (fine.v.same_plane)
      ++st_.shared_plane;
    else {
      ++st_.clean;
      const std::vector<Pc> key(fine.pcs.begin(), fine.pcs.end());
      st_.reached.emplace(key, pose);
      if (g_.graph->find(fine.pcs))
        ++st_.clean_found;
      else
        st_.missing.emplace(key, std::make_pair(pose, fine.describe()));
    }
    return fine;
  }

  // The oracle's first contact of A translated from p along u (mm; infinite when there is
  // none within reach_). Events at the start are skipped, except a vertex pushed into a face
  // it touches (then 0).
  double first_contact(const Pose& p, const Vec3& u) const {
    oracle::Motion m;
    m.u = u;
    return oracle::time_of_impact(A_, B_, cf::test::to_oracle(p), m, reach_, kTouchTol);
  }

  // A, moved from p along u until it touches; nullopt when it misses. A contact held at p
  // that the motion pushes into (an edge on an edge, whose event at the start
  // first_contact skips) stops it at once.
  std::optional<Pose> guarded(const Pose& p, const Vec3& u) {
    const double s = first_contact(p, u);
    if (s > 0 && o_.analyse(translated(p, std::min(kProbeStep, 0.5 * s) * u)).v.penetrating)
      return p;
    if (!std::isfinite(s)) return std::nullopt;
    return translated(p, s * u);
  }

  void trial() {
    ++st_.trials;
    const oracle::Poly& A = A_;
    const oracle::Poly& B = B_;
    Mat3 R;
    Vec3 u, target;
    switch (pick(reflex_.empty() ? 4 : 5)) {
      case 4: {  // towards a concave corner of B, any orientation
        const int eb = reflex_[static_cast<std::size_t>(pick(reflex_.size()))];
        R = random_rotation();
        target = random_point_on_edge(eb);
        u = (-bisector(B, eb) + 0.7 * random_unit()).normalized();
        break;
      }
      case 0:  // anything
        R = random_rotation();
        target =
            B.box.lo + (B.box.hi - B.box.lo).cwiseProduct(Vec3(uni(0, 1), uni(0, 1), uni(0, 1)));
        u = random_unit();
        break;
      case 1: {  // a face of A parallel to a face of B, approaching it
        const int fa = pick(A.F.size()), fb = pick(B.F.size());
        const Vec3 nb = B.F[static_cast<std::size_t>(fb)].n;
        R = spin(nb) * align(A.F[static_cast<std::size_t>(fa)].n, -nb);
        target = point_on_b_face(fb);
        u = pick(3) ? -nb : (random_unit() - 2 * nb).normalized();
        break;
      }
      case 2: {  // an edge of A parallel to a face of B
        const int ea = pick(A.E.size()), fb = pick(B.F.size());
        const Vec3 nb = B.F[static_cast<std::size_t>(fb)].n;
        R = spin(nb) * align(bisector(A, ea), -nb);
        target = point_on_b_face(fb);
        u = pick(3) ? -nb : (random_unit() - 2 * nb).normalized();
        break;
      }
      default: {  // a face of A square to the bisector of an edge of B
        const int fa = pick(A.F.size()), eb = pick(B.E.size());
        const Vec3 bis = bisector(B, eb);
        R = spin(bis) * align(A.F[static_cast<std::size_t>(fa)].n, -bis);
        target = point_on_edge(B, eb, uni(0.05, 0.95));
        u = pick(3) ? -bis : (random_unit() - 2 * bis).normalized();
        break;
      }
    }
    // Start well clear of B's bounding sphere, on the line through the target.
    Pose start;
    start.R_BA = R;
    start.t_BA = target - u * (radius_a_ + 2 * radius_b_ + 1) - R * center_a_;
    history_ = "approach from " + pose_str(start) + " along " + vec_str(u);
    std::optional<Pose> pose = guarded(start, u);
    if (!pose) {
      ++st_.missed_b;
      return;
    }
    Analysis an = record(*pose);
    const int steps = 1 + pick(8);
    for (int k = 0; k < steps; ++k) {
      if (!an.contact() || an.v.penetrating) return;
      const std::vector<Contact> cs = contacts(an);
      if (cs.empty()) return;
      std::optional<Pose> next;
      switch (pick(5)) {
        case 0:
        case 1:
          history_ += ", slide";
          next = slide(*pose, cs);
          break;
        case 2:
        case 3:
          history_ += ", snap";
          next = snap(*pose, cs);
          break;
        default:
          history_ += ", tilt";
          next = tilt(*pose, cs);
          break;
      }
      if (!next) return;
      pose = next;
      an = record(*pose);
    }
  }

  // Translates along the contact planes (keeping every contact) until a new contact, or
  // for a random length and then presses A back against B along a contact normal.
  std::optional<Pose> slide(const Pose& pose, const std::vector<Contact>& cs) {
    Eigen::MatrixXd N(static_cast<Eigen::Index>(cs.size()), 3);
    for (std::size_t i = 0; i < cs.size(); ++i)
      N.row(static_cast<Eigen::Index>(i)) = cs[i].n.transpose();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(N, Eigen::ComputeFullV);
    const auto& sv = svd.singularValues();
    int rank = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      if (sv(i) > 1e-9) ++rank;
    if (rank >= 3) return tilt(pose, cs);
    Vec3 u = Vec3::Zero();
    if (!reflex_.empty() && pick(2) == 0) {
      // Towards a concave corner of B, within the contact planes.
      const int eb = reflex_[static_cast<std::size_t>(pick(reflex_.size()))];
      const Vec3 d = random_point_on_edge(eb) - cs[0].point;
      for (int c = rank; c < 3; ++c) u += d.dot(svd.matrixV().col(c)) * svd.matrixV().col(c);
    } else {
      for (int c = rank; c < 3; ++c) u += uni(-1, 1) * svd.matrixV().col(c);
    }
    if (u.norm() < 1e-6) return std::nullopt;
    u.normalize();
    const double s = first_contact(pose, u);
    const double len = uni(5, 80);
    // A touch already present (a dominated one off the contact planes, such as an edge of A
    // through a vertex of B) may block the slide at once.
    if (s == 0 || o_.analyse(translated(pose, std::min(kProbeStep, 0.5 * std::min(s, len)) * u))
                      .v.penetrating)
      return std::nullopt;
    if (s <= len) return translated(pose, s * u);
    const Vec3 n = cs[static_cast<std::size_t>(pick(cs.size()))].n;
    return guarded(translated(pose, len * u), -n);
  }

  // Rotates about a contact to bring a neighbouring element flat against the other solid
  // (v-f -> e-f, e-f -> f-f, f-e -> f-f, f-v -> f-e, e-e -> e-f), then re-establishes
  // contact if the rotation pushed A into B or off it.
  std::optional<Pose> snap(const Pose& pose, const std::vector<Contact>& cs) {
    const oracle::Poly& A = A_;
    const oracle::Poly& B = B_;
    const Contact& c = cs[static_cast<std::size_t>(pick(cs.size()))];
    const Mat3& R = pose.R_BA;
    auto vertex = [](const oracle::Poly& P, int v) -> const oracle::Vertex& {
      return P.V[static_cast<std::size_t>(v)];
    };
    auto edge = [](const oracle::Poly& P, int e) -> const oracle::Edge& {
      return P.E[static_cast<std::size_t>(e)];
    };
    auto normal = [](const oracle::Poly& P, int f) -> const Vec3& {
      return P.F[static_cast<std::size_t>(f)].n;
    };
    Mat3 Q = Mat3::Identity();
    Vec3 pivot = c.point;
    auto flatten_dir = [&](const Vec3& d, const Vec3& n) {  // rotate d into the plane normal to n
      const Vec3 dp = d - d.dot(n) * n;
      return dp.norm() < 1e-9 ? Mat3(Mat3::Identity()) : align(d.normalized(), dp.normalized());
    };
    switch (c.type) {
      case oracle::PcType::VF: {
        const auto& es = vertex(A, c.a).edges;
        const oracle::Edge& e = edge(A, es[static_cast<std::size_t>(pick(es.size()))]);
        const Vec3 p = pose.apply(vertex(A, c.a).p);
        const Vec3 other = pose.apply(vertex(A, e.v0 == c.a ? e.v1 : e.v0).p);
        Q = flatten_dir(other - p, c.n);
        pivot = p;
        break;
      }
      case oracle::PcType::EF: {
        const oracle::Edge& e = edge(A, c.a);
        const int f = pick(2) ? e.face[0] : e.face[1];
        Q = align(R * normal(A, f), -c.n);
        break;
      }
      case oracle::PcType::FE: {
        const oracle::Edge& e = edge(B, c.b);
        const int f = pick(2) ? e.face[0] : e.face[1];
        Q = align(R * normal(A, c.a), -normal(B, f));
        break;
      }
      case oracle::PcType::FV: {
        const auto& es = vertex(B, c.b).edges;
        const Vec3 d = edge(B, es[static_cast<std::size_t>(pick(es.size()))]).dir;
        const Vec3 m = R * normal(A, c.a);
        const Vec3 mp = m - m.dot(d) * d;
        Q = align(m, mp.normalized());
        pivot = vertex(B, c.b).p;
        break;
      }
      case oracle::PcType::EE: {
        const oracle::Edge& e = edge(B, c.b);
        const int f = pick(2) ? e.face[0] : e.face[1];
        const oracle::Edge& ea = edge(A, c.a);
        Q = flatten_dir(R * (vertex(A, ea.v1).p - vertex(A, ea.v0).p), normal(B, f));
        break;
      }
      case oracle::PcType::FF:
        return tilt(pose, cs);
      default:  // degenerate types: never in cs
        return std::nullopt;
    }
    return resettle(rotate_about(pose, Q, pivot), c.n);
  }

  // Small random rotation about a contact point, then contact re-established.
  std::optional<Pose> tilt(const Pose& pose, const std::vector<Contact>& cs) {
    const std::size_t i = static_cast<std::size_t>(pick(cs.size()));
    const Mat3 Q = axis_angle(random_unit(), uni(0.01, 0.3));
    return resettle(rotate_about(pose, Q, cs[i].point), cs[i].n);
  }

  // After a rotation: if A now penetrates B, back it off along n until clear; then press it
  // against B along -n.
  std::optional<Pose> resettle(const Pose& rotated, const Vec3& n) {
    Pose p = rotated;
    const Analysis an = o_.analyse(p);
    if (an.contact() && !an.v.penetrating) return p;
    if (an.v.penetrating) {
      p = translated(p, 40 * n);
      const Analysis clear = o_.analyse(p);
      if (clear.contact()) return std::nullopt;
    }
    return guarded(p, -n);
  }

  const Generated& g_;
  const Oracle& o_;
  const oracle::Poly& A_;
  const oracle::Poly& B_;
  Vec3 center_a_;  // A's bounding box: centre (A's frame), half diagonals of A and B
  double radius_a_ = 0, radius_b_ = 0;
  double reach_ = 0;  // longest translation to a first contact (mm)
  std::mt19937 rng_;
  RecallStats st_;
  std::string history_;      // the current trial's moves, for messages
  std::vector<int> reflex_;  // B's reflex edges: most multi-PC CFs are around them
};

void check_recall(const Generated& g, const std::string& label, int trials, std::uint32_t seed) {
  Explorer ex(g, seed);
  const RecallStats st = ex.run(trials);
  std::size_t by_size[4] = {0, 0, 0, 0};
  for (const auto& [pcs, pose] : st.reached) ++by_size[pcs.size()];
  WARN(label << ": recall over " << st.trials << " random guarded/sliding motions (" << st.missed_b
             << " missed B): " << st.poses << " poses; " << st.no_contact << " without contact, "
             << st.ambiguous << " too close to a boundary case, " << st.degenerate
             << " degenerate, " << st.shared_plane << " with two PCs in one plane, " << st.too_many
             << " with > 3 PCs, " << st.penetrating << " penetrating; " << st.clean
             << " clean poses reaching " << st.reached.size() << " distinct CFs (" << by_size[1]
             << " one-PC, " << by_size[2] << " two-PC, " << by_size[3] << " three-PC); "
             << st.missing.size() << " of them missing from the graph");
  std::ostringstream os;
  int n = 0;
  // What the generator's own pose verification says about each pose (diagnostics for
  // whoever fixes the generator: accepted means the witness search missed it).
  const cf::gen::WitnessSearch search(g.ai, g.bi, cf::gen::SearchParams{});
  for (const auto& [pcs, v] : st.missing) {
    if (++n > 25) break;
    std::string why;
    const double clearance = search.verify(PcSet(pcs), v.first, &why);
    os << "  {" << cf::to_string(PcSet(pcs)) << "} at " << pose_str(v.first)
       << " (clearance of that pose "
       << g.oracle->analyse(v.first, g.oracle->fine, true).v.clearance << " mm; cfgen's verify: "
       << (clearance >= 0 ? "accepts, clearance " + std::to_string(clearance) + " mm"
                          : "rejects: " + why)
       << ")\n";
  }
  INFO("CFs reached by motion but absent from the graph (first 25):\n" << os.str());
  CHECK(st.missing.empty());
  std::ostringstream pen;
  for (const auto& s : st.penetrations) pen << "  " << s << "\n";
  INFO("penetrating poses (a bug of this test's motion code):\n" << pen.str());
  CHECK(st.penetrating == 0);
  CHECK(st.clean > st.poses / 3);
}

// ---------------------------------------------------------------------------------------
// Section 4: transitions
// ---------------------------------------------------------------------------------------

void check_transitions(const Generated& g, const std::string& label) {
  const cf::CfGraph& G = *g.graph;
  const oracle::Poly& A = g.oracle->A;
  const oracle::Poly& B = g.oracle->B;
  const std::size_t n = G.num_cfs();
  std::vector<oracle::CfKey> keys;  // by CF id
  for (std::size_t i = 0; i < n; ++i)
    keys.push_back(cf::test::to_oracle(G.cf(cf::CfId(static_cast<int>(i))).pcs));
  std::set<std::tuple<int, int, int>> all;
  std::size_t kinds[3] = {0, 0, 0}, bad = 0;
  std::ostringstream failures;
  auto fail = [&](const std::string& s) {
    if (++bad <= 10) failures << "  " << s << "\n";
  };
  for (std::size_t i = 0; i < G.num_transitions(); ++i) {
    const cf::Transition& t = G.transition(i);
    const PcSet& from = G.cf(t.from).pcs;
    const PcSet& to = G.cf(t.to).pcs;
    const oracle::CfKey& kf = keys[t.from.index()];
    const oracle::CfKey& kt = keys[t.to.index()];
    all.insert({t.from.value(), t.to.value(), static_cast<int>(t.kind)});
    ++kinds[static_cast<int>(t.kind)];
    const std::string desc = std::string(cf::to_string(t.kind)) + " {" + cf::to_string(from) +
                             "} -> {" + cf::to_string(to) + "}";
    if (t.kind == cf::TransitionKind::kGain && !oracle::is_gain(kf, kt))
      fail(desc + ": not exactly one PC gained");
    if (t.kind == cf::TransitionKind::kLose && !oracle::is_gain(kt, kf))
      fail(desc + ": not exactly one PC lost");
    if (t.kind == cf::TransitionKind::kChange && !oracle::is_change(A, B, kf, kt))
      fail(desc + ": not a replacement by neighbouring PCs");
  }
  // Reverse pairs.
  for (const auto& [f, t, k] : all) {
    const int rk = k == static_cast<int>(cf::TransitionKind::kGain)
                       ? static_cast<int>(cf::TransitionKind::kLose)
                   : k == static_cast<int>(cf::TransitionKind::kLose)
                       ? static_cast<int>(cf::TransitionKind::kGain)
                       : k;
    if (!all.count({t, f, rk}))
      fail("no reverse of " + std::string(cf::to_string(static_cast<cf::TransitionKind>(k))) + " " +
           std::to_string(f) + " -> " + std::to_string(t));
  }
  // Completeness: every pair of graph CFs that the rules of docs/spec.md, section 4, relate has its
  // transition.
  std::size_t expected_gain = 0, expected_change = 0;
  std::vector<std::vector<int>> by_size(4);
  for (std::size_t i = 0; i < n; ++i)
    by_size[static_cast<std::size_t>(G.cf(cf::CfId(static_cast<int>(i))).pcs.size())].push_back(
        static_cast<int>(i));
  for (std::size_t i = 0; i < n; ++i) {
    const PcSet& s = G.cf(cf::CfId(static_cast<int>(i))).pcs;
    if (s.size() > 1)
      for (int k = 0; k < s.size(); ++k) {
        PcSet sub;
        for (int j = 0; j < s.size(); ++j)
          if (j != k) sub.insert(s[j]);
        if (const auto id = G.find(sub)) {
          ++expected_gain;
          if (!all.count(
                  {id->value(), static_cast<int>(i), static_cast<int>(cf::TransitionKind::kGain)}))
            fail("missing gain {" + cf::to_string(sub) + "} -> {" + cf::to_string(s) + "}");
        }
      }
  }
  for (const auto& ids : by_size)
    for (int i : ids)
      for (int j : ids) {
        if (i == j) continue;
        const PcSet& s = G.cf(cf::CfId(i)).pcs;
        const PcSet& t = G.cf(cf::CfId(j)).pcs;
        if (!oracle::is_change(A, B, keys[static_cast<std::size_t>(i)],
                               keys[static_cast<std::size_t>(j)]))
          continue;
        ++expected_change;
        if (!all.count({i, j, static_cast<int>(cf::TransitionKind::kChange)}))
          fail("missing change {" + cf::to_string(s) + "} -> {" + cf::to_string(t) + "}");
      }
  WARN(label << ": " << G.num_transitions() << " transitions (" << kinds[0] << " gain, " << kinds[1]
             << " lose, " << kinds[2]
             << " change); by the spec's rules over the graph's CFs: " << expected_gain
             << " gain and " << expected_change << " change expected; " << bad << " problems");
  INFO("first problems:\n" << failures.str());
  CHECK(bad == 0);
  CHECK(kinds[0] == expected_gain);
  CHECK(kinds[2] == expected_change);
}

// ---------------------------------------------------------------------------------------
// Section 1 helpers
// ---------------------------------------------------------------------------------------

int face_with(const Polyhedron& m, const Vec3& n, double d) {
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    if ((m.faces()[f].normal - n).norm() < 1e-9 && std::abs(m.faces()[f].offset - d) < 1e-9)
      return static_cast<int>(f);
  FAIL("model " << m.name() << " has no face with normal " << vec_str(n) << " and offset " << d);
  return -1;
}

// The cube's face with outward normal n (the cube is 30 mm, centred on its origin).
int cube_face(const Polyhedron& cube, const Vec3& n) { return face_with(cube, n, 15); }

std::vector<Vec3> axes() {
  return {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
          -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
}

// Counts of the one-PC CFs of the graph, by type.
std::map<PcType, int> single_pc_counts(const cf::CfGraph& G) {
  std::map<PcType, int> out;
  for (std::size_t i = 0; i < G.num_cfs(); ++i) {
    const PcSet& s = G.cf(cf::CfId(static_cast<int>(i))).pcs;
    if (s.size() == 1) ++out[s[0].type];
  }
  return out;
}

// The one-PC sets that local convexity allows, under the hand-derived facts used below:
// every A element qualifies (the cube is convex), B's reflex edges never touch with an edge
// (f-e, e-e), and B's non-pointed vertices are exactly those on a reflex edge (a 270-degree
// corner in one of their faces; all other vertices are three convex 90-degree edges).
// Convexity as the oracle derives it from the face loops.
std::set<std::vector<Pc>> allowed_single_pcs(const oracle::Poly& A, const oracle::Poly& B) {
  auto count = [](const oracle::Poly& P, K k) {
    return static_cast<int>(k == K::kVertex ? P.V.size() : k == K::kEdge ? P.E.size() : P.F.size());
  };
  std::set<int> nonpointed;
  for (const oracle::Edge& e : B.E)
    if (!e.convex) {
      nonpointed.insert(e.v0);
      nonpointed.insert(e.v1);
    }
  std::set<std::vector<Pc>> out;
  for (PcType t : {PcType::kFF, PcType::kEF, PcType::kFE, PcType::kVF, PcType::kFV, PcType::kEE})
    for (int a = 0; a < count(A, cf::a_kind(t)); ++a)
      for (int b = 0; b < count(B, cf::b_kind(t)); ++b) {
        if ((t == PcType::kFE || t == PcType::kEE) && !B.E[static_cast<std::size_t>(b)].convex)
          continue;
        if (t == PcType::kFV && nonpointed.count(b)) continue;
        out.insert({Pc{t, a, b}});
      }
  return out;
}

void check_single_pcs(const Generated& g, const std::map<PcType, int>& expected) {
  const auto got = single_pc_counts(*g.graph);
  int total = 0, total_expected = 0;
  for (const auto& [t, n] : expected) {
    total_expected += n;
    const int have = got.count(t) ? got.at(t) : 0;
    total += have;
    INFO("type " << cf::to_string(t));
    CHECK(have == n);
  }
  CHECK(total == total_expected);
  // The hand counts equal the size of the set local convexity allows, and that set is what
  // the graph holds.
  const auto allowed = allowed_single_pcs(g.oracle->A, g.oracle->B);
  CHECK(static_cast<int>(allowed.size()) == total_expected);
  std::ostringstream missing;
  int n_missing = 0;
  for (const auto& pcs : allowed)
    if (!g.graph->find(PcSet(pcs))) {
      if (++n_missing <= 40) missing << " {" << cf::to_string(PcSet(pcs)) << "}";
    }
  INFO("one-PC CFs allowed by local convexity but missing from the graph (first 40):"
       << missing.str());
  CHECK(n_missing == 0);
}

// Number of CFs made only of f-f PCs, with the given number of PCs.
std::vector<PcSet> all_ff(const cf::CfGraph& G, int size) {
  std::vector<PcSet> out;
  for (std::size_t i = 0; i < G.num_cfs(); ++i) {
    const PcSet& s = G.cf(cf::CfId(static_cast<int>(i))).pcs;
    if (s.size() != size) continue;
    bool ff = true;
    for (const Pc& p : s) ff = ff && p.type == PcType::kFF;
    if (ff) out.push_back(s);
  }
  return out;
}

std::size_t count_size(const cf::CfGraph& G, int size) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < G.num_cfs(); ++i)
    if (G.cf(cf::CfId(static_cast<int>(i))).pcs.size() == size) ++n;
  return n;
}

// The cube seated on B faces: cube face with normal src[k] flat against the plane with
// outward normal dst[k], cube centred at `center` (check_hand_cf has the oracle confirm that
// it realises exactly those f-f PCs).
Pose seat_pose(const std::vector<Vec3>& src, const std::vector<Vec3>& dst, const Vec3& center) {
  // R maps src[k] to -dst[k]; with two pairs the third axis follows by the cross product.
  Mat3 S, D;
  S.col(0) = src[0];
  S.col(1) = src[1];
  S.col(2) = src[0].cross(src[1]);
  D.col(0) = -dst[0];
  D.col(1) = -dst[1];
  D.col(2) = (-dst[0]).cross(-dst[1]);
  Pose p;
  p.R_BA = D * S.transpose();
  p.t_BA = center;
  return p;
}

// A CF derived by hand, with a witness built by hand: the oracle must confirm the witness, and
// the graph must hold the CF. When it does not, the message says what cfgen's own pose
// verification thinks of the hand witness (accepted: its search missed the CF).
void check_hand_cf(const Generated& g, const PcSet& s, const Pose& p) {
  const Analysis an = g.oracle->analyse(p);
  INFO("hand witness for {" << cf::to_string(s) << "}: " << pose_str(p)
                            << "; geometry: " << an.describe());
  CHECK(an.clean());
  CHECK(an.pcs == s);
  const bool found = g.graph->find(s).has_value();
  if (!found) {
    const cf::gen::WitnessSearch search(g.ai, g.bi, cf::gen::SearchParams{});
    std::string why;
    const double c = search.verify(s, p, &why);
    INFO("the graph lacks {" << cf::to_string(s) << "}; cfgen's own verify() of the hand witness: "
                             << (c >= 0 ? "accepts, clearance " + std::to_string(c) + " mm"
                                        : "rejects: " + why));
    CHECK(found);
  }
}

// Poses that this file's random motions (section 3) reached with earlier versions of cfgen
// (up to commit 297f4f3), whose CFs the graph lacked then: kept as fixed cases, each checked
// like a hand witness (the oracle must confirm the PCs; the graph must hold them).
struct KnownPose {
  const char* pcs;
  std::array<double, 9> R;  // row-major
  std::array<double, 3> t;
};

const KnownPose kKnownLBlock[] = {
    {"v-f:0:4;e-e:5:7",
     {-0.20123300967084398, -0.9705135725899106, 0.1326977062257768, 0.03593038514742266,
      0.12806444116514235, 0.9911147795952887, -0.9788842031833856, 0.20421288972008686,
      0.009100133526480248},
     {38.266657568417685, 37.326644088617805, 5.4327777985633166}},
    {"v-f:0:4;e-e:7:7",
     {0.8752655031402867, -0.4826118792134054, 0.03156062506805274, 0.31360959136829736,
      0.616018389630216, 0.7226135674336629, -0.36818381715440773, -0.6225810129449023,
      0.6905313599729623},
     {40.05271640005061, 44.78362322648263, -3.0858130309089153}},
    {"v-f:7:5;e-e:2:5",
     {0.5702612681509431, -0.7054576925382995, -0.4208699681438627, 0.8033585838009565,
      0.5859087054974752, 0.10642356250189328, 0.17151405738364295, -0.39879873728587806,
      0.9008565342267266},
     {45.448833932496576, 40.87872929966075, -3.073047797873069}},
    {"v-f:1:5;e-e:1:5",
     {-0.9620152998438014, 0.2303402881050774, 0.14652615651176704, 0.16974314652582012,
      0.08433342828647206, 0.9818732795432232, 0.21380792098038573, 0.9694489282830326,
      -0.12022873357448591},
     {40.08322616690969, 37.98205116016236, 9.540207205658987}},
};
const KnownPose kKnownCornerBlock[] = {
    {"f-f:0:8",
     {-0.9853364954080301, 0.1706223631796867, -1.3877787807814457e-17, -0.1706223631796867,
      -0.9853364954080303, 0.0, -1.3877787807814457e-17, -9.367506770274758e-17, 1.0},
     {73.68739417973941, 62.657790407626635, 35.0}},
    {"f-f:0:8;f-e:3:13",
     {-0.7071067811865479, -0.7071067811865475, 0.0, 0.7071067811865475, -0.7071067811865479, 0.0,
      0.0, 0.0, 1.0},
     {38.59518910292749, 82.61801433266893, 35.0}},
    {"f-f:1:7;f-f:3:8",
     {6.123233995736766e-17, -2.220446049250313e-16, -1.0, 1.0, 1.359631073446891e-32,
      6.123233995736766e-17, 0.0, -1.0, 2.220446049250313e-16},
     {35.00000000000001, 48.81278313935288, 35.0}},
    {"f-f:1:7;e-f:7:8",
     {2.220446049250313e-16, 0.0, -1.0, 0.9905728931686751, 0.13698665380043576,
      2.1995136671308372e-16, 0.13698665380043576, -0.9905728931686751, 3.0417147423119797e-17},
     {35.0, 45.95152353305607, 36.91339320453666}},
    {"f-f:1:8",
     {1.0000000000000002, -1.224646799147353e-16, 0.0, -1.2246467991473535e-16, -1.0,
      1.232595164407831e-32, 0.0, -1.232595164407831e-32, -1.0000000000000002},
     {114.57391414262597, 49.60365602226874, 35.000000000000014}},
    {"f-f:1:8;f-f:3:2",
     {1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0},
     {54.305736735713865, 35.0, 35.0}},
    {"f-f:1:8;f-f:5:2",
     {1.904841565079193e-17, 1.0, 1.1102230246251565e-16, 1.0000000000000004,
      -4.5736189654517455e-17, 4.930380657631324e-32, 1.9048415650792052e-17,
      1.1102230246251565e-16, -1.0000000000000004},
     {110.95680161397704, 35.00000000000001, 35.00000000000003}},
    {"f-f:2:8",
     {6.123233995736766e-17, -2.220446049250313e-16, 1.0, 1.0, 1.359631073446891e-32,
      -6.123233995736766e-17, 0.0, 1.0, 2.220446049250313e-16},
     {97.40445155054888, 44.820308355946864, 35.0}},
    {"f-f:3:8",
     {0.7071067811865476, 1.1102230246251565e-16, 0.7071067811865475, -0.7071067811865477,
      -5.551115123125783e-17, 0.7071067811865475, 5.551115123125783e-17, -1.0,
      5.551115123125783e-17},
     {42.73539368492308, 83.67489234443653, 34.99999999999999}},
    {"f-f:3:8;e-f:3:7",
     {-0.019676976383174876, 4.930380657631324e-32, 0.9998063895577066, -0.9998063895577065,
      1.1102230246251565e-16, -0.019676976383174886, -1.7308720336445528e-16, -1.0000000000000004,
      -2.261589041895112e-17},
     {35.29225048911322, 65.75679867805931, 35.00000000000003}},
    {"f-f:4:8",
     {-1.8374716891430261e-16, -0.5614308119748539, -0.8275236814528368, 1.2466268283769597e-16,
      -0.8275236814528368, 0.5614308119748539, -1.0, 0.0, 2.220446049250313e-16},
     {96.4984129645026, 74.97395974201312, 35.0}},
    {"f-f:5:8",
     {-1.1063709015797068e-16, -0.8670247010982287, 0.49826515800879273, 1.9251815721559955e-16,
      -0.49826515800879273, -0.8670247010982287, 1.0, 0.0, 2.220446049250313e-16},
     {116.09474358978994, 78.69578867913933, 35.0}},
    {"e-f:0:7",
     {0.0, 0.7071067811865476, 0.7071067811865476, 0.7071067811865476, 0.5, -0.5,
      -0.7071067811865476, 0.49999999999999994, -0.49999999999999994},
     {41.21320343559643, 46.48138212001735, 65.90927437709148}},
    {"e-f:0:7;v-f:2:8",
     {0.0, 0.7071067811865476, 0.7071067811865476, -0.9776492018291898, 0.14866411497524917,
      -0.14866411497524917, -0.21024280763619058, -0.6913023802350358, 0.6913023802350358},
     {41.21320343559643, 42.23128253244936, 43.89271352159393}},
    {"e-f:0:8",
     {0.009047398038667477, 0.032018905375932036, -0.9994463138594574, -0.9999590714567923,
      0.00028969963868269444, -0.009042758726706776, -1.0993810029003015e-16, 0.9994872214153848,
      0.03202021591672267},
     {36.85450739563752, 79.86870411367964, 35.472611559981615}},
    {"e-f:0:8;e-f:5:2",
     {-1.0, -1.2246467991473535e-16, -2.465190328815662e-32, 8.659560562354934e-17,
      -0.7071067811865477, 0.7071067811865477, -8.659560562354934e-17, 0.7071067811865475,
      0.7071067811865479},
     {48.50625107860529, 41.21320343559643, 41.21320343559643}},
    {"e-f:0:8;e-f:5:7",
     {-5.551115123125783e-17, -0.7071067811865476, 0.7071067811865477, 1.0, 6.123233995736766e-17,
      1.1102230246251565e-16, -1.6653345369377348e-16, 0.7071067811865476, 0.7071067811865477},
     {41.21320343559643, 63.74735098705716, 41.21320343559643}},
    {"e-f:1:2",
     {0.9904243250977524, -0.1101900249654898, -0.08317340111337632, 0.08368298543743341,
      1.1102230246251565e-16, 0.9964924274415126, -0.10980352545770179, -0.9939105384279338,
      0.009221030254537587},
     {134.30744225070913, 36.20263119318419, 86.83254496683662}},
    {"e-f:1:2;e-f:3:8",
     {6.123233995736766e-17, -1.0, -1.1102230246251565e-16, 0.7071067811865476,
      -5.551115123125783e-17, 0.7071067811865477, -0.7071067811865476, -1.6653345369377348e-16,
      0.7071067811865477},
     {105.25678269771662, 41.21320343559643, 41.21320343559643}},
    {"e-f:1:7;e-f:9:2",
     {0.7071067811865477, -1.6653345369377348e-16, 0.7071067811865476, 0.7071067811865477,
      -5.551115123125783e-17, -0.7071067811865476, 1.1102230246251565e-16, 1.0,
      6.123233995736766e-17},
     {41.21320343559643, 41.21320343559643, 95.68855485798314}},
    {"e-f:1:8",
     {-0.23718454720674803, -0.8666418268652026, 0.4389481000005288, 0.4119890954623294,
      -0.4989308007406882, -0.7624519927788159, 0.8797775149357145, -8.326672684688674e-17,
      0.47538565840119573},
     {88.07957709001113, 52.30418364132146, 40.32744760005366}},
    {"e-f:2:2;e-f:4:8",
     {6.123233995736766e-17, 1.1102230246251565e-16, 1.0, 0.7071067811865476, 0.7071067811865477,
      -1.6653345369377348e-16, -0.7071067811865476, 0.7071067811865477, -5.551115123125783e-17},
     {40.00185141054513, 41.21320343559643, 41.21320343559643}},
    {"e-f:2:7;e-f:7:8",
     {0.7071067811865476, 0.7071067811865476, 0.0, 1.1102230246251565e-16, -1.8369701987210297e-16,
      1.0, 0.7071067811865476, -0.7071067811865476, -2.220446049250313e-16},
     {41.21320343559643, 71.01306224939484, 41.21320343559643}},
    {"e-f:2:8",
     {-0.5578803207863637, 0.5578803207863637, -0.6144421009001645, -0.4344761761930151,
      0.4344761761930151, 0.7889619158371285, 0.7071067811865476, 0.7071067811865476, 0.0},
     {53.364752052941, 73.4723195768112, 41.21320343559643}},
    {"e-f:3:2",
     {0.6810859349069884, 0.2687822511695054, 0.6810859349069884, -0.7071067811865476, 0.0,
      0.7071067811865476, 0.19005775246454307, -0.9632009662870221, 0.19005775246454307},
     {66.37660196400509, 41.21320343559643, 79.13413858728056}},
    {"v-f:2:7;e-e:4:20",
     {-0.01897150768054346, -0.983639203720488, 0.17914798017407524, -0.9804559438107366,
      0.05339672454928777, 0.18935398610434676, -0.19582191946389643, -0.17205437138163984,
      -0.9654279202229149},
     {37.7263803736266, 37.72341849016255, 109.06005400889228}},
};

void check_known_poses(const Generated& g, const KnownPose* begin, const KnownPose* end) {
  for (const KnownPose* k = begin; k != end; ++k) {
    std::vector<Pc> pcs;
    std::stringstream ss(k->pcs);
    for (std::string item; std::getline(ss, item, ';');) pcs.push_back(*cf::pc_from_string(item));
    Pose p;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p.R_BA(r, c) = k->R[static_cast<std::size_t>(3 * r + c)];
    p.t_BA = Vec3(k->t[0], k->t[1], k->t[2]);
    check_hand_cf(g, PcSet(pcs), p);
  }
}

}  // namespace

// =======================================================================================
// 0. The oracle, as this file uses it (cfgen's models, kTouchTol), on poses whose answer is
//    known
// =======================================================================================

TEST_CASE("cfgen test oracle: contact analysis of known poses", "[cfgen][oracle]") {
  const Polyhedron A = load("cube.off"), B = load("l_block.off");
  const Oracle o(A, B);
  const int floor = face_with(B, Vec3::UnitY(), 20);
  const int bottom = cube_face(A, -Vec3::UnitY());
  auto at = [](const Mat3& R, const Vec3& t) {
    Pose p;
    p.R_BA = R;
    p.t_BA = t;
    return p;
  };
  // Flat on the floor, 20 mm from the wall: one f-f; the bottom face's edges and vertices
  // touch the floor too but are dominated.
  const Analysis flat = o.analyse(at(Mat3::Identity(), Vec3(70, 35, 40)));
  CHECK(flat.clean());
  CHECK(flat.pcs == PcSet({Pc{PcType::kFF, bottom, floor}}));
  CHECK(flat.v.touches.size() == 9);  // the face, its 4 edges, its 4 vertices
  // 1 micrometre into the floor, or above it.
  CHECK(o.analyse(at(Mat3::Identity(), Vec3(70, 35 - 1e-3, 40))).v.penetrating);
  CHECK_FALSE(o.analyse(at(Mat3::Identity(), Vec3(70, 35 + 1e-3, 40))).contact());
  // Against the wall as well (x = 20): two f-f, with distinct contact planes.
  const Analysis corner = o.analyse(at(Mat3::Identity(), Vec3(35, 35, 40)));
  CHECK(corner.clean());
  CHECK(corner.pcs ==
        PcSet({Pc{PcType::kFF, bottom, floor},
               Pc{PcType::kFF, cube_face(A, -Vec3::UnitX()), face_with(B, Vec3::UnitX(), 20)}}));
  // On an edge: 45 degrees about z, the lowest edge (along z) on the floor.
  const Mat3 Rz = axis_angle(Vec3::UnitZ(), M_PI / 4);
  const Analysis edge = o.analyse(at(Rz, Vec3(70, 20 + 15 * std::sqrt(2.0), 40)));
  CHECK(edge.clean());
  REQUIRE(edge.pcs.size() == 1);
  CHECK(edge.pcs[0].type == PcType::kEF);
  CHECK(edge.pcs[0].b == floor);
  // On a vertex: a generic tilt, the lowest vertex on the floor.
  const Mat3 Rg = axis_angle(Vec3(0.3, 0.5, 0.8), 0.4);
  int lo = 0;
  for (int v = 1; v < 8; ++v)
    if ((Rg * A.vertices()[v].p).y() < (Rg * A.vertices()[lo].p).y()) lo = v;
  const Analysis vertex = o.analyse(at(Rg, Vec3(70, 20 - (Rg * A.vertices()[lo].p).y(), 40)));
  CHECK(vertex.clean());
  CHECK(vertex.pcs == PcSet({Pc{PcType::kVF, lo, floor}}));
  // A vertex on a convex edge of B (the top edge of the floor's end, x = 120, y = 20), the
  // cube beyond the plane through the edge square to its bisector: a degenerate v-e touch.
  const Vec3 bis = Vec3(1, 1, 0).normalized();
  int ext = 0;
  for (int v = 1; v < 8; ++v)
    if ((Rg * A.vertices()[v].p).dot(bis) < (Rg * A.vertices()[ext].p).dot(bis)) ext = v;
  const Analysis ve = o.analyse(at(Rg, Vec3(120, 20, 40) - Rg * A.vertices()[ext].p));
  CHECK_FALSE(ve.v.penetrating);
  CHECK(degenerate_pcs(ve) == 1);
  CHECK_FALSE(ve.clean());
  // Edges crossing: the cube's lowest edge (along z, as above) across the floor's end edge
  // (along z too, so turn the cube 30 degrees about the bisector first).
  const Mat3 Rc = axis_angle(bis, 0.5) * align(Vec3(1, -1, 0).normalized(), -bis);
  int e_lo = 0;
  double best = 1e300;
  for (int e = 0; e < 12; ++e) {
    const double h =
        (Rc * (A.edge_point(cf::EdgeId(e), 0) + A.edge_point(cf::EdgeId(e), 1))).dot(bis);
    if (h < best) best = h, e_lo = e;
  }
  const Vec3 mid = 0.5 * (A.edge_point(cf::EdgeId(e_lo), 0) + A.edge_point(cf::EdgeId(e_lo), 1));
  const Analysis ee = o.analyse(at(Rc, Vec3(120, 20, 40) - Rc * mid));
  INFO(ee.describe());
  CHECK(ee.clean());
  REQUIRE(ee.pcs.size() == 1);
  CHECK(ee.pcs[0].type == PcType::kEE);
  CHECK(ee.pcs[0].a == e_lo);
  // The same pushed 1 micrometre further into B along the bisector: penetrating.
  CHECK(o.analyse(at(Rc, Vec3(120, 20, 40) - Rc * mid - 1e-3 * bis)).v.penetrating);
}

// =======================================================================================
// 1. Hand-derived cases
// =======================================================================================

TEST_CASE("cfgen: cube on a large box, every single-PC CF and nothing else", "[cfgen][hand]") {
  // B: a 200 mm box, A: the 30 mm cube. Both convex, all edges convex, all vertices pointed,
  // every B face much larger than the cube: every element pair is a valid one-PC CF.
  //   f-f 6 x 6 = 36     e-f 12 x 6 = 72    f-e 6 x 12 = 72
  //   v-f 8 x 6 = 48     f-v 6 x 8 = 48     e-e 12 x 12 = 144      total 420.
  // No CF of two or three PCs: two touching convex solids are separated by one plane that
  // holds every contact point; every PC's contact plane is then that plane (a face in contact
  // spans it; two edges crossing inside both lie in it), so two PCs never have distinct
  // planes. In particular no two PCs on the same face of B.
  const Generated& g = generated(
      "cube/big_box", [] { return load("cube.off"); }, big_box);
  WARN("cube vs 200 mm box: " << g.graph->num_cfs() << " CFs generated in " << g.seconds << " s");
  check_single_pcs(g, {{PcType::kFF, 36},
                       {PcType::kEF, 72},
                       {PcType::kFE, 72},
                       {PcType::kVF, 48},
                       {PcType::kFV, 48},
                       {PcType::kEE, 144}});
  CHECK(count_size(*g.graph, 2) == 0);
  CHECK(count_size(*g.graph, 3) == 0);
  std::size_t same_b_face = 0;
  for (std::size_t i = 0; i < g.graph->num_cfs(); ++i) {
    const PcSet& s = g.graph->cf(cf::CfId(static_cast<int>(i))).pcs;
    for (int x = 0; x < s.size(); ++x)
      for (int y = x + 1; y < s.size(); ++y)
        if (cf::b_kind(s[x].type) == K::kFace && cf::b_kind(s[y].type) == K::kFace &&
            s[x].b == s[y].b)
          ++same_b_face;
  }
  CHECK(same_b_face == 0);
  check_witnesses(g, "cube vs box");
}

TEST_CASE("cfgen: cube vs L-block", "[cfgen]") {
  const Generated& g = cube_l_block();
  const Polyhedron& A = *g.A;
  const Polyhedron& B = *g.B;
  WARN("cube vs L-block: " << g.graph->num_cfs() << " CFs (" << count_size(*g.graph, 1) << " + "
                           << count_size(*g.graph, 2) << " + " << count_size(*g.graph, 3) << "), "
                           << g.graph->num_transitions() << " transitions, generated in "
                           << g.seconds << " s");

  SECTION("hand-derived CFs") {
    // L-block: the L profile (0,0) (120,0) (120,20) (20,20) (20,80) (0,80) extruded 80 mm in z:
    // 12 vertices, 18 edges, 8 faces. One reflex edge, where the floor top (y = 20) meets the
    // wall's inner face (x = 20); its two end vertices have a 270-degree corner in the end
    // faces, so they are not pointed. Hence 17 convex edges and 10 pointed vertices, and
    // every B face is large enough for the cube to rest on it from outside:
    //   f-f 6 x 8 = 48     e-f 12 x 8 = 96    f-e 6 x 17 = 102
    //   v-f 8 x 8 = 64     f-v 6 x 10 = 60    e-e 12 x 17 = 204      total 574.
    check_single_pcs(g, {{PcType::kFF, 48},
                         {PcType::kEF, 96},
                         {PcType::kFE, 102},
                         {PcType::kVF, 64},
                         {PcType::kFV, 60},
                         {PcType::kEE, 204}});
    // {f-f, f-f}: the two cube faces must be adjacent (the cube's face normals are
    // perpendicular or opposite, and no two B faces face each other across a gap), and the
    // two B faces perpendicular with the cube touching both open faces from outside: only the
    // floor (y = 20) and the wall (x = 20) across the reflex edge. Any cube face on the floor
    // and any of its four neighbours on the wall: 6 x 4 = 24 CFs.
    const int floor = face_with(B, Vec3::UnitY(), 20), wall = face_with(B, Vec3::UnitX(), 20);
    std::set<std::vector<Pc>> expected;
    for (const Vec3& n1 : axes())
      for (const Vec3& n2 : axes()) {
        if (std::abs(n1.dot(n2)) > 0.5) continue;  // same or opposite
        const int a1 = cube_face(A, n1), a2 = cube_face(A, n2);
        const PcSet s({Pc{PcType::kFF, a1, floor}, Pc{PcType::kFF, a2, wall}});
        expected.insert({s.begin(), s.end()});
        // Independent witness: the cube in the corner, centred 15 mm off both faces.
        const Pose p = seat_pose({n1, n2}, {Vec3::UnitY(), Vec3::UnitX()}, Vec3(35, 35, 40));
        check_hand_cf(g, s, p);
      }
    CHECK(expected.size() == 24);
    const auto ff2 = all_ff(*g.graph, 2);
    std::set<std::vector<Pc>> got;
    for (const PcSet& s : ff2) got.insert({s.begin(), s.end()});
    CHECK(got == expected);
    // Opposite cube faces on two B faces never: checked over every two-PC f-f CF.
    for (const PcSet& s : ff2)
      CHECK(A.faces()[static_cast<std::size_t>(s[0].a)].normal.dot(
                A.faces()[static_cast<std::size_t>(s[1].a)].normal) > -0.5);
    // docs/spec.md, section 4: the L-block is the union of two convex pieces and the cube is
    // convex, so all PCs with one piece share a plane: no three-PC CF.
    CHECK(count_size(*g.graph, 3) == 0);
  }
  SECTION("witnesses") { check_witnesses(g, "cube vs L-block"); }
  SECTION("recall") {
    check_known_poses(g, std::begin(kKnownLBlock), std::end(kKnownLBlock));
    check_recall(g, "cube vs L-block", 2000, 20240611u);
  }
  SECTION("transitions") { check_transitions(g, "cube vs L-block"); }
  SECTION("determinism: 1 and 2 threads give the same bytes") {
    // The whole enumeration (all levels) in process: the graph's bytes must not depend on the
    // thread count (the cached graph was generated with 2 threads).
    cf::gen::EnumerateOptions opt;
    cf::gen::ExecuteOptions exec;
    exec.threads = 1;
    const cf::gen::Enumeration e1 = cf::gen::enumerate_pair(g.ai, g.bi, {}, opt, exec);
    const cf::CfGraph g1 = cf::CfGraph::from_parts(A, B, e1.cfs, e1.transitions);
    CHECK(g1.num_cfs() == g.graph->num_cfs());
    CHECK(g1.to_json(1) == g.graph->to_json(1));
    // And the file cfgen writes (metadata included), through its own entry point; one PC
    // keeps this part short.
    const fs::path dir =
        fs::temp_directory_path() / ("cf_cfgen_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::string bytes[2];
    for (int threads = 1; threads <= 2; ++threads) {
      cf::tools::GenerateArgs args;
      args.a_path = kModels + "cube.off";
      args.b_path = kModels + "l_block.off";
      args.out_path = (dir / ("g" + std::to_string(threads) + ".json")).string();
      args.threads = threads;
      args.max_pcs = 1;
      args.quiet = true;
      REQUIRE(cf::tools::run_generate(args) == 0);
      std::ifstream in(args.out_path, std::ios::binary);
      std::ostringstream os;
      os << in.rdbuf();
      bytes[threads - 1] = os.str();
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    CHECK(bytes[0].size() > 10000);
    CHECK(bytes[0] == bytes[1]);
  }
}

TEST_CASE("cfgen: cube vs corner block", "[cfgen]") {
  const Generated& g = cube_corner_block();
  const Polyhedron& A = *g.A;
  const Polyhedron& B = *g.B;
  WARN("cube vs corner block: " << g.graph->num_cfs() << " CFs (" << count_size(*g.graph, 1)
                                << " + " << count_size(*g.graph, 2) << " + "
                                << count_size(*g.graph, 3) << "), " << g.graph->num_transitions()
                                << " transitions, generated in " << g.seconds << " s");

  SECTION("hand-derived CFs") {
    // Corner block: floor 120 x 20 x 120 with walls 20 thick, 80 high along x = 0 and z = 0.
    // 14 vertices, 9 faces, 14 + 9 - 2 = 21 edges. Three reflex edges meet at (20,20,20):
    // floor top (y = 20) / x-wall (x = 20), floor top / z-wall (z = 20), x-wall / z-wall.
    // Their four end vertices are not pointed; 18 convex edges, 10 pointed vertices. Every
    // face takes the cube from outside (the inner faces are 100 x 100, 100 x 60, 100 x 60):
    //   f-f 6 x 9 = 54     e-f 12 x 9 = 108   f-e 6 x 18 = 108
    //   v-f 8 x 9 = 72     f-v 6 x 10 = 60    e-e 12 x 18 = 216      total 618.
    check_single_pcs(g, {{PcType::kFF, 54},
                         {PcType::kEF, 108},
                         {PcType::kFE, 108},
                         {PcType::kVF, 72},
                         {PcType::kFV, 60},
                         {PcType::kEE, 216}});
    const int floor = face_with(B, Vec3::UnitY(), 20), xwall = face_with(B, Vec3::UnitX(), 20),
              zwall = face_with(B, Vec3::UnitZ(), 20);
    const int inner[3] = {floor, xwall, zwall};
    const Vec3 inner_n[3] = {Vec3::UnitY(), Vec3::UnitX(), Vec3::UnitZ()};
    // One f-f on each inner face, with a hand-made witness (cube centred 15 mm off the face,
    // 35 mm from the other two): all six cube faces on each.
    for (int k = 0; k < 3; ++k)
      for (const Vec3& n1 : axes()) {
        const Vec3 other = std::abs(n1.dot(Vec3::UnitX())) < 0.5 ? Vec3::UnitX() : Vec3::UnitY();
        Vec3 center = Vec3(70, 50, 70);
        center(k == 0 ? 1 : k == 1 ? 0 : 2) = 35;
        // Any rotation taking n1 to -inner_n[k]; the second pair only fixes the spin.
        const Vec3 spin_to = inner_n[(k + 1) % 3];
        const Pose p = seat_pose({n1, other}, {inner_n[k], spin_to}, center);
        const PcSet s({Pc{PcType::kFF, cube_face(A, n1), inner[k]}});
        check_hand_cf(g, s, p);
      }
    // {f-f, f-f}: two adjacent cube faces on two of the three inner faces (the only pairs of
    // B faces across a reflex edge): 3 face pairs x 6 x 4 = 72.
    std::set<std::vector<Pc>> expected2, expected3;
    for (int k1 = 0; k1 < 3; ++k1)
      for (int k2 = k1 + 1; k2 < 3; ++k2)
        for (const Vec3& n1 : axes())
          for (const Vec3& n2 : axes()) {
            if (std::abs(n1.dot(n2)) > 0.5) continue;
            const PcSet s({Pc{PcType::kFF, cube_face(A, n1), inner[k1]},
                           Pc{PcType::kFF, cube_face(A, n2), inner[k2]}});
            expected2.insert({s.begin(), s.end()});
            // Centre: 35 along the axes of the two faces (15 mm off each), 50 along the third
            // (15 mm clear of the third inner face, below the walls' top at y = 80).
            const int ax1 = k1 == 0 ? 1 : k1 == 1 ? 0 : 2, ax2 = k2 == 0 ? 1 : k2 == 1 ? 0 : 2;
            Vec3 center(50, 50, 50);
            center(ax1) = 35;
            center(ax2) = 35;
            const Pose p = seat_pose({n1, n2}, {inner_n[k1], inner_n[k2]}, center);
            check_hand_cf(g, s, p);
          }
    CHECK(expected2.size() == 72);
    // The seat: three mutually adjacent cube faces on floor, x-wall and z-wall. The map of
    // their normals to the three inward normals must be a proper rotation: of the 6 x 4 x 2 =
    // 48 ordered triples of perpendicular cube normals, the 24 with det = det(-y, -x, -z) =
    // +1 (= 8 cube corners x 3 rotations about the corner's diagonal).
    for (const Vec3& n1 : axes())
      for (const Vec3& n2 : axes())
        for (const Vec3& n3 : axes()) {
          if (std::abs(n1.dot(n2)) > 0.5 || std::abs(n1.dot(n3)) > 0.5 ||
              std::abs(n2.dot(n3)) > 0.5)
            continue;
          Mat3 S;
          S << n1, n2, n3;
          if (S.determinant() < 0) continue;  // det(-y, -x, -z) = +1
          const PcSet s({Pc{PcType::kFF, cube_face(A, n1), floor},
                         Pc{PcType::kFF, cube_face(A, n2), xwall},
                         Pc{PcType::kFF, cube_face(A, n3), zwall}});
          expected3.insert({s.begin(), s.end()});
          const Pose p = seat_pose({n1, n2}, {Vec3::UnitY(), Vec3::UnitX()}, Vec3(35, 35, 35));
          check_hand_cf(g, s, p);
        }
    CHECK(expected3.size() == 24);
    std::set<std::vector<Pc>> got2, got3;
    for (const PcSet& s : all_ff(*g.graph, 2)) got2.insert({s.begin(), s.end()});
    for (const PcSet& s : all_ff(*g.graph, 3)) got3.insert({s.begin(), s.end()});
    CHECK(got2 == expected2);
    CHECK(got3 == expected3);
    WARN("corner block: " << got3.size() << " three-f-f CFs (seat) in the graph, 24 derived; "
                          << got2.size() << " two-f-f CFs, 72 derived");
  }
  SECTION("witnesses") { check_witnesses(g, "cube vs corner block"); }
  SECTION("recall") {
    check_known_poses(g, std::begin(kKnownCornerBlock), std::end(kKnownCornerBlock));
    check_recall(g, "cube vs corner block", 2000, 77u);
  }
  SECTION("transitions") { check_transitions(g, "cube vs corner block"); }
}

TEST_CASE("cfgen: cube in a U-channel wider than the cube", "[cfgen][hand]") {
  // B: the U-channel; its slot's inner walls (x = 20, normal +x; x = 60, normal -x) face
  // each other 40 mm apart, more than the 30 mm cube. Enumerating all its two-PC sets takes
  // longer than this test's budget, so the graph is generated with one PC, and the two-PC
  // cases below ask the generator's witness search directly (as enumerate() does, seeded
  // with the one-PC witnesses).
  const Generated& g = generated(
      "cube/u_channel", [] { return load("cube.off"); }, u_channel, 1);
  const Polyhedron& A = *g.A;
  const Polyhedron& B = *g.B;
  WARN("cube vs U-channel (one PC): " << g.graph->num_cfs() << " CFs, generated in " << g.seconds
                                      << " s");
  // One PC: 16 vertices, 24 edges, 10 faces; the two reflex edges run along the slot's
  // bottom corners and their four end vertices are not pointed: 22 convex edges, 12 pointed
  // vertices. Every face takes the cube from outside (inside the slot the cube is 30 mm in
  // a 40 mm gap; an edge or vertex down needs only a small tilt):
  //   f-f 6 x 10 = 60    e-f 12 x 10 = 120  f-e 6 x 22 = 132
  //   v-f 8 x 10 = 80    f-v 6 x 12 = 72    e-e 12 x 22 = 264      total 728.
  check_single_pcs(g, {{PcType::kFF, 60},
                       {PcType::kEF, 120},
                       {PcType::kFE, 132},
                       {PcType::kVF, 80},
                       {PcType::kFV, 72},
                       {PcType::kEE, 264}});
  const int left = face_with(B, Vec3::UnitX(), 20), right = face_with(B, -Vec3::UnitX(), -60),
            floor = face_with(B, Vec3::UnitY(), 20), front = face_with(B, -Vec3::UnitZ(), 0);
  // Hand witnesses inside the slot.
  // The cube flat on the slot floor (5 mm clear of each wall), each face down.
  for (const Vec3& n : axes()) {
    const Vec3 other = std::abs(n.dot(Vec3::UnitX())) < 0.5 ? Vec3::UnitX() : Vec3::UnitZ();
    const Pose p = seat_pose({n, other}, {Vec3::UnitY(), Vec3::UnitX()}, Vec3(40, 35, 40));
    check_hand_cf(g, PcSet({Pc{PcType::kFF, cube_face(A, n), floor}}), p);
  }
  // The cube tilted by 0.15 rad about a generic axis: its lowest vertex on the slot floor, or
  // its leftmost vertex on the left wall (its width grows to about 36 mm, still clear).
  {
    const Mat3 R = axis_angle(Vec3(0.3, 0.5, 0.8), 0.15);
    int lo = 0, lx = 0;
    for (int v = 0; v < 8; ++v) {
      if ((R * A.vertices()[v].p).y() < (R * A.vertices()[lo].p).y()) lo = v;
      if ((R * A.vertices()[v].p).x() < (R * A.vertices()[lx].p).x()) lx = v;
    }
    Pose p;
    p.R_BA = R;
    p.t_BA = Vec3(40, 20 - (R * A.vertices()[lo].p).y(), 40);
    check_hand_cf(g, PcSet({Pc{PcType::kVF, lo, floor}}), p);
    p.t_BA = Vec3(20 - (R * A.vertices()[lx].p).x(), 50, 40);
    check_hand_cf(g, PcSet({Pc{PcType::kVF, lx, left}}), p);
  }
  // A cube face on the slot floor's front edge (y = 20, z = 0, x in 20..60), the face
  // tilted 45 degrees between the floor and the front face, cube edges along x: the cube
  // spans x in 25..55 and lies beyond the plane y - z = 20, which B does not cross there.
  int front_edge = -1;
  for (std::size_t e = 0; e < B.num_edges(); ++e) {
    const cf::Edge& E = B.edges()[e];
    if ((E.left.value() == floor && E.right.value() == front) ||
        (E.left.value() == front && E.right.value() == floor))
      front_edge = static_cast<int>(e);
  }
  REQUIRE(front_edge >= 0);
  const Vec3 m = Vec3(0, 1, -1).normalized();
  for (const Vec3& n : axes()) {
    const Vec3 other = std::abs(n.dot(Vec3::UnitX())) < 0.5 ? Vec3::UnitX() : Vec3::UnitY();
    const Pose p = seat_pose({n, other}, {m, Vec3::UnitX()}, Vec3(40, 20, 0) + 15 * m);
    check_hand_cf(g, PcSet({Pc{PcType::kFE, cube_face(A, n), front_edge}}), p);
  }

  // Two PCs. Opposite cube faces (30 mm apart) can never lie on both walls (40 mm apart):
  // the search must find no witness for {f-f(a, left wall), f-f(opposite of a, right wall)}.
  // Across the slot's two reflex edges, floor (y = 20) with either wall, with adjacent cube
  // faces: 2 x 6 x 4 = 48 CFs that must be found, with witnesses the oracle confirms.
  const cf::gen::WitnessSearch search(g.ai, g.bi, cf::gen::SearchParams{});
  auto seeds = [&](const PcSet& s) {
    std::vector<Mat3> out;
    for (const Pc& pc : s)
      if (const auto id = g.graph->find(PcSet({pc}))) out.push_back(g.graph->cf(*id).witness.R_BA);
    return out;
  };
  for (const Vec3& n : axes()) {
    const PcSet s(
        {Pc{PcType::kFF, cube_face(A, n), left}, Pc{PcType::kFF, cube_face(A, -n), right}});
    const cf::gen::Witness w = search.find(s, seeds(s));
    INFO("{" << cf::to_string(s) << "} cannot be realised (walls 40 mm apart); a claimed witness: "
             << pose_str(w.pose) << ": " << g.oracle->analyse(w.pose).describe());
    CHECK_FALSE(w.found);
  }
  int found = 0;
  for (int side = 0; side < 2; ++side)
    for (const Vec3& n1 : axes())
      for (const Vec3& n2 : axes()) {
        if (std::abs(n1.dot(n2)) > 0.5) continue;
        const int wall = side == 0 ? left : right;
        const PcSet s(
            {Pc{PcType::kFF, cube_face(A, n1), floor}, Pc{PcType::kFF, cube_face(A, n2), wall}});
        // A hand-made witness first: the cube in the slot's corner.
        const Vec3 wn = side == 0 ? Vec3(Vec3::UnitX()) : Vec3(-Vec3::UnitX());
        const Pose p = seat_pose({n1, n2}, {Vec3::UnitY(), wn}, Vec3(side == 0 ? 35 : 45, 35, 40));
        const Analysis hand = g.oracle->analyse(p);
        INFO("hand witness for {" << cf::to_string(s) << "}: " << pose_str(p) << ": "
                                  << hand.describe());
        CHECK(hand.clean());
        CHECK(hand.pcs == s);
        const cf::gen::Witness w = search.find(s, seeds(s));
        INFO("cfgen's witness search for {" << cf::to_string(s) << "}");
        CHECK(w.found);
        if (!w.found) continue;
        ++found;
        const Analysis an = g.oracle->analyse(w.pose);
        INFO("its witness " << pose_str(w.pose) << ": " << an.describe());
        CHECK(an.clean());
        CHECK(an.pcs == s);
      }
  CHECK(found == 48);
  check_witnesses(g, "cube vs U-channel");
}

TEST_CASE("cfgen: cube in a slot exactly its width, whose faces never touch one wall alone",
          "[cfgen][hand]") {
  // The U-channel's slot is 30 mm wide (walls x = 20, normal +x, and x = 50, normal -x; floor
  // y = 20), the cube's width: whenever a cube face lies on one wall, the opposite face lies
  // on the other. No single PC of a face on a wall is a CF, nor a face on the floor with a
  // face on one wall; the CFs of faces on the walls are the cube held between both, lifted
  // or on the floor. (A face on the floor alone is a CF: the cube turned about the vertical,
  // over the slot's open end.) Levels that pair only valid sets never propose them: a set is
  // a candidate when its subsets are valid or open (failed, no rule refutes them).
  const Generated& g = generated(
      "cube/exact_slot", [] { return load("cube.off"); },
      [] { return cf::test::from_oracle(oracle::make_u_channel(30, 20, 20, 80, 80), "slot"); });
  const Polyhedron& A = *g.A;
  const Polyhedron& B = *g.B;
  const int left = face_with(B, Vec3::UnitX(), 20), right = face_with(B, -Vec3::UnitX(), -50),
            floor = face_with(B, Vec3::UnitY(), 20);
  std::set<std::vector<Pc>> want2, want3, got2, got3;
  for (const Vec3& a : axes()) {
    const Pc l{PcType::kFF, cube_face(A, a), left}, r{PcType::kFF, cube_face(A, -a), right};
    const PcSet walls({l, r});
    want2.insert({walls.begin(), walls.end()});
    for (const Vec3& b : axes()) {
      if (std::abs(a.dot(b)) > 0.5) continue;
      const PcSet seat({l, r, Pc{PcType::kFF, cube_face(A, b), floor}});
      want3.insert({seat.begin(), seat.end()});
    }
  }
  REQUIRE(want2.size() == 6);   // 3 axes across the slot, each either way
  REQUIRE(want3.size() == 24);  // and 4 faces down for each
  auto wall = [&](const Pc& pc) { return pc.b == left || pc.b == right; };
  for (std::size_t i = 0; i < g.graph->num_cfs(); ++i) {
    const PcSet& s = g.graph->cf(cf::CfId(static_cast<int>(i))).pcs;
    int on_walls = 0;
    bool ff_inside = true;
    for (const Pc& pc : s) {
      on_walls += pc.type == PcType::kFF && wall(pc);
      ff_inside = ff_inside && pc.type == PcType::kFF && (wall(pc) || pc.b == floor);
    }
    INFO("CF {" << cf::to_string(s) << "}");
    CHECK(on_walls != 1);  // a face on one wall has the opposite face on the other
    if (on_walls == 2 && ff_inside) (s.size() == 2 ? got2 : got3).insert({s.begin(), s.end()});
  }
  CHECK(got2 == want2);
  CHECK(got3 == want3);
  check_witnesses(g, "cube in an exact slot");
}

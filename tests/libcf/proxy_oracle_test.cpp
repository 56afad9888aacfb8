// The proxy (docs/spec.md, section 6b) checked against the independent oracle (tests/oracle).
//
// The recall test keeps, for each fixed seed, the generated pair, cfgen's graph and
// samples.csv: poses where the oracle realised a CF of the graph by exact first contacts
// (tests/oracle/README.md). From a deterministic selection of those poses this test pushes the
// device pose (translation only, A's rotation fixed) into B and out again, and checks what the
// run time renders with its default parameters (proxy on) with the oracle's geometry only:
//
//  - every tick where the device pose penetrates B (the oracle's exact interior test) renders
//    a CF (HapticResult::cf valid);
//  - the proxy pose X_WP never penetrates B by more than ProxyParams::penetration_tolerance_mm
//    (plus a numerical tolerance), measured here with the oracle's polyhedra: depth of A's
//    vertices inside B, of B's vertices inside A, and of crossing edge pairs (below);
//  - the rendered force along the push direction (out of B, against the device's motion) at
//    the end of each hold grows strictly with the depth of the device (1 < 3 < 6 mm), on the
//    runs where the proxy did not turn by more than kTipRad. A push whose line passes beside
//    the support tips A over its edge (the proxy turns, its CF changes): there the push along
//    the first normal falls, as for a part pushed off a ledge. The hand holds A at the middle
//    of the contact's corners (as the oracle sees them); the count of turned runs is printed
//    (13 of 160 today: docs/force-model.md, "The proxy", Limits);
//  - after pulling out to 10 mm outside, X_WP is X_WD exactly and F_W is gravity alone. (Not
//    3 mm: a proxy tipped onto B's side face can stay wedged there by friction under the
//    coupling's torque until the hand pulls far enough to overcome it, as a real part would.)
//
// Nothing of libcf's implementation is used to choose the motions or to measure: the push
// direction, the slide direction, the free approach and the free end pose all come from the
// oracle. libcf is only the code under test (cf::step on a CfModel/CfState, public API).
//
// The selected poses are independent of the results: up to 20 per pair with
// free_clearance_mm >= 1, by a fixed stride over the file; a pose is skipped (and the next one
// in stride order taken) only when the oracle finds no push direction that presses every PC,
// B in the way of the approach, or no slide direction whose end pose is clear of B.
//
// Environment: CF_PROXY_ORACLE_VERBOSE=1 also prints the skipped poses and where the deepest
// proxy was; CF_PROXY_ORACLE_TRACE=seed_N:row prints every tick of one run (row: 1-based data
// row of samples.csv, as in the failure lines).

#include <cf/graph.hpp>
#include <cf/model.hpp>
#include <cf/params.hpp>
#include <cf/servo.hpp>
#include <cf/state.hpp>

#include "classify.hpp"
#include "graph.hpp"
#include "motion.hpp"
#include "oracle_kept.hpp"
#include "oracle_pose.hpp"
#include "pc_lists.hpp"
#include "poly.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// ---- the motion ----------------------------------------------------------------------------

constexpr int kMaxSamplesPerPair = 20;  // the brief: up to 20 poses per pair
// Only poses where nothing but the CF's own PCs is within 1 mm (the oracle's
// free_clearance_mm): the push then starts from an unambiguous contact.
constexpr double kMinFreeClearanceMm = 1.0;
constexpr double kStepMm = 0.02;         // 20 um per tick
constexpr double kTickS = 1e-3;          // 1 kHz servo
constexpr double kStartOutsideMm = 2.0;  // device starts 2 mm outside along the push direction
constexpr double kHoldDepthsMm[3] = {1.0, 3.0, 6.0};  // past the touching pose
constexpr int kHoldTicks = 20;
constexpr double kSlideMm = 3.0;        // sideways while pressed 6 mm in
constexpr double kEndOutsideMm = 10.0;  // pulled out to 10 mm outside (see the header)
constexpr int kEndHoldTicks = 20;       // ticks at the final pose; the last one is checked
// rad. A proxy turned more than this from the device at a hold has tipped over the support's
// edge: the push is then not expected to grow along the first normal. Pushes that keep their
// support turn the proxy by a few milliradians (the coupling's moment against the PCs'
// lever arms); 0.05 rad (3 degrees) is far above that and far below a tip onto a side face.
constexpr double kTipRad = 0.05;

// ---- choosing the motion with the oracle -----------------------------------------------------

// Each PC's into-B direction must make at least this cosine with the push direction, so that
// the push presses every PC of the CF (and is not a slide along one of its contact planes,
// where "depth past the touching pose" would not press that PC at all).
constexpr double kMinPushCos = 0.2;
// Sign of an e-e normal: |n . (interior of B - interior of A)| below this (unit vectors) would
// leave the orientation to rounding; such a pose is skipped.
constexpr double kMinEeSideDot = 1e-6;
// The sum of the PCs' unit into-B directions shorter than this: they (nearly) cancel (A wedged
// between opposite walls) and no push direction presses them all.
constexpr double kMinNormalSum = 1e-6;
// Probe step of the oracle's penetration test along +-d at the sample pose: far above the
// oracle's length tolerance (1e-7 of the smaller model's diagonal, below 1e-5 mm here) and far
// below the 1 mm free clearance, so that only the CF's own contacts decide.
constexpr double kProbeMm = 1e-3;
// The end pose must be farther than epsilon from B (oracle clearance) by this margin, so that
// no contact is within the detection band there and the force must be gravity only. The
// oracle's distances are exact to rounding (~1e-12 mm); 1e-3 mm is far above that.
constexpr double kEndClearanceMarginMm = 1e-3;

// ---- checks -------------------------------------------------------------------------------------

// Added to ProxyParams::penetration_tolerance_mm (0.01 mm) when checking the proxy's depth: the
// oracle's depths and the library's poses are exact to double rounding at coordinates of at
// most ~100 mm (~1e-13 mm); 1e-6 mm is far above that and four orders below the bound itself.
constexpr double kProxyDepthNumTolMm = 1e-6;
// The brief's tolerance on the gravity-only force after pulling out: F_W = (0, -m g, 0) is
// a sum of exactly representable terms when nothing is in contact and the coupling is zero.
constexpr double kGravityTolN = 1e-9;

// ---- the oracle's depth measure -------------------------------------------------------------

// Feasibility slack of the normal-cone tests of the e-e depth (dot products of unit vectors):
// n exactly on a cone's boundary (a face normal) must count, rounding must not flip it.
constexpr double kConeSlack = 1e-9;
// e-e pairs nearer to parallel than this sine have no single crossing point; their depth is
// that of the vertices or faces around them.
constexpr double kMinEeSin = 1e-3;
// An e-e crossing counts only when the closest points are inside both open segments, at least
// this far (as a share of the segment) from an end; at an end the vertex measures apply.
constexpr double kSegInterior = 1e-9;
// An e-e pair measures a local crossing only: deeper than this it is a distant pair whose
// supporting planes happen to cross (a proxy this deep would show in the vertex depths too).
constexpr double kEeLocalMm = 1.0;

using cf::test::to_cf;
using cf::test::to_oracle;

double dist_to_surface(const oracle::Poly& P, const oracle::Vec3& x) {
  double best = oracle::kInf;
  for (const oracle::Face& f : P.F) best = std::min(best, oracle::point_face_dist(P, f, x));
  return best;
}

/// How deep A at pose X penetrates B, by the oracle's own polyhedra: the largest of
///  - a vertex of A strictly inside B: its distance to B's surface (v-f);
///  - a vertex of B strictly inside A: its distance to A's surface (f-v);
///  - two convex edges crossing (not near parallel, closest points inside both segments) whose
///    common normal n is in B's edge's outward normal cone with -n in A's (the pair supports a
///    plane between the two solids locally): -n.(p_A - p_B) when positive, the midpoint of the
///    closest points inside both solids and the depth local (e-e).
/// 0 when none. These are the three point-contact kinds whose depth bounds how far A has to
/// move to leave B locally.
double oracle_depth(const oracle::Poly& A, const oracle::Poly& B, const oracle::Pose& X,
                    std::string* what) {
  double depth = 0;
  auto take = [&](double d, const std::string& w) {
    if (d > depth) {
      depth = d;
      if (what) *what = w;
    }
  };
  std::vector<oracle::Vec3> pa(A.V.size());
  for (std::size_t i = 0; i < A.V.size(); ++i) pa[i] = X.apply(A.V[i].p);
  for (std::size_t i = 0; i < A.V.size(); ++i)
    if (oracle::point_in_solid(B, pa[i]))
      take(dist_to_surface(B, pa[i]), "A vertex " + std::to_string(i) + " in B");
  for (std::size_t j = 0; j < B.V.size(); ++j) {
    const oracle::Vec3 y = X.inv(B.V[j].p);
    if (oracle::point_in_solid(A, y))
      take(dist_to_surface(A, y), "B vertex " + std::to_string(j) + " in A");
  }
  for (std::size_t ea = 0; ea < A.E.size(); ++ea) {
    const oracle::Edge& EA = A.E[ea];
    if (!EA.convex) continue;
    const oracle::Vec3& a0 = pa[EA.v0];
    const oracle::Vec3& a1 = pa[EA.v1];
    const oracle::Vec3 ma0 = X.R * EA.m[0], ma1 = X.R * EA.m[1];
    for (std::size_t eb = 0; eb < B.E.size(); ++eb) {
      const oracle::Edge& EB = B.E[eb];
      if (!EB.convex) continue;
      const oracle::Vec3& b0 = B.V[EB.v0].p;
      const oracle::Vec3& b1 = B.V[EB.v1].p;
      oracle::Vec3 n = (a1 - a0).cross(b1 - b0);
      const double len = n.norm();
      if (len < kMinEeSin * (a1 - a0).norm() * (b1 - b0).norm()) continue;
      n /= len;
      double s = 0, t = 0;
      const double dist = oracle::seg_seg_dist(a0, a1, b0, b1, &s, &t);
      if (dist > kEeLocalMm) continue;
      if (s <= kSegInterior || s >= 1 - kSegInterior || t <= kSegInterior || t >= 1 - kSegInterior)
        continue;
      // n outward from B at its edge: n . m <= 0 for both in-face directions of B's wedge.
      if (n.dot(EB.m[0]) > kConeSlack || n.dot(EB.m[1]) > kConeSlack) n = -n;
      if (n.dot(EB.m[0]) > kConeSlack || n.dot(EB.m[1]) > kConeSlack) continue;
      // -n outward from A at its edge: (-n) . m <= 0 for A's in-face directions.
      if (-n.dot(ma0) > kConeSlack || -n.dot(ma1) > kConeSlack) continue;
      const oracle::Vec3 p = a0 + s * (a1 - a0), q = b0 + t * (b1 - b0);
      const double sigma = n.dot(p - q);  // < 0: A's edge is below B's supporting plane
      if (sigma >= 0) continue;
      const oracle::Vec3 mid = 0.5 * (p + q);
      if (!oracle::point_in_solid(B, mid) || !oracle::point_in_solid(A, X.inv(mid))) continue;
      take(-sigma, "A edge " + std::to_string(ea) + " x B edge " + std::to_string(eb));
    }
  }
  return depth;
}

// ---- samples --------------------------------------------------------------------------------

struct Sample {
  int row = 0;  // 1-based data row of samples.csv
  std::string pcs;
  double free_mm = 0;
  oracle::Pose X;
};

std::vector<Sample> read_samples(const fs::path& file) {
  std::vector<Sample> out;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  int row = 0;
  while (std::getline(in, line)) {
    ++row;
    std::vector<std::string> f;
    std::string cell;
    std::istringstream ls(line);
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    REQUIRE(f.size() == 14);
    Sample s;
    s.row = row;
    s.pcs = f[0];
    s.free_mm = std::stod(f[1]);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        s.X.R(i, j) = std::stod(f[static_cast<std::size_t>(2 + 3 * i + j)]);
      s.X.t(i) = std::stod(f[static_cast<std::size_t>(11 + i)]);
    }
    out.push_back(s);
  }
  return out;
}

oracle::Pose translated(const oracle::Pose& X, const oracle::Vec3& v) {
  oracle::Pose Y = X;
  Y.t += v;
  return Y;
}

/// The push direction d (unit, A's motion into B) and the slide direction p (unit, d . p = 0)
/// for a sample, from the oracle alone; false with the reason when the pose does not suit.
bool plan(const oracle::Classifier& C, double epsilon_mm, const Sample& s, oracle::Vec3* d_out,
          oracle::Vec3* p_out, std::string* why) {
  const oracle::Poly& A = C.A();
  const oracle::Poly& B = C.B();
  const oracle::Verdict V = C.classify(s.X, false);
  if (!V.valid_cf()) {
    *why = "oracle: not a valid CF at the sample pose (" + V.describe() + ")";
    return false;
  }
  std::vector<oracle::Vec3> into;  // per PC: the direction that moves A into B there
  for (int k : V.pcs) {
    const oracle::Touch& t = V.touches[static_cast<std::size_t>(k)];
    oracle::Vec3 u;
    switch (t.type) {
      case oracle::PcType::VF:
      case oracle::PcType::EF:
      case oracle::PcType::FF:
        u = -t.normal;  // B's face's outward normal
        break;
      case oracle::PcType::FV:
      case oracle::PcType::FE:
        u = t.normal;  // A's face's outward normal (world)
        break;
      case oracle::PcType::EE: {
        // Interior sides of the two wedges: the sum of the in-face directions points into the
        // solid at a convex edge and out of it at a reflex one.
        const oracle::Edge& EA = A.E[static_cast<std::size_t>(t.a)];
        const oracle::Edge& EB = B.E[static_cast<std::size_t>(t.b)];
        const oracle::Vec3 a_in = (EA.convex ? 1.0 : -1.0) * (s.X.R * (EA.m[0] + EA.m[1]));
        const oracle::Vec3 b_in = (EB.convex ? 1.0 : -1.0) * (EB.m[0] + EB.m[1]);
        const double side = t.normal.dot(b_in - a_in);
        if (std::abs(side) < kMinEeSideDot) {
          *why = "e-e normal of unclear sign";
          return false;
        }
        u = side > 0 ? t.normal : oracle::Vec3(-t.normal);
        break;
      }
      default:
        *why = "degenerate PC";
        return false;
    }
    into.push_back(u.normalized());
  }
  oracle::Vec3 sum = oracle::Vec3::Zero();
  for (const oracle::Vec3& u : into) sum += u;
  if (sum.norm() < kMinNormalSum) {
    *why = "the PCs' normals cancel (opposite walls)";
    return false;
  }
  const oracle::Vec3 d = sum.normalized();
  for (const oracle::Vec3& u : into)
    if (d.dot(u) < kMinPushCos) {
      *why = "no direction presses every PC (cos " + std::to_string(d.dot(u)) + ")";
      return false;
    }
  // The sign, by the oracle's penetration test on a small step each way.
  if (C.interiors_disjoint(translated(s.X, kProbeMm * d))) {
    *why = "a small step along d does not penetrate";
    return false;
  }
  if (!C.interiors_disjoint(translated(s.X, -kProbeMm * d))) {
    *why = "a small step against d penetrates";
    return false;
  }
  // The approach: nothing of B within kStartOutsideMm behind the contact along -d. The time of
  // impact starts from the pose lifted by the probe step (free, checked above), where the CF's
  // own contacts no longer hold: coplanar edges at the start give spurious zero-time events.
  const oracle::Pose lifted = translated(s.X, -kProbeMm * d);
  oracle::Motion back;
  back.u = -d;
  if (std::isfinite(
          oracle::time_of_impact(A, B, lifted, back, kStartOutsideMm - kProbeMm, C.tol().len))) {
    *why = "B is in the way of the approach";
    return false;
  }
  // The slide: the first of four perpendicular directions whose end pose (slid, pulled out) is
  // farther than epsilon from B, reached from the lifted pose by a straight free translation
  // (so that the proxy has a way out; a proxy blocked by a feature of B may not follow).
  const oracle::Vec3 p1 = oracle::any_perp(d), p2 = d.cross(p1).normalized();
  const oracle::Vec3 cands[4] = {p1, -p1, p2, -p2};
  std::string tried;
  for (const oracle::Vec3& p : cands) {
    const oracle::Vec3 move = kSlideMm * p - kEndOutsideMm * d;
    const oracle::Pose end = translated(s.X, move);
    const oracle::Verdict E = C.classify(end, true);
    char b[96];
    if (!E.free() || !(E.clearance > epsilon_mm + kEndClearanceMarginMm)) {
      std::snprintf(b, sizeof b, " end %s",
                    E.free() ? ("clearance " + std::to_string(E.clearance)).c_str()
                             : "touches or penetrates");
      tried += b;
      continue;
    }
    oracle::Motion m;
    m.u = (move + kProbeMm * d).normalized();  // from the lifted pose to the end pose
    const double hit =
        oracle::time_of_impact(A, B, lifted, m, (move + kProbeMm * d).norm(), C.tol().len);
    if (std::isfinite(hit)) {
      std::snprintf(b, sizeof b, " path meets B at %.3g mm", hit);
      tried += b;
      continue;
    }
    *d_out = d;
    *p_out = p;
    return true;
  }
  *why = "no slide direction ends clear of B:" + tried;
  return false;
}

// ---- one run ----------------------------------------------------------------------------------

struct Tick {
  oracle::Vec3 offset;  // device translation relative to the sample pose
  int hold_end = -1;    // index into kHoldDepthsMm when this tick ends a hold
};

std::vector<Tick> script(const oracle::Vec3& d, const oracle::Vec3& p) {
  std::vector<Tick> ticks;
  auto line = [&](const oracle::Vec3& from, const oracle::Vec3& to) {  // excludes `from`
    // Ticks of at most kStepMm; the 1e-9 keeps a whole number of steps (3 mm / 0.02 mm) from
    // rounding up to one more.
    const int n = std::max(1, static_cast<int>(std::ceil((to - from).norm() / kStepMm - 1e-9)));
    for (int k = 1; k <= n; ++k)
      ticks.push_back({from + (to - from) * (static_cast<double>(k) / n), -1});
  };
  oracle::Vec3 at = -kStartOutsideMm * d;
  ticks.push_back({at, -1});
  for (int h = 0; h < 3; ++h) {
    const oracle::Vec3 to = kHoldDepthsMm[h] * d;
    line(at, to);
    at = to;
    for (int k = 0; k < kHoldTicks; ++k) ticks.push_back({at, k + 1 == kHoldTicks ? h : -1});
  }
  oracle::Vec3 to = at + kSlideMm * p;
  line(at, to);
  at = to;
  to = kSlideMm * p - kEndOutsideMm * d;
  line(at, to);
  at = to;
  for (int k = 0; k < kEndHoldTicks; ++k) ticks.push_back({at, -1});
  return ticks;
}

struct PairSummary {
  std::string dir;
  int eligible = 0, run = 0, skipped = 0;
  long ticks = 0, ticks_inside = 0, ticks_without_cf = 0;
  double max_proxy_depth = 0;
  std::string max_depth_where;
  int monotonic = 0, not_monotonic = 0, cf_changed = 0, end_ok = 0, end_bad = 0, depth_bad = 0;
  std::vector<std::string> failures;  // one line each
  std::vector<std::string> skips;
};

constexpr std::size_t kMaxFailureLinesPerSample = 6;

std::string vec_str(const Eigen::Vector3d& v) {
  char b[128];
  std::snprintf(b, sizeof b, "(%.9g, %.9g, %.9g)", v.x(), v.y(), v.z());
  return b;
}

void run_sample(const cf::CfModel& model, const oracle::Classifier& C,
                const oracle::Classifier& C_delta, const Sample& s, const oracle::Vec3& d,
                const oracle::Vec3& p, const std::string& seed, PairSummary& S) {
  // CF_PROXY_ORACLE_TRACE=seed_N:row prints every tick of that run.
  const char* trace_env = std::getenv("CF_PROXY_ORACLE_TRACE");
  const bool trace =
      trace_env != nullptr && std::string(trace_env) == seed + ":" + std::to_string(s.row);
  const cf::Params& prm = model.params();
  const double delta = prm.proxy.penetration_tolerance_mm;
  const Eigen::Vector3d gravity(0, -prm.mass_kg * prm.gravity_N_per_kg, 0);
  const std::vector<Tick> ticks = script(d, p);
  cf::CfState state(model);  // cold start per sample
  const std::string tag = seed + " sample row " + std::to_string(s.row) + " [" + s.pcs + "]";
  std::size_t lines = 0;
  auto fail = [&](const std::string& msg) {
    if (lines++ < kMaxFailureLinesPerSample) S.failures.push_back(tag + ": " + msg);
  };
  long inside = 0, no_cf = 0;
  double hold_force[3] = {0, 0, 0};
  std::set<std::string> hold_cf[3];  // the rendered CF's PCs at the end of each hold
  double hold_turn = 0;              // rad, the most the proxy turned from the device at a hold
  const std::set<std::string> s_key = cf::testdata::pc_strings(s.pcs, ' ');
  std::string hold_info[3];  // the proxy at the end of each hold, for the failure message
  double max_depth = 0;
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    const double t_s = static_cast<double>(k) * kTickS;
    const oracle::Pose XD = translated(s.X, ticks[k].offset);
    const cf::HapticResult& r = cf::step(model, state, to_cf(XD), t_s);
    const double lam = ticks[k].offset.dot(d);  // depth of the device past the touching pose
    char where[96];
    std::snprintf(where, sizeof where, "tick %zu (device %.3f mm along d, %.3f mm sideways)", k,
                  lam, ticks[k].offset.dot(p));
    if (!C.interiors_disjoint(XD)) {
      ++inside;
      if (!r.cf.valid()) {
        ++no_cf;
        fail(std::string(where) + ": device inside B, no CF (status " + cf::to_string(r.status) +
             ", " + std::to_string(r.num_detected) + " contacts detected, identification " +
             r.identification + ")");
      }
    }
    std::string what;
    const double pd = oracle_depth(C.A(), C.B(), to_oracle(r.X_WP), &what);
    if (pd > max_depth) {
      max_depth = pd;
      if (pd > S.max_proxy_depth) {
        S.max_proxy_depth = pd;
        S.max_depth_where = tag + " " + where + ", " + what;
      }
    }
    if (pd > delta + kProxyDepthNumTolMm) {
      ++S.depth_bad;
      // A second opinion: the oracle's exact interior test with the allowed depth as its length
      // tolerance (elements that close count as touching, not penetrating).
      std::string why;
      const bool disjoint = C_delta.interiors_disjoint(to_oracle(r.X_WP), &why);
      char b[300];
      std::snprintf(
          b, sizeof b,
          ": proxy penetrates B by %.6g mm (%s) > %.6g + %.0e mm; oracle at tol %.6g mm: %s", pd,
          what.c_str(), delta, kProxyDepthNumTolMm, delta + kProxyDepthNumTolMm,
          disjoint ? "interiors disjoint" : ("penetrating, " + why).c_str());
      fail(std::string(where) + b + "; X_WP " + oracle::pose_string(to_oracle(r.X_WP)) + ", X_WD " +
           oracle::pose_string(XD));
    }
    if (ticks[k].hold_end >= 0) {
      const int h = ticks[k].hold_end;
      hold_force[h] = r.F_W.dot(-d);
      char b[200];
      std::snprintf(b, sizeof b,
                    "proxy %.4f mm along d, %.4f sideways, turned %.4f rad from the device, CF [",
                    (r.X_WP.t_BA - s.X.t).dot(d),
                    (r.X_WP.t_BA - s.X.t - (r.X_WP.t_BA - s.X.t).dot(d) * d).norm(),
                    Eigen::AngleAxisd(r.X_WP.R_BA * r.X_WD.R_BA.transpose()).angle());
      hold_info[h] = b + cf::to_string(r.pcs) + "] " + cf::to_string(r.status);
      hold_cf[h] = cf::testdata::pc_strings(cf::to_string(r.pcs), ';');
      hold_turn =
          std::max(hold_turn, Eigen::AngleAxisd(r.X_WP.R_BA * r.X_WD.R_BA.transpose()).angle());
    }
    if (trace) {
      const oracle::Vec3 off = r.X_WP.t_BA - s.X.t;
      const double ang = Eigen::AngleAxisd(r.X_WP.R_BA * s.X.R.transpose()).angle();
      std::printf(
          "  %s: dev %.3f/%.3f proxy %.4f/%.4f/%.4f rot %.3g rad, depth %.3g (%s), F.-d %.4f, cf "
          "%d %s [%s], "
          "constrained %d, %d contacts, %d substeps\n",
          where, lam, ticks[k].offset.dot(p), off.dot(d), off.dot(p), off.dot(d.cross(p)), ang, pd,
          what.c_str(), r.F_W.dot(-d), r.cf.value(), cf::to_string(r.status),
          cf::to_string(r.pcs).c_str(), r.proxy ? int(r.proxy->constrained) : -1,
          r.proxy ? r.proxy->num_contacts : -1, r.proxy ? r.proxy->substeps : -1);
    }
    if (k + 1 == ticks.size()) {
      const double dt = (r.X_WP.t_BA - r.X_WD.t_BA).cwiseAbs().maxCoeff();
      const double dR = (r.X_WP.R_BA - r.X_WD.R_BA).cwiseAbs().maxCoeff();
      const double dF = (r.F_W - gravity).cwiseAbs().maxCoeff();
      // "With nothing in the way the proxy is set to the device pose exactly" (force-model.md):
      // equality, no tolerance.
      const bool same = r.X_WP.t_BA == r.X_WD.t_BA && r.X_WP.R_BA == r.X_WD.R_BA;
      if (same && dF <= kGravityTolN) {
        ++S.end_ok;
      } else {
        ++S.end_bad;
        char b[400];
        std::snprintf(
            b, sizeof b,
            ": pulled out %.1f mm: X_WP - X_WD max |dt| %.3g mm, |dR| %.3g; F_W %s, gravity %s "
            "(|diff| %.3g N); status %s",
            kEndOutsideMm, dt, dR, vec_str(r.F_W).c_str(), vec_str(gravity).c_str(), dF,
            cf::to_string(r.status));
        fail(std::string(where) + b);
      }
    }
  }
  // Monotonic unless the proxy tipped. A push whose line passes beside the support tips A over
  // the support's edge (the proxy turns and its CF changes, e.g. f-f to f-e to a v-f on B's
  // side face): the push along the first normal then falls, as it does when a real hand
  // pushes a part off a ledge. Those runs are counted apart, not checked for growth.
  const bool tipped = hold_turn > kTipRad;
  if (tipped) {
    ++S.cf_changed;
    if (std::getenv("CF_PROXY_ORACLE_VERBOSE"))
      std::printf(
          "  tipped %s: turned %.3g rad (held at %s in A's frame, push %s); holds: %s | %s | %s\n",
          tag.c_str(), hold_turn, vec_str(model.params().proxy.grip_point_A).c_str(),
          vec_str(d).c_str(), hold_info[0].c_str(), hold_info[1].c_str(), hold_info[2].c_str());
  } else if (hold_force[0] < hold_force[1] && hold_force[1] < hold_force[2]) {
    ++S.monotonic;
  } else {
    ++S.not_monotonic;
    char b[200];
    std::snprintf(b, sizeof b,
                  "force along the push at 1, 3, 6 mm: %.6g, %.6g, %.6g N (not strictly growing)",
                  hold_force[0], hold_force[1], hold_force[2]);
    fail(std::string(b) + "; at the holds: " + hold_info[0] + " | " + hold_info[1] + " | " +
         hold_info[2] + "; sample pose " + oracle::pose_string(s.X) + ", push d " + vec_str(d));
  }
  S.ticks += static_cast<long>(ticks.size());
  S.ticks_inside += inside;
  S.ticks_without_cf += no_cf;
  if (lines > kMaxFailureLinesPerSample)
    S.failures.push_back(tag + ": ... " + std::to_string(lines - kMaxFailureLinesPerSample) +
                         " more");
}

PairSummary check_pair(const fs::path& dir) {
  PairSummary S;
  S.dir = dir.filename().string();
  const std::string g_path = (dir / "G.json").string();
  const cf::CfGraph g = cf::CfGraph::load(g_path);
  const cf::CfModel model(g);  // default Params: proxy on
  const oracle::Graph og = oracle::read_graph(g_path);
  const oracle::Classifier C(og.A, og.B, oracle::default_tolerances(og.A, og.B));
  oracle::Tolerances tol_delta = C.tol();
  tol_delta.len = model.params().proxy.penetration_tolerance_mm + kProxyDepthNumTolMm;
  const oracle::Classifier C_delta(og.A, og.B, tol_delta);

  std::vector<Sample> eligible;
  for (const Sample& s : read_samples(dir / "samples.csv"))
    if (s.free_mm >= kMinFreeClearanceMm) eligible.push_back(s);
  S.eligible = static_cast<int>(eligible.size());
  // A fixed stride over the eligible rows, then the rows between (offset 1, 2, ...) until
  // kMaxSamplesPerPair suitable poses are found: deterministic, spread over the file.
  const std::size_t n = eligible.size();
  const std::size_t stride = std::max<std::size_t>(1, n / kMaxSamplesPerPair);
  for (std::size_t off = 0; off < stride && S.run < kMaxSamplesPerPair; ++off)
    for (std::size_t i = off; i < n && S.run < kMaxSamplesPerPair; i += stride) {
      const Sample& s = eligible[i];
      oracle::Vec3 d, p;
      std::string why;
      if (!plan(C, model.params().epsilon_mm, s, &d, &p, &why)) {
        ++S.skipped;
        S.skips.push_back("row " + std::to_string(s.row) + " [" + s.pcs + "]: " + why);
        continue;
      }
      ++S.run;
      // The hand holds A at the middle of its PCs' touch points (ProxyParams::grip_point_A): the
      // push line passes through the support, as when an operator presses a part onto a seat, so
      // the proxy is not expected to tip. (Held at A's frame origin, which the generated
      // shapes put at a corner, most pushes pass beside the support and tip A over its edge.)
      const oracle::Verdict V = C.classify(s.X, false);
      oracle::Vec3 c = oracle::Vec3::Zero();
      int k = 0;
      // The corners of the PCs' contact regions: the touching pairs of a vertex or of two
      // edges that a PC dominates (their elements in the closures of the PC's).
      for (const oracle::Touch& t : V.touches) {
        const int ka = oracle::kind_a(t.type), kb = oracle::kind_b(t.type);
        if (!(ka == 0 || kb == 0 || (ka == 1 && kb == 1))) continue;
        bool of_a_pc = false;
        for (int i : V.pcs) {
          const oracle::Touch& pc = V.touches[static_cast<std::size_t>(i)];
          of_a_pc = of_a_pc || (C.A().in_closure(ka, t.a, oracle::kind_a(pc.type), pc.a) &&
                                C.B().in_closure(kb, t.b, oracle::kind_b(pc.type), pc.b));
        }
        if (!of_a_pc) continue;
        // A point touch's place is p0 (p1 is not set for it); a collinear e-e is a segment.
        const bool segment = t.type == oracle::PcType::EEC;
        c += segment ? 0.5 * (t.p0 + t.p1) : t.p0;
        ++k;
      }
      cf::Params P = model.params();
      P.proxy.grip_point_A = s.X.inv(c / std::max(k, 1));
      const cf::CfModel held(g, P);
      run_sample(held, C, C_delta, s, d, p, S.dir, S);
    }
  return S;
}

}  // namespace

TEST_CASE("the proxy against the oracle: pushing into B from the oracle's contact poses",
          "[proxy][oracle]") {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path kept = cf::test::kept_oracle_dir(CF_ORACLE_KEEP_DIR);
  const std::vector<fs::path> dirs = cf::test::kept_oracle_pairs(kept);
  {
    INFO("no samples in " << kept.string()
                          << ": run the recall test first (ctest runs it as a fixture)");
    REQUIRE(!dirs.empty());
  }
  const bool verbose = std::getenv("CF_PROXY_ORACLE_VERBOSE") != nullptr;
  for (const fs::path& dir : dirs) {
    const PairSummary S = check_pair(dir);
    std::printf(
        "%s: %d poses run (%d eligible, %d skipped), %ld ticks, %ld with the device inside B, %ld "
        "of them "
        "without a CF; max proxy depth (oracle) %.3g mm; force %s (%d of %d runs growing at 1 < 3 "
        "< 6 mm, %d "
        "tipped to another CF); end %d of %d at the device with gravity only\n",
        S.dir.c_str(), S.run, S.eligible, S.skipped, S.ticks, S.ticks_inside, S.ticks_without_cf,
        S.max_proxy_depth, S.not_monotonic == 0 ? "monotonic" : "NOT monotonic", S.monotonic, S.run,
        S.cf_changed, S.end_ok, S.run);
    if (verbose) {
      if (!S.max_depth_where.empty())
        std::printf("  deepest proxy: %s\n", S.max_depth_where.c_str());
      for (const std::string& w : S.skips) std::printf("  skipped %s\n", w.c_str());
    }
    for (const std::string& f : S.failures) std::printf("  FAIL %s\n", f.c_str());
    std::fflush(stdout);
    CAPTURE(S.dir, S.run, S.skipped);
    CHECK(S.run > 0);
    CHECK(S.ticks_without_cf == 0);
    CHECK(S.depth_bad == 0);
    CHECK(S.not_monotonic == 0);
    CHECK(S.end_bad == 0);
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("total %.1f s\n", secs);
}

// Identification and rendering on the generated default graphs (cube against the L-block and
// against the corner block): the witness of every CF, perturbed witnesses, short pose
// sequences between neighbouring CFs, and the recorded trajectories through the renderer.
// The graphs are written by cfgen in ctest fixtures (tests/libcf/runtime_graph_test.cmake) into
// the directory CF_RUNTIME_GRAPH_DIR names. Counts are printed on stdout (ctest -V).

#include <cf/graph.hpp>
#include <cf/identifier.hpp>
#include <cf/renderer.hpp>
#include <cf/replay.hpp>

#include "trajectories.hpp"

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using cf::CfId;
using cf::IdStatus;
using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Pose;
using cf::Vec3;

// Witness touches are exact to cfgen's touch tolerance (1e-9 mm); allow for the rounding of
// poses written as shortest round-trip doubles and of the detector's own arithmetic.
constexpr double kExact = 1e-6;  // mm
// Perturbed poses keep every PC of the witness's CF within this band of signed distances
// (mm; inside the detector's [-deepest_contact_mm, epsilon] = [-1, 1]), and the heights over a
// line or plane PC within kSpread of each other, so that its tilt is within the detector's
// angular tolerance (the tilt at which the whole contact stays within epsilon = 1 mm).
constexpr double kBandLo = -0.3, kBandHi = 0.8, kSpread = 0.9;
constexpr double kMaxAngle = 0.04;  // rad, largest rotation of a perturbation (then shrunk)
constexpr double kMaxShift = 1.0;   // mm, largest translation per axis of a perturbation

const char* const kGraphs[] = {"cube_l_block", "cube_corner_block"};

const cf::CfGraph& graph(const std::string& name) {
  static std::map<std::string, std::unique_ptr<cf::CfGraph>> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return *it->second;
  const char* dir = std::getenv("CF_RUNTIME_GRAPH_DIR");
  if (dir == nullptr)
    FAIL(
        "CF_RUNTIME_GRAPH_DIR is not set: run through ctest, whose cfgen fixtures write the "
        "graphs");
  auto g =
      std::make_unique<cf::CfGraph>(cf::CfGraph::load(std::string(dir) + "/" + name + ".json"));
  return *cache.emplace(name, std::move(g)).first->second;
}

bool detected(const cf::Identification& r, const Pc& pc) {
  for (const cf::ContactPc& c : r.contacts)
    if (c.pc == pc) return true;
  return false;
}
bool all_detected(const cf::Identification& r, const PcSet& s) {
  for (const Pc& pc : s)
    if (!detected(r, pc)) return false;
  return true;
}
// The CF could be chosen over every other reading: its PCs are detected and undominated and
// one of them lies in every contact plane.
bool stands(const cf::Identification& r, const PcSet& s) {
  if (!all_detected(r, s)) return false;
  for (const cf::ContactPc& c : r.contacts)
    if (c.dominated && s.contains(c.pc)) return false;
  for (int g = 0; g < r.contacts.num_planes(); ++g) {
    bool covered = false;
    for (const cf::ContactPc& c : r.contacts) covered |= c.plane == g && s.contains(c.pc);
    if (!covered) return false;
  }
  return true;
}

// ---- Geometry computed here, independently of the detector ---------------------------------

// Signed distances (> 0 apart) of a PC's elements at a pose: for point PCs one value, for line
// and plane PCs the heights of the end points / face vertices over the other's plane (the
// contact region's distances lie between them). Appended to `h`.
void pc_heights(const cf::Polyhedron& A, const cf::Polyhedron& B, const Pc& pc, const Pose& P,
                std::vector<double>& h) {
  auto over_b = [&](int f, const Vec3& p_A) {
    const cf::Face& F = B.faces()[static_cast<std::size_t>(f)];
    return F.normal.dot(P.apply(p_A)) - F.offset;
  };
  auto over_a = [&](int f, const Vec3& p_B) {
    const cf::Face& F = A.faces()[static_cast<std::size_t>(f)];
    return F.normal.dot(P.inverse_apply(p_B)) - F.offset;
  };
  switch (pc.type) {
    case PcType::kVF:
      h.push_back(over_b(pc.b, A.vertices()[static_cast<std::size_t>(pc.a)].p));
      break;
    case PcType::kFV:
      h.push_back(over_a(pc.a, B.vertices()[static_cast<std::size_t>(pc.b)].p));
      break;
    case PcType::kEF:
      for (int end = 0; end < 2; ++end)
        h.push_back(over_b(pc.b, A.edge_point(cf::EdgeId(pc.a), end)));
      break;
    case PcType::kFE:
      for (int end = 0; end < 2; ++end)
        h.push_back(over_a(pc.a, B.edge_point(cf::EdgeId(pc.b), end)));
      break;
    case PcType::kFF:
      for (cf::VertexId v : A.faces()[static_cast<std::size_t>(pc.a)].vertices)
        h.push_back(over_b(pc.b, A.vertex(v).p));
      break;
    case PcType::kEE: {
      // Distance between the two edges' lines along their common normal, which points out
      // of B's wedge and into A's (the sums of each edge's face normals).
      const cf::Edge& EA = A.edges()[static_cast<std::size_t>(pc.a)];
      const cf::Edge& EB = B.edges()[static_cast<std::size_t>(pc.b)];
      const Vec3 uA = P.R_BA * EA.dir;
      Vec3 n = uA.cross(EB.dir).normalized();
      const Vec3 sumA = P.R_BA * (A.face(EA.left).normal + A.face(EA.right).normal);
      if (n.dot(B.face(EB.left).normal + B.face(EB.right).normal - sumA) < 0) n = -n;
      h.push_back((P.apply(A.vertex(EA.v0).p) - B.vertex(EB.v0).p).dot(n));
      break;
    }
  }
}

struct Span {
  double lo = 0, hi = 0;
};
Span pc_span(const cf::CfGraph& g, const Pc& pc, const Pose& P) {
  std::vector<double> h;
  pc_heights(g.model_a(), g.model_b(), pc, P, h);
  Span s{h[0], h[0]};
  for (double v : h) s.lo = std::min(s.lo, v), s.hi = std::max(s.hi, v);
  return s;
}

// The detector's distance of a contact lies within the independent span of its elements.
bool distance_consistent(const cf::CfGraph& g, const cf::ContactPc& c, const Pose& P) {
  const Span s = pc_span(g, c.pc, P);
  if (c.pc.type == PcType::kEE) {
    // Only comparable when the crossing lies inside both edges (else the detector measures
    // from the nearer end, within in_plane_tolerance_mm): then equal.
    const cf::Edge& EA = g.model_a().edges()[static_cast<std::size_t>(c.pc.a)];
    const cf::Edge& EB = g.model_b().edges()[static_cast<std::size_t>(c.pc.b)];
    const Vec3 p0 = P.apply(g.model_a().vertex(EA.v0).p), uA = P.R_BA * EA.dir;
    const Vec3 q0 = g.model_b().vertex(EB.v0).p;
    const double b = uA.dot(EB.dir), cA = uA.dot(p0 - q0), fB = EB.dir.dot(p0 - q0),
                 den = 1 - b * b;
    const double sA = (b * fB - cA) / den, tB = (fB - b * cA) / den;
    if (sA < 0 || sA > EA.length || tB < 0 || tB > EB.length) return true;
  }
  return c.distance >= s.lo - kExact && c.distance <= s.hi + kExact;
}

// ---- Poses -----------------------------------------------------------------------------------

// Uniform in [-1, 1] from the raw mt19937 output (specified by the standard, unlike the
// distributions), so the poses are the same with every standard library.
double uniform(std::mt19937& rng) { return static_cast<double>(rng()) / 4294967295.0 * 2.0 - 1.0; }

// Rotates by `w` (axis times angle) about the point c, then translates by v.
Pose moved(const Pose& p, const Vec3& w, const Vec3& v, const Vec3& c) {
  const double a = w.norm();
  const Mat3 dR = a > 0 ? Mat3(Eigen::AngleAxisd(a, w / a)) : Mat3::Identity();
  Pose q;
  q.R_BA = dR * p.R_BA;
  q.t_BA = dR * (p.t_BA - c) + c + v;
  return q;
}

Pose interpolate(const Pose& a, const Pose& b, double s) {
  Pose p;
  p.R_BA = Eigen::Quaterniond(a.R_BA).slerp(s, Eigen::Quaterniond(b.R_BA)).toRotationMatrix();
  p.t_BA = (1 - s) * a.t_BA + s * b.t_BA;
  return p;
}

// Mean of the contact origins of the identified CF: the centre for small rotations.
Vec3 contact_centre(const cf::Identification& r) {
  Vec3 c = Vec3::Zero();
  for (int k = 0; k < r.num_cf_pcs; ++k) c += r.cf_pcs[static_cast<std::size_t>(k)].origin_W;
  return r.num_cf_pcs > 0 ? Vec3(c / r.num_cf_pcs) : c;
}

// A random pose near `w` at which every PC of `pcs` stays within [kBandLo, kBandHi]; shrinks
// the motion until it does (false after 20 tries).
bool perturb(const cf::CfGraph& g, const PcSet& pcs, const Pose& w, const Vec3& c,
             std::mt19937& rng, Pose* out) {
  double scale = 1;
  for (int tries = 0; tries < 20; ++tries, scale *= 0.7) {
    const Vec3 axis = Vec3(uniform(rng), uniform(rng), uniform(rng)).normalized();
    const double angle = kMaxAngle * scale * 0.5 * (1 + uniform(rng));
    const Vec3 shift = kMaxShift * scale * Vec3(uniform(rng), uniform(rng), uniform(rng));
    const Pose p = moved(w, angle * axis, shift, c);
    bool ok = true;
    for (const Pc& pc : pcs) {
      const Span s = pc_span(g, pc, p);
      ok = ok && s.lo >= kBandLo && s.hi <= kBandHi && s.hi - s.lo <= kSpread;
    }
    if (ok) {
      *out = p;
      return true;
    }
  }
  return false;
}

// Gauss-Newton on the twist of A from `p`: brings every PC of `pcs` to exact contact of its
// elements' lines and planes (all heights of pc_heights zero). False when it does not
// converge.
bool solve_contact(const cf::CfGraph& g, const PcSet& pcs, const Vec3& c, Pose* p) {
  auto residual = [&](const Pose& q) {
    std::vector<double> h;
    for (const Pc& pc : pcs) pc_heights(g.model_a(), g.model_b(), pc, q, h);
    return h;
  };
  for (int it = 0; it < 30; ++it) {
    const std::vector<double> r0 = residual(*p);
    double worst = 0;
    for (double v : r0) worst = std::max(worst, std::abs(v));
    if (worst < 1e-9) return true;
    Eigen::MatrixXd J(r0.size(), 6);
    constexpr double kStep = 1e-7;
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
      x[k] = kStep;
      const std::vector<double> r1 = residual(moved(*p, x.head<3>(), x.tail<3>(), c));
      for (std::size_t i = 0; i < r0.size(); ++i)
        J(static_cast<Eigen::Index>(i), k) = (r1[i] - r0[i]) / kStep;
    }
    const Eigen::VectorXd rv =
        Eigen::Map<const Eigen::VectorXd>(r0.data(), static_cast<Eigen::Index>(r0.size()));
    const Eigen::Matrix<double, 6, 1> x = -J.completeOrthogonalDecomposition().solve(rv);
    *p = moved(*p, x.head<3>(), x.tail<3>(), c);
  }
  return false;
}

std::string describe(const cf::Identification& r) {
  std::string s = std::string(cf::to_string(r.status)) + " CF " + std::to_string(r.cf.value()) +
                  " {" + cf::to_string(r.pcs) + "}; contacts:";
  for (const cf::ContactPc& c : r.contacts) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " %s(d %.4f, misfit %.3f%s, plane %d)",
                  cf::to_string(c.pc).c_str(), c.distance, c.misfit,
                  c.dominated ? ", dominated" : "", c.plane);
    s += buf;
  }
  return s;
}

}  // namespace

TEST_CASE("the witness of every CF identifies exactly that CF", "[runtime_graph]") {
  for (const char* name : kGraphs) {
    const cf::CfGraph& g = graph(name);
    cf::CfIdentifier id(g);
    std::size_t exact = 0, kept = 0, with_apart = 0;
    double nearest_apart = 1e9;  // mm, the nearest contact in a plane the CF leaves out
    int shown = 0;
    std::ostringstream notes;
    for (std::size_t i = 0; i < g.num_cfs(); ++i) {
      const CfId X(static_cast<std::int32_t>(i));
      id.reset();
      const cf::Identification& r = id.step(g.cf(X).witness);
      bool ok = r.status == IdStatus::kMatchedByFit && r.cf == X;
      for (int k = 0; k < r.num_cf_pcs && ok; ++k)
        ok = std::abs(r.cf_pcs[static_cast<std::size_t>(k)].distance) <= kExact;
      if (ok) {
        ++exact;
        // Near pairs in other planes (at least 0.01 mm away at a witness), which a CF holding
        // them would also explain: the exact CF must win over it.
        with_apart += r.partial_cover;
        for (const cf::ContactPc& c : r.contacts) {
          bool in_cf_plane = false;
          for (int k = 0; k < r.num_cf_pcs; ++k)
            in_cf_plane |= r.cf_pcs[static_cast<std::size_t>(k)].plane == c.plane;
          if (!in_cf_plane) nearest_apart = std::min(nearest_apart, c.distance);
        }
      } else if (shown++ < 10) {
        notes << name << ": CF " << i << " {" << cf::to_string(g.cf(X).pcs) << "} -> "
              << describe(r) << "\n";
      }
      // Staying there: the previous CF.
      const cf::Identification& again = id.step(g.cf(X).witness);
      kept += again.status == IdStatus::kMatchedPrevious && again.cf == X;
    }
    std::printf(
        "%s: %zu/%zu witnesses identify their CF (matched-by-fit, PCs at |d| <= %g mm), %zu/%zu "
        "kept "
        "(matched-previous); %zu leave out contacts of other planes within epsilon as apart "
        "(nearest: %s mm)\n",
        name, exact, g.num_cfs(), kExact, kept, g.num_cfs(), with_apart,
        with_apart > 0 ? std::to_string(nearest_apart).c_str() : "-");
    INFO(notes.str());
    CHECK(exact == g.num_cfs());
    CHECK(kept == g.num_cfs());
  }
}

TEST_CASE(
    "perturbed witnesses: a CF of the graph consistent with the geometry, near the previous one",
    "[runtime_graph]") {
  std::mt19937 rng(20240601);
  for (const char* name : kGraphs) {
    const cf::CfGraph& g = graph(name);
    cf::CfIdentifier id(g);
    std::size_t poses = 0, found = 0, consistent = 0, own_detected = 0, same_by_fit = 0;
    std::size_t prev_same = 0, prev_neighbour = 0, prev_far = 0, wrong_jumps = 0, wrong_status = 0;
    int shown = 0;
    std::ostringstream notes;
    for (std::size_t i = 0; i < g.num_cfs(); ++i) {
      const CfId X(static_cast<std::int32_t>(i));
      const cf::CfRecord& rec = g.cf(X);
      id.reset();
      const Vec3 c = contact_centre(id.step(rec.witness));
      for (int rep = 0; rep < 3; ++rep) {
        Pose P;
        if (!perturb(g, rec.pcs, rec.witness, c, rng, &P)) continue;
        ++poses;
        // By fit (no history).
        id.reset();
        const cf::Identification& r = id.step(P);
        own_detected += all_detected(r, rec.pcs);
        bool ok = r.has_cf() && g.find(r.pcs) == r.cf && r.num_cf_pcs == r.pcs.size();
        bool geo = ok;
        for (int k = 0; k < r.num_cf_pcs && ok; ++k) {
          const cf::ContactPc& pc = r.cf_pcs[static_cast<std::size_t>(k)];
          ok = detected(r, pc.pc) && pc.pc == r.pcs[k];
          geo = geo && distance_consistent(g, pc, P) && pc.distance <= 1.0 && pc.distance >= -1.0;
        }
        found += ok;
        consistent += ok && geo;
        same_by_fit += r.cf == X;
        if (!(ok && geo) && shown++ < 10)
          notes << name << ": near CF " << i << " by fit: " << describe(r) << "\n";
        // Coming from X: X, else a neighbour, whenever one of them stands at P (the preference
        // of docs/spec.md, section 6); elsewhere only when none does (the motion changed more than
        // one step).
        bool near_stands = stands(r, rec.pcs);
        for (const cf::Transition& t : g.out_transitions(X))
          near_stands = near_stands || stands(r, g.cf(t.to).pcs);
        id.reset();
        id.step(rec.witness);
        const cf::Identification& q = id.step(P);
        if (q.cf == X) {
          ++prev_same;
          wrong_status += q.status != IdStatus::kMatchedPrevious;
        } else if (q.has_cf() && g.adjacent(X, q.cf)) {
          ++prev_neighbour;
          wrong_status += q.status != IdStatus::kMatchedNeighbour;
        } else {
          ++prev_far;
          if (near_stands) {
            ++wrong_jumps;
            if (shown++ < 10)
              notes << name << ": from CF " << i << " {" << cf::to_string(rec.pcs)
                    << "}: " << describe(q) << "\n";
          }
        }
      }
    }
    std::printf(
        "%s: %zu perturbed poses (PCs within [%g, %g] mm); by fit: %zu CFs of the graph, %zu with "
        "distances matching the geometry, %zu the witness's CF, %zu with its PCs all detected; "
        "from the witness's CF: %zu kept, %zu neighbours, %zu elsewhere (none of them standing "
        "there)\n",
        name, poses, kBandLo, kBandHi, found, consistent, same_by_fit, own_detected, prev_same,
        prev_neighbour, prev_far);
    INFO(notes.str());
    CHECK(poses >= 2 * g.num_cfs());
    CHECK(own_detected == poses);  // the detector finds the PCs within tolerance
    CHECK(found == poses);
    CHECK(consistent == poses);
    CHECK(wrong_jumps == 0);
    CHECK(wrong_status == 0);
  }
}

TEST_CASE("sequences: the previous CF and its neighbours are preferred", "[runtime_graph]") {
  for (const char* name : kGraphs) {
    const cf::CfGraph& g = graph(name);
    cf::CfIdentifier id(g), probe(g);
    // 1. Every transition: the witness of one CF, then the witness of its neighbour.
    std::size_t to_next = 0, kept_prev = 0, wrong = 0;
    std::ostringstream notes;
    for (std::size_t k = 0; k < g.num_transitions(); ++k) {
      const cf::Transition& t = g.transition(k);
      id.reset();
      id.step(g.cf(t.from).witness);
      const cf::Identification& r = id.step(g.cf(t.to).witness);
      if (r.cf == t.to && r.status == IdStatus::kMatchedNeighbour) {
        ++to_next;
      } else if (r.cf == t.from && r.status == IdStatus::kMatchedPrevious) {
        ++kept_prev;  // the previous CF still stands there: allowed
      } else if (wrong++ < 10) {
        notes << name << ": " << t.from.value() << " -> " << t.to.value() << ": " << describe(r)
              << "\n";
      }
    }
    std::printf(
        "%s: %zu transitions, witness to witness: %zu reach the neighbour (matched-neighbour), %zu "
        "keep the "
        "previous CF, %zu other\n",
        name, g.num_transitions(), to_next, kept_prev, wrong);
    INFO(notes.str());
    CHECK(wrong == 0);
    notes.str("");

    // 2. Poses between neighbours: for each change X -> Y, move A from X's witness towards
    // the pose D where Y's PCs touch exactly (Gauss-Newton), and stop short of it. Where the
    // previous CF still stands there (its PCs detected, undominated, in every contact
    // plane), it is kept.
    std::size_t solved = 0, between = 0, deep = 0, stood = 0, kept = 0, failed = 0, fit_valid = 0;
    for (std::size_t k = 0; k < g.num_transitions(); ++k) {
      const cf::Transition& t = g.transition(k);
      if (t.kind != cf::TransitionKind::kChange) continue;
      const CfId X = t.from, Y = t.to;
      probe.reset();
      const Vec3 c = contact_centre(probe.step(g.cf(X).witness));
      Pose D = g.cf(X).witness;
      if (!solve_contact(g, g.cf(Y).pcs, c, &D)) continue;
      ++solved;
      for (double s : {0.9, 0.97, 0.995}) {
        const Pose P = interpolate(g.cf(X).witness, D, s);
        probe.reset();
        const cf::Identification& f = probe.step(P);
        if (!all_detected(f, g.cf(X).pcs) || !all_detected(f, g.cf(Y).pcs)) continue;
        // The path can run into other elements: keep the poses without deep contacts.
        bool shallow = true;
        for (const cf::ContactPc& contact : f.contacts)
          shallow = shallow && contact.distance >= kBandLo;
        if (!shallow) {
          ++deep;
          continue;
        }
        ++between;
        fit_valid += f.has_cf();
        if (!f.has_cf() && failed++ < 10)
          notes << name << ": " << X.value() << " -> " << Y.value() << " at " << s
                << ", by fit: " << describe(f) << "\n";
        for (const CfId prev : {X, Y}) {
          if (!stands(f, g.cf(prev).pcs)) continue;
          ++stood;
          id.reset();
          id.step(g.cf(prev).witness);
          const cf::Identification& r = id.step(P);
          if (r.cf == prev && r.status == IdStatus::kMatchedPrevious) {
            ++kept;
          } else if (failed++ < 10) {
            notes << name << ": " << X.value() << " -> " << Y.value() << " at " << s
                  << ", previous " << prev.value() << ": " << describe(r) << "\n";
          }
        }
      }
    }
    std::printf(
        "%s: change transitions: %zu with a pose touching both, %zu poses between them with both "
        "CFs' PCs "
        "detected and no contact deeper than %g mm (%zu more skipped), %zu identified by fit; "
        "previous CF "
        "standing there %zu times, kept %zu\n",
        name, solved, between, -kBandLo, deep, fit_valid, stood, kept);
    INFO(notes.str());
    CHECK(between > 1000);
    CHECK(fit_valid == between);
    CHECK(stood > 1000);
    CHECK(failed == 0);
  }
}

TEST_CASE("an edge rocking onto a face: the hysteresis band of dominance", "[runtime_graph]") {
  const cf::CfGraph& g = graph("cube_l_block");
  const cf::Polyhedron& A = g.model_a();
  const cf::Polyhedron& B = g.model_b();
  // The cube's bottom face (normal -y), its edge at x = +15 (along z), the slab's top (y = 20).
  int fa = -1, ea = -1, fb = -1;
  for (std::size_t f = 0; f < A.num_faces(); ++f)
    if (A.faces()[f].normal.dot(Vec3(0, -1, 0)) > 0.999) fa = static_cast<int>(f);
  for (std::size_t e = 0; e < A.num_edges(); ++e) {
    const Vec3 m = 0.5 * (A.edge_point(cf::EdgeId(static_cast<std::int32_t>(e)), 0) +
                          A.edge_point(cf::EdgeId(static_cast<std::int32_t>(e)), 1));
    if ((m - Vec3(15, -15, 0)).norm() < 1e-9) ea = static_cast<int>(e);
  }
  for (std::size_t f = 0; f < B.num_faces(); ++f)
    if (B.faces()[f].normal.dot(Vec3(0, 1, 0)) > 0.999 && std::abs(B.faces()[f].offset - 20) < 1e-9)
      fb = static_cast<int>(f);
  REQUIRE(fa >= 0);
  REQUIRE(ea >= 0);
  REQUIRE(fb >= 0);
  const std::optional<CfId> ff = g.find(PcSet({Pc{PcType::kFF, fa, fb}}));
  const std::optional<CfId> ef = g.find(PcSet({Pc{PcType::kEF, ea, fb}}));
  REQUIRE(ff);
  REQUIRE(ef);
  REQUIRE(g.adjacent(*ff, *ef));
  // Tilt about the edge, which stays on the slab at (85, 20, 40 + z): the face rises on the
  // -x side by theta * 30 mm. The f-f's angular tolerance: atan(epsilon / L), L the extent of
  // the overlap (the whole face) along the tilt: 30 mm.
  const double tol = std::atan(1.0 / 30);
  auto tilted = [&](double fraction) {
    Pose p;
    p.R_BA = Eigen::AngleAxisd(-fraction * tol, Vec3::UnitZ()).toRotationMatrix();
    p.t_BA = Vec3(85, 20, 40) - p.R_BA * Vec3(15, -15, 0);
    return p;
  };
  cf::CfIdentifier id(g);
  struct Tick {
    double fraction;  // tilt / tolerance
    CfId expect;
    IdStatus status;
  };
  // Down from the edge: the e-f stands until the face is within a quarter of its tolerance
  // (DetectionParams::dominance_fit), then the f-f dominates it; back up, the f-f stands
  // until the face leaves its tolerance.
  const double kappa = cf::DetectionParams().dominance_fit;
  REQUIRE(kappa == 0.25);
  const Tick ticks[] = {
      {1.7, *ef, IdStatus::kMatchedByFit},     {0.85, *ef, IdStatus::kMatchedPrevious},
      {0.4, *ef, IdStatus::kMatchedPrevious},  {0.3, *ef, IdStatus::kMatchedPrevious},
      {0.2, *ff, IdStatus::kMatchedNeighbour}, {0.0, *ff, IdStatus::kMatchedPrevious},
      {0.6, *ff, IdStatus::kMatchedPrevious},  {0.95, *ff, IdStatus::kMatchedPrevious},
      {1.05, *ef, IdStatus::kMatchedNeighbour}};
  for (const Tick& t : ticks) {
    INFO("tilt " << t.fraction << " x tolerance " << tol << " rad");
    const cf::Identification& r = id.step(tilted(t.fraction));
    INFO(describe(r));
    CHECK(r.cf == t.expect);
    CHECK(r.status == t.status);
  }
  // Without history the better fit wins: the e-f above a quarter of the tolerance, the f-f
  // below (it dominates the e-f there).
  for (double fraction : {0.3, 0.6, 0.95}) {
    id.reset();
    CHECK(id.step(tilted(fraction)).cf == *ef);
  }
  for (double fraction : {0.0, 0.2}) {
    id.reset();
    CHECK(id.step(tilted(fraction)).cf == *ff);
  }
}

TEST_CASE("the renderer on the recorded trajectories identifies CFs on contact ticks",
          "[runtime_graph]") {
  struct Case {
    const char* trajectory;
    const char* graph;
    std::vector<std::string> runs;  // the CFs' PC sets in order ("" = no contact)
  };
  const std::vector<Case> cases = {
      {"cube_lblock_guarded", "cube_l_block", {"", "f-f:2:4"}},
      {"cube_lblock_slide", "cube_l_block", {"", "f-f:2:4"}},
      {"cube_lblock_corner", "cube_l_block", {"", "f-f:2:4", "f-f:2:4;f-f:5:5"}},
      {"cube_lblock_break", "cube_l_block", {"f-f:5:5", "f-f:2:4;f-f:5:5", "f-f:2:4", ""}},
      {"cube_lblock_rotate", "cube_l_block", {"", "f-f:2:4", "e-f:4:4", "f-f:2:4"}},
      // The last part seats the cube against the second wall too (see below).
      {"cube_corner_seat", "cube_corner_block", {"", "f-f:2:2", "f-f:2:2;f-f:5:7"}},
  };
  for (const Case& k : cases) {
    const cf::CfGraph& g = graph(k.graph);
    const std::vector<cf::ReplayRow> rows = cf::testdata::replay_rows(
        g,
        cf::testdata::read_samples(std::string(CF_SOURCE_DIR) + "/data/trajectories/" +
                                   k.trajectory + ".csv"),
        cf::Params());
    std::size_t contact = 0, identified = 0, no_fit = 0, unlisted = 0;
    std::vector<std::string> runs;
    for (const cf::ReplayRow& row : rows) {
      if (row.status != "no_contact") {
        ++contact;
        identified += row.cf >= 0;
        no_fit += row.status == "no_fitting_cf";
        unlisted += row.status == "unlisted_transition";
      }
      const std::string pcs = row.cf >= 0 ? row.pcs : "";
      if (runs.empty() || runs.back() != pcs) runs.push_back(pcs);
    }
    std::string seq;
    for (const std::string& r : runs)
      seq += (seq.empty() ? "" : " -> ") + (r.empty() ? std::string("none") : r);
    std::printf(
        "%s on %s: %zu ticks, %zu in contact: %zu with a CF, %zu no_fitting_cf, %zu "
        "unlisted_transition; %s\n",
        k.trajectory, k.graph, rows.size(), contact, identified, no_fit, unlisted, seq.c_str());
    INFO(k.trajectory << ": " << seq);
    CHECK(contact > 0);
    CHECK(10 * identified >= 9 * contact);  // a CF on at least 90% of the contact ticks
    CHECK(10 * no_fit <= contact);          // conservative rendering on at most 10%
    REQUIRE(runs.size() >= k.runs.size());
    for (std::size_t i = 0; i < k.runs.size(); ++i) CHECK(runs[i] == k.runs[i]);
    if (std::string(k.trajectory) != "cube_corner_seat") {
      CHECK(runs.size() == k.runs.size());
    } else {
      // Seated against the floor and both walls: the three f-f, when the graph holds them.
      const std::optional<CfId> seat =
          g.find(PcSet({Pc{PcType::kFF, 0, 8}, Pc{PcType::kFF, 2, 2}, Pc{PcType::kFF, 5, 7}}));
      if (seat) {
        CHECK(runs.back() == cf::to_string(g.cf(*seat).pcs));
      } else {
        WARN(
            "the corner graph lacks the seated CF {f-f:0:8;f-f:2:2;f-f:5:7}: the trajectory ends "
            "in {"
            << runs.back() << "}");
      }
    }
  }
}

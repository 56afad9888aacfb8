// Independent tests of the CF graph generator (tools/cfgen; docs/spec.md, sections 3-5b).
//
// Everything that decides what a contact *is* lives in this file and is written from the
// specification (docs/spec.md), not from the generator: open-set touching of two elements,
// domination, PC types, contact planes, interpenetration by ray casting, first contact of a
// translated polyhedron. From libcf it uses only the model data (features, adjacency) and the
// closed-set distances of cf::element_distance / cf::point_face. The generator's own WitnessSearch
// appears only in failure messages (what its verify() says about a pose this file found) and for
// the U-channel's two-PC sets (see that test).
//
// Sections:
//  0. the oracle itself on poses with known answers;
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
#include "mesh/model_loader.hpp"

#include <cf/geometry.hpp>
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
#include <limits>
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
using cf::ElementKind;
using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Polyhedron;
using cf::Pose;
using cf::Vec3;
using K = cf::ElementKind;
using V2 = Eigen::Vector2d;

namespace {

// ---------------------------------------------------------------------------------------
// Tolerances
// ---------------------------------------------------------------------------------------

// Two elements touch when their closed distance is below this (mm). The generator's own
// touch tolerance is 1e-9 and its witnesses keep every other pair >= 1e-2 mm apart, so
// 1e-7 separates "touching" from "apart" by five orders of magnitude either way.
constexpr double kTouchTol = 1e-7;
// A second, coarser tolerance: a random pose whose classification changes between kTouchTol
// and this is too close to a boundary case to be judged, and is skipped in the recall test.
constexpr double kCoarseTol = 1e-5;
// Contact planes closer than this (unit normals' cross product, offsets in mm) are the same.
constexpr double kPlaneTol = 1e-6;
// A point counts as strictly inside a solid when it is this far (mm) from its boundary.
constexpr double kInsideMargin = 1e-6;
// Radius (mm) of the probe points around each contact, to catch interpenetration that is
// purely local (two wedges crossing at an e-e touch, an edge poking through a vertex).
constexpr double kProbeRadius = 1e-3;

const std::string kModels = std::string(CF_SOURCE_DIR) + "/data/models/";

double cross2(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

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
std::string pose_str(const Pose& p) {
  std::ostringstream os;
  os << "R=[" << vec_str(p.R_BA.row(0).transpose()) << ", " << vec_str(p.R_BA.row(1).transpose())
     << ", " << vec_str(p.R_BA.row(2).transpose()) << "] t=" << vec_str(p.t_BA);
  return os.str();
}

// ---------------------------------------------------------------------------------------
// Models built in memory
// ---------------------------------------------------------------------------------------

Polyhedron from_soup(const std::string& name, std::vector<Vec3> pts,
                     std::vector<std::vector<int>> polys) {
  cf::tools::PolygonSoup soup;
  soup.points = std::move(pts);
  soup.polygons = std::move(polys);
  cf::tools::LoadOptions opt;
  opt.name = name;
  return cf::tools::model_from_soup(soup, name, opt);
}

// Axis-aligned box [0, s]^3 (same facet layout as data/models/make_models.py).
Polyhedron big_box(double s) {
  std::vector<Vec3> v{{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0},
                      {0, 0, s}, {s, 0, s}, {s, s, s}, {0, s, s}};
  return from_soup(
      "big_box", v,
      {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}});
}

// Extrusion along z of a counter-clockwise xy polygon.
Polyhedron prism(const std::string& name, const std::vector<V2>& poly, double z0, double z1) {
  const int n = static_cast<int>(poly.size());
  std::vector<Vec3> v;
  for (const V2& p : poly) v.emplace_back(p.x(), p.y(), z0);
  for (const V2& p : poly) v.emplace_back(p.x(), p.y(), z1);
  std::vector<std::vector<int>> f(2);
  for (int i = n - 1; i >= 0; --i) f[0].push_back(i);
  for (int i = 0; i < n; ++i) f[1].push_back(n + i);
  for (int i = 0; i < n; ++i) f.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  return from_soup(name, v, f);
}

// U-channel, 80 x 80 x 80 mm: floor 20 thick, two arms 20 thick; the slot between the arms
// is 40 mm wide (x in 20..60), more than the 30 mm cube.
Polyhedron u_channel() {
  return prism("u_channel",
               {{0, 0}, {80, 0}, {80, 80}, {60, 80}, {60, 20}, {20, 20}, {20, 80}, {0, 80}}, 0, 80);
}

// ---------------------------------------------------------------------------------------
// Generated graphs, once per process
// ---------------------------------------------------------------------------------------

struct Generated {
  std::unique_ptr<Polyhedron> A, B;  // stable addresses: ModelInfo points at them
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

// ---------------------------------------------------------------------------------------
// Model geometry for the independent checks
// ---------------------------------------------------------------------------------------

struct FaceGeom {
  Vec3 n;                              // outward unit normal (model frame)
  double d;                            // plane n . x = d
  Vec3 u, w;                           // in-plane axes
  std::vector<std::vector<V2>> loops;  // every loop, in (u, w) coordinates
  Vec3 c;                              // bounding sphere
  double r = 0;
};

// Signed in-plane distance from q to the boundary of a face: > 0 inside the open region
// (even-odd rule over all loops, so holes are outside), < 0 outside, 0 on the boundary.
double inset2d(const FaceGeom& f, const V2& q) {
  bool in = false;
  double bd = std::numeric_limits<double>::infinity();
  for (const auto& loop : f.loops)
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const V2& a = loop[k];
      const V2& b = loop[(k + 1) % loop.size()];
      if ((a.y() > q.y()) != (b.y() > q.y())) {
        const double x = a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        if (x > q.x()) in = !in;
      }
      const V2 ab = b - a;
      const double s = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      bd = std::min(bd, (a + s * ab - q).norm());
    }
  return in ? bd : -bd;
}

struct ModelGeom {
  const Polyhedron* m = nullptr;
  std::vector<FaceGeom> faces;
  Vec3 center;  // bounding sphere of the whole model
  double radius = 0;

  explicit ModelGeom(const Polyhedron& model) : m(&model) {
    for (const cf::Face& F : model.faces()) {
      FaceGeom g;
      g.n = F.normal;
      g.d = F.offset;
      const Vec3 ref = std::abs(g.n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
      g.u = g.n.cross(ref).normalized();
      g.w = g.n.cross(g.u);
      Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
      for (const auto& loop : F.loops) {
        g.loops.emplace_back();
        for (cf::VertexId v : loop) {
          const Vec3& p = model.vertex(v).p;
          g.loops.back().emplace_back(g.u.dot(p), g.w.dot(p));
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
      }
      g.c = 0.5 * (lo + hi);
      for (const auto& loop : F.loops)
        for (cf::VertexId v : loop) g.r = std::max(g.r, (model.vertex(v).p - g.c).norm());
      faces.push_back(std::move(g));
    }
    center = 0.5 * (model.bbox_min() + model.bbox_max());
    radius = 0.5 * (model.bbox_max() - model.bbox_min()).norm();
  }
};

// A model placed by a pose (B: the identity), with world-frame accessors.
struct Placed {
  const ModelGeom* g;
  Pose pose;
  const Polyhedron& m() const { return *g->m; }
  Vec3 vertex(int i) const { return pose.apply(m().vertices()[static_cast<std::size_t>(i)].p); }
  Vec3 edge_pt(int e, int end) const { return pose.apply(m().edge_point(cf::EdgeId(e), end)); }
  Vec3 normal(int f) const { return pose.R_BA * g->faces[static_cast<std::size_t>(f)].n; }
  double offset(int f) const {
    return g->faces[static_cast<std::size_t>(f)].d + normal(f).dot(pose.t_BA);
  }
  double plane_dist(int f, const Vec3& p) const { return normal(f).dot(p) - offset(f); }
  V2 to2d(int f, const Vec3& p) const {
    const FaceGeom& F = g->faces[static_cast<std::size_t>(f)];
    const Vec3 q = pose.inverse_apply(p);
    return {F.u.dot(q), F.w.dot(q)};
  }
  V2 dir2d(int f, const Vec3& d) const {
    const FaceGeom& F = g->faces[static_cast<std::size_t>(f)];
    const Vec3 q = pose.R_BA.transpose() * d;
    return {F.u.dot(q), F.w.dot(q)};
  }
  double inset(int f, const Vec3& p) const {
    return inset2d(g->faces[static_cast<std::size_t>(f)], to2d(f, p));
  }
  // Bounding sphere of an element, world frame.
  std::pair<Vec3, double> sphere(K k, int i) const {
    if (k == K::kVertex) return {vertex(i), 0.0};
    if (k == K::kEdge) {
      const Vec3 a = edge_pt(i, 0), b = edge_pt(i, 1);
      return {0.5 * (a + b), 0.5 * (b - a).norm()};
    }
    const FaceGeom& F = g->faces[static_cast<std::size_t>(i)];
    return {pose.apply(F.c), F.r};
  }
};

int count(const Polyhedron& m, K k) {
  return static_cast<int>(k == K::kVertex ? m.num_vertices()
                          : k == K::kEdge ? m.num_edges()
                                          : m.num_faces());
}

// Parameters along the line P + t D (world, in face f's plane) in (t0, t1) where it crosses
// the boundary of face f, sorted, with t0 and t1 included.
std::vector<double> cuts_on_line(const Placed& S, int f, const Vec3& P, const Vec3& D, double t0,
                                 double t1, double tol) {
  std::vector<double> cuts{t0, t1};
  const V2 q0 = S.to2d(f, P), e = S.dir2d(f, D);
  for (const auto& loop : S.g->faces[static_cast<std::size_t>(f)].loops)
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const V2& a = loop[k];
      const V2 s = loop[(k + 1) % loop.size()] - a;
      const double den = cross2(e, s);
      const V2 w = a - q0;
      if (std::abs(den) > 1e-12 * s.norm()) {
        const double t = cross2(w, s) / den, r = cross2(w, e) / den;
        if (r >= -1e-9 && r <= 1 + 1e-9 && t > t0 && t < t1) cuts.push_back(t);
      } else if (std::abs(cross2(w, e)) / e.norm() < tol) {  // collinear: both ends cut
        for (const V2& x : {a, V2(a + s)}) {
          const double t = (x - q0).dot(e) / e.squaredNorm();
          if (t > t0 && t < t1) cuts.push_back(t);
        }
      }
    }
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

// Does the open segment (t0, t1) of the line share more than tol with the open face?
bool line_meets_open_face(const Placed& S, int f, const Vec3& P, const Vec3& D, double t0,
                          double t1, double tol) {
  const std::vector<double> cuts = cuts_on_line(S, f, P, D, t0, t1, tol);
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i + 1] - cuts[i] <= tol) continue;
    if (S.inset(f, P + 0.5 * (cuts[i] + cuts[i + 1]) * D) > tol) return true;
  }
  return false;
}

// Open sub-intervals of the whole line inside the open face.
std::vector<std::pair<double, double>> line_in_open_face(const Placed& S, int f, const Vec3& P,
                                                         const Vec3& D, double tol) {
  const std::vector<double> cuts = cuts_on_line(S, f, P, D, -1e6, 1e6, tol);
  std::vector<std::pair<double, double>> out;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
    if (cuts[i + 1] - cuts[i] > tol && S.inset(f, P + 0.5 * (cuts[i] + cuts[i + 1]) * D) > tol)
      out.push_back({cuts[i], cuts[i + 1]});
  return out;
}

// ---------------------------------------------------------------------------------------
// Open-set touching (docs/spec.md, section 4)
// ---------------------------------------------------------------------------------------

enum class Touch { kNone, kTouch, kPenetrate };

// The open edge (p0, p1) contains the point closest to p, by more than tol from the ends.
bool in_open_edge(const Vec3& p, const Vec3& p0, const Vec3& p1, double tol) {
  const double len = (p1 - p0).norm();
  const double s = (p - p0).dot(p1 - p0) / len;
  return s > tol && s < len - tol;
}

// Open edge (p0, p1) against open face f of S (the edge belongs to the other solid).
Touch touch_edge_face(const Vec3& p0, const Vec3& p1, const Placed& S, int f, double tol) {
  const double h0 = S.plane_dist(f, p0), h1 = S.plane_dist(f, p1);
  if (std::abs(h0) <= tol && std::abs(h1) <= tol) {
    // In the plane: some part of the open edge lies in the open face.
    const double len = (p1 - p0).norm();
    return line_meets_open_face(S, f, p0, (p1 - p0) / len, 0, len, tol) ? Touch::kTouch
                                                                        : Touch::kNone;
  }
  if ((h0 > tol && h1 < -tol) || (h0 < -tol && h1 > tol)) {
    // Crosses the plane at one interior point: inside the open face it pierces the solid.
    const Vec3 x = p0 + (h0 / (h0 - h1)) * (p1 - p0);
    return S.inset(f, x) > tol ? Touch::kPenetrate : Touch::kNone;
  }
  return Touch::kNone;  // meets the plane at an end point at most: that is a vertex touch
}

// Coplanar faces: do the open regions overlap? The boundary of the overlap is made of pieces
// of the two faces' boundaries; each piece lies between two consecutive crossings with the
// other face's boundary, so testing both sides of the midpoint of every such piece finds a
// point in both open regions whenever the overlap is not empty.
bool coplanar_overlap(const Placed& S1, int f1, const Placed& S2, int f2, double tol) {
  const double delta = 20 * tol;
  for (int pass = 0; pass < 2; ++pass) {
    const Placed& P = pass == 0 ? S1 : S2;
    const Placed& Q = pass == 0 ? S2 : S1;
    const int fp = pass == 0 ? f1 : f2, fq = pass == 0 ? f2 : f1;
    const Vec3 n = Q.normal(fq);
    for (const auto& loop : P.m().face(cf::FaceId(fp)).loops)
      for (std::size_t k = 0; k < loop.size(); ++k) {
        const Vec3 a = P.pose.apply(P.m().vertex(loop[k]).p);
        const Vec3 b = P.pose.apply(P.m().vertex(loop[(k + 1) % loop.size()]).p);
        const double len = (b - a).norm();
        const Vec3 D = (b - a) / len, perp = n.cross(D);
        const std::vector<double> cuts = cuts_on_line(Q, fq, a, D, 0, len, tol);
        for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
          if (cuts[i + 1] - cuts[i] <= 2 * delta) continue;
          const Vec3 m = a + 0.5 * (cuts[i] + cuts[i + 1]) * D;
          for (double sg : {-1.0, 1.0}) {
            const Vec3 x = m + sg * delta * perp;
            if (P.inset(fp, x) > tol && Q.inset(fq, x) > tol) return true;
          }
        }
      }
  }
  return false;
}

Touch touch_face_face(const Placed& A, int fa, const Placed& B, int fb, double tol) {
  const Vec3 na = A.normal(fa), nb = B.normal(fb);
  const cf::Face& Fa = A.m().face(cf::FaceId(fa));
  const cf::Face& Fb = B.m().face(cf::FaceId(fb));
  double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
  for (cf::VertexId v : Fa.vertices) {
    const double h = B.plane_dist(fb, A.pose.apply(A.m().vertex(v).p));
    amin = std::min(amin, h);
    amax = std::max(amax, h);
  }
  if (amax <= tol && amin >= -tol) {  // coplanar
    if (!coplanar_overlap(A, fa, B, fb, tol)) return Touch::kNone;
    // Same orientation: both solids on the same side of the shared region.
    return na.dot(nb) < 0 ? Touch::kTouch : Touch::kPenetrate;
  }
  for (cf::VertexId v : Fb.vertices) {
    const double h = A.plane_dist(fa, B.pose.apply(B.m().vertex(v).p));
    bmin = std::min(bmin, h);
    bmax = std::max(bmax, h);
  }
  // The open faces can share points off a common plane only where both straddle the other's
  // plane: then along the planes' intersection line, and that is a transversal crossing.
  if (!(amax > tol && amin < -tol && bmax > tol && bmin < -tol)) return Touch::kNone;
  const double k = na.dot(nb);
  if (std::abs(k) > 1 - 1e-12) return Touch::kNone;
  const double da = A.offset(fa), db = B.offset(fb);
  const Vec3 P = ((da - db * k) * na + (db - da * k) * nb) / (1 - k * k);
  const Vec3 D = na.cross(nb).normalized();
  for (const auto& [a0, a1] : line_in_open_face(A, fa, P, D, tol))
    for (const auto& [b0, b1] : line_in_open_face(B, fb, P, D, tol))
      if (std::min(a1, b1) - std::max(a0, b0) > tol) return Touch::kPenetrate;
  return Touch::kNone;
}

struct TouchResult {
  Touch touch = Touch::kNone;
  bool parallel_ee = false;  // collinear e-e: degenerate
};

// Element a (kind ka) of posed A and element b (kind kb) of B, known to be within tol as
// closed sets: do the open elements share a point?
TouchResult open_touch(const Placed& A, K ka, int a, const Placed& B, K kb, int b, double tol) {
  TouchResult r;
  auto yes = [](bool x) { return x ? Touch::kTouch : Touch::kNone; };
  if (ka == K::kVertex && kb == K::kVertex) {
    r.touch = Touch::kTouch;
  } else if (ka == K::kVertex && kb == K::kEdge) {
    r.touch = yes(in_open_edge(A.vertex(a), B.edge_pt(b, 0), B.edge_pt(b, 1), tol));
  } else if (ka == K::kEdge && kb == K::kVertex) {
    r.touch = yes(in_open_edge(B.vertex(b), A.edge_pt(a, 0), A.edge_pt(a, 1), tol));
  } else if (ka == K::kVertex && kb == K::kFace) {
    const Vec3 p = A.vertex(a);
    r.touch = yes(std::abs(B.plane_dist(b, p)) <= tol && B.inset(b, p) > tol);
  } else if (ka == K::kFace && kb == K::kVertex) {
    const Vec3 p = B.vertex(b);
    r.touch = yes(std::abs(A.plane_dist(a, p)) <= tol && A.inset(a, p) > tol);
  } else if (ka == K::kEdge && kb == K::kEdge) {
    const Vec3 p0 = A.edge_pt(a, 0), p1 = A.edge_pt(a, 1), q0 = B.edge_pt(b, 0),
               q1 = B.edge_pt(b, 1);
    const Vec3 da = (p1 - p0).normalized(), db = (q1 - q0).normalized();
    const Vec3 c = da.cross(db);
    if (c.norm() > 1e-9) {
      // Closest points of the two lines; both strictly inside their edges.
      const Vec3 w = p0 - q0;
      const double bb = da.dot(db), d = da.dot(w), e = db.dot(w);
      const double den = 1 - bb * bb;
      const double s = (bb * e - d) / den, t = (e - bb * d) / den;
      const Vec3 x = p0 + s * da, y = q0 + t * db;
      r.touch = yes((x - y).norm() <= tol && in_open_edge(x, p0, p1, tol) &&
                    in_open_edge(y, q0, q1, tol));
    } else {
      // Parallel (and within tol, so collinear): the open intervals overlap by more than tol.
      const double la = (p1 - p0).norm();
      double s0 = (q0 - p0).dot(da), s1 = (q1 - p0).dot(da);
      if (s0 > s1) std::swap(s0, s1);
      r.touch = yes(std::min(la, s1) - std::max(0.0, s0) > tol);
      r.parallel_ee = true;
    }
  } else if (ka == K::kEdge && kb == K::kFace) {
    r.touch = touch_edge_face(A.edge_pt(a, 0), A.edge_pt(a, 1), B, b, tol);
  } else if (ka == K::kFace && kb == K::kEdge) {
    r.touch = touch_edge_face(B.edge_pt(b, 0), B.edge_pt(b, 1), A, a, tol);
  } else {
    r.touch = touch_face_face(A, a, B, b, tol);
  }
  return r;
}

// Element (k, i) is (k2, j) or lies on its boundary (the domination of docs/spec.md, section 4).
bool within_closure(const Polyhedron& m, K k, int i, K k2, int j) {
  if (k == k2) return i == j;
  if (k == K::kVertex && k2 == K::kEdge) {
    const cf::Edge& e = m.edges()[static_cast<std::size_t>(j)];
    return e.v0.value() == i || e.v1.value() == i;
  }
  if (k == K::kVertex && k2 == K::kFace) {
    const auto& vs = m.faces()[static_cast<std::size_t>(j)].vertices;
    return std::find(vs.begin(), vs.end(), cf::VertexId(i)) != vs.end();
  }
  if (k == K::kEdge && k2 == K::kFace) {
    const cf::Edge& e = m.edges()[static_cast<std::size_t>(i)];
    return e.left.value() == j || e.right.value() == j;
  }
  return false;
}

// Odd number of crossings of a ray from q (model frame) with the faces.
bool ray_cast_inside(const Placed& S, const Vec3& q) {
  static const Vec3 dirs[] = {
      Vec3(0.5377, 0.8323, 0.1357).normalized(), Vec3(-0.3121, 0.1743, 0.9339).normalized(),
      Vec3(0.7071, -0.5003, 0.4999).normalized(), Vec3(-0.1234, -0.9111, -0.3932).normalized(),
      Vec3(0.9436, 0.2317, -0.2367).normalized()};
  for (const Vec3& dir : dirs) {
    int crossings = 0;
    bool bad = false;
    for (const FaceGeom& F : S.g->faces) {
      const double den = F.n.dot(dir);
      if (std::abs(den) < 1e-9)
        continue;  // parallel: no crossing (q in the plane fails the margin)
      const double t = (F.d - F.n.dot(q)) / den;
      if (t <= 0) continue;
      const Vec3 h = q + t * dir;
      const double s = inset2d(F, {F.u.dot(h), F.w.dot(h)});
      if (std::abs(s) < 1e-6) {
        bad = true;
        break;
      }
      if (s > 0) ++crossings;
    }
    if (!bad) return crossings % 2 == 1;
  }
  return false;
}

// Strictly inside the placed solid (by more than margin from its boundary): ray casting in
// the model frame, with rays that graze a face's boundary retried in another direction. A
// point on the boundary may cast either way; the margin test after the cast rejects it.
bool inside_solid(const Placed& S, const Vec3& p_world, double margin) {
  const Polyhedron& m = S.m();
  const Vec3 q = S.pose.inverse_apply(p_world);
  if (!ray_cast_inside(S, q)) return false;
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    if (cf::point_face(q, m, cf::FaceId(static_cast<int>(f))).distance <= margin) return false;
  return true;
}

// ---------------------------------------------------------------------------------------
// Pose analysis: the CF that a pose realises, computed from the geometry alone
// ---------------------------------------------------------------------------------------

struct Contact {
  K ka;
  int a;
  K kb;
  int b;
  bool parallel_ee = false;
  Vec3 point;
};

struct ContactPlane {
  Vec3 n;    // unit, pointing from B into A
  double d;  // n . x = d
};

struct Analysis {
  std::vector<Contact> touching;
  std::vector<Contact> undominated;
  bool penetrating = false;
  std::string why;     // what penetrates
  int degenerate = 0;  // undominated touches of degenerate type (v-v, v-e, e-v, collinear e-e)
  bool shared_plane = false;
  bool too_many = false;             // more than 3 PCs
  PcSet pcs;                         // the PCs, when none of the above
  std::vector<ContactPlane> planes;  // of the non-degenerate undominated touches
  std::vector<Vec3> points;          // their contact points

  bool contact() const { return !touching.empty(); }
  bool clean() const {
    return contact() && !penetrating && degenerate == 0 && !shared_plane && !too_many;
  }
  std::string signature() const {
    std::ostringstream os;
    os << penetrating << degenerate << shared_plane << too_many << ":" << cf::to_string(pcs);
    return os.str();
  }
  std::string describe() const {
    std::ostringstream os;
    os << "touching:";
    for (const Contact& c : touching)
      os << " "
         << "vef"[static_cast<int>(c.ka)] << c.a << "-"
         << "vef"[static_cast<int>(c.kb)] << c.b;
    os << " | undominated:";
    for (const Contact& c : undominated)
      os << " "
         << "vef"[static_cast<int>(c.ka)] << c.a << "-"
         << "vef"[static_cast<int>(c.kb)] << c.b << (c.parallel_ee ? "(collinear)" : "");
    if (penetrating) os << " | PENETRATING: " << why;
    if (shared_plane) os << " | two PCs share a contact plane";
    return os.str();
  }
};

std::optional<PcType> pc_type(K ka, K kb, bool parallel_ee) {
  if (ka == K::kFace && kb == K::kFace) return PcType::kFF;
  if (ka == K::kEdge && kb == K::kFace) return PcType::kEF;
  if (ka == K::kFace && kb == K::kEdge) return PcType::kFE;
  if (ka == K::kVertex && kb == K::kFace) return PcType::kVF;
  if (ka == K::kFace && kb == K::kVertex) return PcType::kFV;
  if (ka == K::kEdge && kb == K::kEdge && !parallel_ee) return PcType::kEE;
  return std::nullopt;
}

ContactPlane contact_plane(const Placed& A, const Placed& B, const Contact& c) {
  if (c.kb == K::kFace) return {B.normal(c.b), B.offset(c.b)};
  if (c.ka == K::kFace) return {-A.normal(c.a), -A.offset(c.a)};
  // e-e: the plane of both edges, oriented along B's edge's outward bisector.
  const Vec3 da = A.edge_pt(c.a, 1) - A.edge_pt(c.a, 0), db = B.edge_pt(c.b, 1) - B.edge_pt(c.b, 0);
  Vec3 n = da.cross(db).normalized();
  const cf::Edge& eb = B.m().edges()[static_cast<std::size_t>(c.b)];
  const Vec3 bis = B.normal(eb.left.value()) + B.normal(eb.right.value());
  if (n.dot(bis) < 0) n = -n;
  return {n, n.dot(c.point)};
}

bool same_plane(const ContactPlane& x, const ContactPlane& y) {
  if (x.n.cross(y.n).norm() > kPlaneTol) return false;
  const double sg = x.n.dot(y.n) > 0 ? 1.0 : -1.0;
  return std::abs(x.d - sg * y.d) <= kPlaneTol * 10;
}

Analysis analyse(const ModelGeom& ga, const ModelGeom& gb, const Pose& pose, double tol) {
  const Placed A{&ga, pose}, B{&gb, Pose()};
  Analysis out;
  // Whole-model bounding spheres first: far apart means no contact at all.
  if ((pose.apply(ga.center) - gb.center).norm() > ga.radius + gb.radius + tol) return out;
  const K kinds[] = {K::kVertex, K::kEdge, K::kFace};
  std::vector<std::pair<Vec3, double>> sb[3];
  for (K kb : kinds)
    for (int b = 0; b < count(*gb.m, kb); ++b) sb[static_cast<int>(kb)].push_back(B.sphere(kb, b));
  for (K ka : kinds)
    for (int a = 0; a < count(*ga.m, ka); ++a) {
      const auto [ca, ra] = A.sphere(ka, a);
      for (K kb : kinds)
        for (int b = 0; b < count(*gb.m, kb); ++b) {
          const auto& [cb, rb] = sb[static_cast<int>(kb)][static_cast<std::size_t>(b)];
          if ((ca - cb).norm() - ra - rb > tol) continue;
          const cf::ClosestPoints cp = cf::element_distance(*ga.m, pose, ka, a, *gb.m, kb, b);
          if (cp.distance > tol) continue;
          const TouchResult t = open_touch(A, ka, a, B, kb, b, tol);
          if (t.touch == Touch::kPenetrate && !out.penetrating) {
            out.penetrating = true;
            out.why = std::string("open ") + "vef"[static_cast<int>(ka)] + std::to_string(a) +
                      " crosses open " + "vef"[static_cast<int>(kb)] + std::to_string(b);
          }
          if (t.touch != Touch::kNone)
            out.touching.push_back({ka, a, kb, b, t.parallel_ee, 0.5 * (cp.p_a + cp.p_b)});
        }
    }
  if (out.touching.empty()) return out;
  // Domination.
  for (const Contact& c : out.touching) {
    bool dominated = false;
    for (const Contact& o : out.touching)
      if (&o != &c && within_closure(*ga.m, c.ka, c.a, o.ka, o.a) &&
          within_closure(*gb.m, c.kb, c.b, o.kb, o.b))
        dominated = true;
    if (!dominated) out.undominated.push_back(c);
  }
  std::vector<Pc> pcs;
  for (const Contact& c : out.undominated) {
    const auto t = pc_type(c.ka, c.kb, c.parallel_ee);
    if (!t) {
      ++out.degenerate;
      continue;
    }
    pcs.push_back({*t, c.a, c.b});
    out.planes.push_back(contact_plane(A, B, c));
    out.points.push_back(c.point);
  }
  for (std::size_t i = 0; i < out.planes.size(); ++i)
    for (std::size_t j = i + 1; j < out.planes.size(); ++j)
      if (same_plane(out.planes[i], out.planes[j])) out.shared_plane = true;
  if (pcs.size() > 3)
    out.too_many = true;
  else if (out.degenerate == 0)
    out.pcs = PcSet(pcs);
  // Interiors disjoint: no vertex of one strictly inside the other (edges crossing faces
  // transversally were reported above), and no probe point next to a contact inside both.
  for (int v = 0; v < count(*ga.m, K::kVertex) && !out.penetrating; ++v)
    if (inside_solid(B, A.vertex(v), kInsideMargin)) {
      out.penetrating = true;
      out.why = "vertex v" + std::to_string(v) + " of A inside B";
    }
  for (int v = 0; v < count(*gb.m, K::kVertex) && !out.penetrating; ++v)
    if (inside_solid(A, B.vertex(v), kInsideMargin)) {
      out.penetrating = true;
      out.why = "vertex v" + std::to_string(v) + " of B inside A";
    }
  for (const Contact& c : out.touching) {
    if (out.penetrating) break;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Vec3 x = c.point + kProbeRadius * Vec3(dx, dy, dz).normalized();
          if (!out.penetrating && inside_solid(A, x, kInsideMargin) &&
              inside_solid(B, x, kInsideMargin)) {
            out.penetrating = true;
            out.why = "probe point " + vec_str(x) + " inside both";
          }
        }
  }
  return out;
}

// Smallest closed distance (mm) between element pairs that do not touch at `pose`, up to
// `cap`: how far the pose is from gaining another contact.
double pose_clearance(const ModelGeom& ga, const ModelGeom& gb, const Pose& pose, double cap) {
  const Placed A{&ga, pose}, B{&gb, Pose()};
  double best = cap;
  const K kinds[] = {K::kVertex, K::kEdge, K::kFace};
  for (K ka : kinds)
    for (int a = 0; a < count(*ga.m, ka); ++a)
      for (K kb : kinds)
        for (int b = 0; b < count(*gb.m, kb); ++b) {
          const auto [ca, ra] = A.sphere(ka, a);
          const auto [cb, rb] = B.sphere(kb, b);
          if ((ca - cb).norm() - ra - rb >= best) continue;
          const double d = cf::element_distance(*ga.m, pose, ka, a, *gb.m, kb, b).distance;
          if (d > kTouchTol) best = std::min(best, d);
        }
  return best;
}

// ---------------------------------------------------------------------------------------
// Section 2: witnesses
// ---------------------------------------------------------------------------------------

void check_witnesses(const Generated& g, const std::string& label) {
  const ModelGeom ga(*g.A), gb(*g.B);
  std::size_t ok = 0, bad = 0;
  std::size_t by_size[4] = {0, 0, 0, 0};
  std::ostringstream failures;
  for (std::size_t i = 0; i < g.graph->num_cfs(); ++i) {
    const cf::CfRecord& r = g.graph->cf(cf::CfId(static_cast<int>(i)));
    const Analysis an = analyse(ga, gb, r.witness, kTouchTol);
    std::string why;
    if (!an.contact())
      why = "no contact at the witness";
    else if (an.penetrating)
      why = "interiors intersect";
    else if (an.degenerate)
      why = "degenerate undominated touch";
    else if (an.shared_plane)
      why = "two PCs share a contact plane";
    else if (an.too_many)
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

// Smallest s >= s_min at which A, translated from `pose` by s * u, first touches B (closed
// sets); infinity when it never does. Under a translation the first contact is a vertex
// reaching a face, a face reaching a vertex, or an edge reaching an edge.
double first_contact(const ModelGeom& ga, const ModelGeom& gb, const Pose& pose, const Vec3& u,
                     double s_min) {
  const Polyhedron& A = *ga.m;
  const Polyhedron& B = *gb.m;
  const Placed PA{&ga, pose};
  double best = std::numeric_limits<double>::infinity();
  std::vector<Vec3> va;
  for (int i = 0; i < count(A, K::kVertex); ++i) va.push_back(PA.vertex(i));
  constexpr double kIn = -1e-9;  // closed face: the boundary counts
  for (const FaceGeom& F : gb.faces) {
    const double den = F.n.dot(u);
    if (den > -1e-12) continue;  // only approaching the face from its front
    for (const Vec3& p : va) {
      const double s = (F.d - F.n.dot(p)) / den;
      if (s < s_min || s >= best) continue;
      const Vec3 h = p + s * u;
      if (inset2d(F, {F.u.dot(h), F.w.dot(h)}) >= kIn) best = s;
    }
  }
  for (int f = 0; f < count(A, K::kFace); ++f) {
    const Vec3 m = PA.normal(f);
    const double den = m.dot(u);
    if (den < 1e-12) continue;
    const double e = PA.offset(f);
    const FaceGeom& F = ga.faces[static_cast<std::size_t>(f)];
    for (const cf::Vertex& vb : B.vertices()) {
      const double s = (m.dot(vb.p) - e) / den;
      if (s < s_min || s >= best) continue;
      const Vec3 x = pose.inverse_apply(vb.p - s * u);
      if (inset2d(F, {F.u.dot(x), F.w.dot(x)}) >= kIn) best = s;
    }
  }
  for (int ea = 0; ea < count(A, K::kEdge); ++ea) {
    const Vec3 p0 = PA.edge_pt(ea, 0), da = PA.edge_pt(ea, 1) - p0;
    for (int eb = 0; eb < count(B, K::kEdge); ++eb) {
      const Vec3 q0 = B.edge_point(cf::EdgeId(eb), 0), db = B.edge_point(cf::EdgeId(eb), 1) - q0;
      Mat3 M;
      M << u, da, -db;
      const double det = M.determinant();
      if (std::abs(det) < 1e-9 * da.norm() * db.norm()) continue;
      const Vec3 x = M.inverse() * (q0 - p0);
      if (x(0) < s_min || x(0) >= best) continue;
      if (x(1) < -1e-12 || x(1) > 1 + 1e-12 || x(2) < -1e-12 || x(2) > 1 + 1e-12) continue;
      best = x(0);
    }
  }
  return best;
}

struct RecallStats {
  int trials = 0, missed_b = 0, poses = 0, no_contact = 0, penetrating = 0, ambiguous = 0,
      degenerate = 0, shared_plane = 0, too_many = 0, clean = 0, clean_found = 0;
  std::map<std::vector<Pc>, Pose> reached;  // distinct clean CFs, with the first pose
  std::map<std::vector<Pc>, std::pair<Pose, std::string>> missing;
  std::vector<std::string> penetrations;
};

class Explorer {
 public:
  Explorer(const Generated& g, std::uint32_t seed) : g_(g), ga_(*g.A), gb_(*g.B), rng_(seed) {
    for (std::size_t e = 0; e < g.B->num_edges(); ++e)
      if (!g.B->edges()[e].convex) reflex_.push_back(static_cast<int>(e));
  }

  RecallStats run(int trials) {
    for (int i = 0; i < trials; ++i) trial();
    return st_;
  }

 private:
  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
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
  Vec3 random_point_on_edge(int e) {
    const double s = uni(0.05, 0.95);
    return (1 - s) * g_.B->edge_point(cf::EdgeId(e), 0) + s * g_.B->edge_point(cf::EdgeId(e), 1);
  }
  Vec3 reflex_bisector(int e) const {
    const cf::Edge& E = g_.B->edges()[static_cast<std::size_t>(e)];
    return (g_.B->face(E.left).normal + g_.B->face(E.right).normal).normalized();
  }
  Vec3 point_on_b_face(int f) {
    const cf::Face& F = g_.B->faces()[static_cast<std::size_t>(f)];
    const FaceGeom& G = gb_.faces[static_cast<std::size_t>(f)];
    double u0 = 1e300, u1 = -1e300, w0 = 1e300, w1 = -1e300;
    for (const auto& loop : G.loops)
      for (const V2& p : loop) {
        u0 = std::min(u0, p.x()), u1 = std::max(u1, p.x());
        w0 = std::min(w0, p.y()), w1 = std::max(w1, p.y());
      }
    for (int k = 0; k < 100; ++k) {
      const V2 q(uni(u0, u1), uni(w0, w1));
      if (inset2d(G, q) > 0.5) return q.x() * G.u + q.y() * G.w + G.d * G.n;
    }
    return F.centroid;
  }

  // Classifies a pose, counts it, and checks the graph.
  Analysis record(const Pose& pose) {
    ++st_.poses;
    const Analysis fine = analyse(ga_, gb_, pose, kTouchTol);
    history_ += " -> {" + fine.describe() + "} at " + pose_str(pose) + "\n";
    if (!fine.contact()) {
      ++st_.no_contact;
      return fine;
    }
    const Analysis coarse = analyse(ga_, gb_, pose, kCoarseTol);
    if (fine.penetrating && coarse.penetrating) {
      ++st_.penetrating;
      if (st_.penetrations.size() < 5)
        st_.penetrations.push_back(fine.describe() + " at " + pose_str(pose) + " after " +
                                   history_);
      return fine;
    }
    // Includes slivers: nearly coplanar faces (a tilt of 1e-4 rad) that cross over less
    // than the fine tolerance's worth of depth.
    if (coarse.signature() != fine.signature()) {
      ++st_.ambiguous;
      return fine;
    }
    if (fine.degenerate)
      ++st_.degenerate;
    else if (fine.too_many)
      ++st_.too_many;
    else if (fine.shared_plane)
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

  // A, from a start pose clear of B, moved along u until it touches; nullopt when it misses.
  std::optional<Pose> guarded(const Pose& start, const Vec3& u, double s_min) {
    const double s = first_contact(ga_, gb_, start, u, s_min);
    if (!std::isfinite(s)) return std::nullopt;
    return translated(start, s * u);
  }

  void trial() {
    ++st_.trials;
    const Polyhedron& A = *g_.A;
    const Polyhedron& B = *g_.B;
    Mat3 R;
    Vec3 u, target;
    switch (pick(reflex_.empty() ? 4 : 5)) {
      case 4: {  // towards a concave corner of B, any orientation
        const int eb = reflex_[static_cast<std::size_t>(pick(static_cast<int>(reflex_.size())))];
        R = random_rotation();
        target = random_point_on_edge(eb);
        u = (-reflex_bisector(eb) + 0.7 * random_unit()).normalized();
        break;
      }
      case 0:  // anything
        R = random_rotation();
        target = B.bbox_min() +
                 (B.bbox_max() - B.bbox_min()).cwiseProduct(Vec3(uni(0, 1), uni(0, 1), uni(0, 1)));
        u = random_unit();
        break;
      case 1: {  // a face of A parallel to a face of B, approaching it
        const int fa = pick(count(A, K::kFace)), fb = pick(count(B, K::kFace));
        const Vec3 nb = B.faces()[static_cast<std::size_t>(fb)].normal;
        R = spin(nb) * align(A.faces()[static_cast<std::size_t>(fa)].normal, -nb);
        target = point_on_b_face(fb);
        u = pick(3) ? -nb : (random_unit() - 2 * nb).normalized();
        break;
      }
      case 2: {  // an edge of A parallel to a face of B
        const int ea = pick(count(A, K::kEdge)), fb = pick(count(B, K::kFace));
        const cf::Edge& e = A.edges()[static_cast<std::size_t>(ea)];
        const Vec3 bis = (A.face(e.left).normal + A.face(e.right).normal).normalized();
        const Vec3 nb = B.faces()[static_cast<std::size_t>(fb)].normal;
        R = spin(nb) * align(bis, -nb);
        target = point_on_b_face(fb);
        u = pick(3) ? -nb : (random_unit() - 2 * nb).normalized();
        break;
      }
      default: {  // a face of A square to the bisector of an edge of B
        const int fa = pick(count(A, K::kFace)), eb = pick(count(B, K::kEdge));
        const cf::Edge& e = B.edges()[static_cast<std::size_t>(eb)];
        const Vec3 bis = (B.face(e.left).normal + B.face(e.right).normal).normalized();
        R = spin(bis) * align(A.faces()[static_cast<std::size_t>(fa)].normal, -bis);
        const double s = uni(0.05, 0.95);
        target = (1 - s) * B.edge_point(cf::EdgeId(eb), 0) + s * B.edge_point(cf::EdgeId(eb), 1);
        u = pick(3) ? -bis : (random_unit() - 2 * bis).normalized();
        break;
      }
    }
    // Start well clear of B's bounding sphere, on the line through the target.
    Pose start;
    start.R_BA = R;
    start.t_BA = target - u * (ga_.radius + 2 * gb_.radius + 1) - R * ga_.center;
    history_ = "approach from " + pose_str(start) + " along " + vec_str(u);
    std::optional<Pose> pose = guarded(start, u, 0);
    if (!pose) {
      ++st_.missed_b;
      return;
    }
    Analysis an = record(*pose);
    const int steps = 1 + pick(8);
    for (int k = 0; k < steps; ++k) {
      if (!an.contact() || an.penetrating || an.planes.empty()) return;
      std::optional<Pose> next;
      switch (pick(5)) {
        case 0:
        case 1:
          history_ += ", slide";
          next = slide(*pose, an);
          break;
        case 2:
        case 3:
          history_ += ", snap";
          next = snap(*pose, an);
          break;
        default:
          history_ += ", tilt";
          next = tilt(*pose, an);
          break;
      }
      if (!next) return;
      pose = next;
      an = record(*pose);
    }
  }

  // Translates along the contact planes (keeping every contact) until a new contact, or
  // for a random length and then presses A back against B along a contact normal.
  std::optional<Pose> slide(const Pose& pose, const Analysis& an) {
    Eigen::MatrixXd N(static_cast<Eigen::Index>(an.planes.size()), 3);
    for (std::size_t i = 0; i < an.planes.size(); ++i)
      N.row(static_cast<Eigen::Index>(i)) = an.planes[i].n.transpose();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(N, Eigen::ComputeFullV);
    const auto& sv = svd.singularValues();
    int rank = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      if (sv(i) > 1e-9) ++rank;
    if (rank >= 3) return tilt(pose, an);
    Vec3 u = Vec3::Zero();
    if (!reflex_.empty() && pick(2) == 0) {
      // Towards a concave corner of B, within the contact planes.
      const int eb = reflex_[static_cast<std::size_t>(pick(static_cast<int>(reflex_.size())))];
      const Vec3 d = random_point_on_edge(eb) - an.points[0];
      for (int c = rank; c < 3; ++c) u += d.dot(svd.matrixV().col(c)) * svd.matrixV().col(c);
    } else {
      for (int c = rank; c < 3; ++c) u += uni(-1, 1) * svd.matrixV().col(c);
    }
    if (u.norm() < 1e-6) return std::nullopt;
    u.normalize();
    const double s = first_contact(ga_, gb_, pose, u, 1e-7);
    const double len = uni(5, 80);
    // A touch already present (a dominated one off the contact planes, such as an edge of A
    // through a vertex of B) may block the slide at once; first_contact ignores s = 0.
    if (analyse(ga_, gb_, translated(pose, std::min(1e-3, 0.5 * std::min(s, len)) * u), kTouchTol)
            .penetrating)
      return std::nullopt;
    if (s <= len) return translated(pose, s * u);
    const Vec3 n = an.planes[static_cast<std::size_t>(pick(static_cast<int>(an.planes.size())))].n;
    return guarded(translated(pose, len * u), -n, -1e-9);
  }

  // Rotates about a contact to bring a neighbouring element flat against the other solid
  // (v-f -> e-f, e-f -> f-f, f-e -> f-f, f-v -> f-e, e-e -> e-f), then re-establishes
  // contact if the rotation pushed A into B or off it.
  std::optional<Pose> snap(const Pose& pose, const Analysis& an) {
    const Polyhedron& A = *g_.A;
    const Polyhedron& B = *g_.B;
    const Placed PA{&ga_, pose}, PB{&gb_, Pose()};
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < an.undominated.size(); ++i)
      if (pc_type(an.undominated[i].ka, an.undominated[i].kb, an.undominated[i].parallel_ee))
        idx.push_back(i);
    if (idx.empty()) return std::nullopt;
    const std::size_t i = idx[static_cast<std::size_t>(pick(static_cast<int>(idx.size())))];
    const Contact& c = an.undominated[i];
    const ContactPlane cp = contact_plane(PA, PB, c);
    const PcType t = *pc_type(c.ka, c.kb, c.parallel_ee);
    Mat3 Q = Mat3::Identity();
    Vec3 pivot = c.point;
    auto flatten_dir = [&](const Vec3& d, const Vec3& n) {  // rotate d into the plane normal to n
      const Vec3 dp = d - d.dot(n) * n;
      return dp.norm() < 1e-9 ? Mat3(Mat3::Identity()) : align(d.normalized(), dp.normalized());
    };
    switch (t) {
      case PcType::kVF: {
        const auto& es = A.vertices()[static_cast<std::size_t>(c.a)].edges;
        const int e = es[static_cast<std::size_t>(pick(static_cast<int>(es.size())))].value();
        const Vec3 p = PA.vertex(c.a);
        const Vec3 other =
            (PA.edge_pt(e, 0) - p).norm() < 1e-9 ? PA.edge_pt(e, 1) : PA.edge_pt(e, 0);
        Q = flatten_dir(other - p, cp.n);
        pivot = p;
        break;
      }
      case PcType::kEF: {
        const cf::Edge& e = A.edges()[static_cast<std::size_t>(c.a)];
        const int f = pick(2) ? e.left.value() : e.right.value();
        Q = align(PA.normal(f), -cp.n);
        break;
      }
      case PcType::kFE: {
        const cf::Edge& e = B.edges()[static_cast<std::size_t>(c.b)];
        const int f = pick(2) ? e.left.value() : e.right.value();
        Q = align(PA.normal(c.a), -PB.normal(f));
        break;
      }
      case PcType::kFV: {
        const auto& es = B.vertices()[static_cast<std::size_t>(c.b)].edges;
        const int e = es[static_cast<std::size_t>(pick(static_cast<int>(es.size())))].value();
        const Vec3 d = B.edge_point(cf::EdgeId(e), 1) - B.edge_point(cf::EdgeId(e), 0);
        const Vec3 m = PA.normal(c.a);
        const Vec3 mp = m - m.dot(d.normalized()) * d.normalized();
        Q = align(m, mp.normalized());
        pivot = PB.vertex(c.b);
        break;
      }
      case PcType::kEE: {
        const cf::Edge& e = B.edges()[static_cast<std::size_t>(c.b)];
        const int f = pick(2) ? e.left.value() : e.right.value();
        Q = flatten_dir(PA.edge_pt(c.a, 1) - PA.edge_pt(c.a, 0), PB.normal(f));
        break;
      }
      case PcType::kFF:
        return tilt(pose, an);
    }
    return resettle(rotate_about(pose, Q, pivot), cp.n);
  }

  // Small random rotation about a contact point, then contact re-established.
  std::optional<Pose> tilt(const Pose& pose, const Analysis& an) {
    const std::size_t i = static_cast<std::size_t>(pick(static_cast<int>(an.planes.size())));
    const Mat3 Q = axis_angle(random_unit(), uni(0.01, 0.3));
    return resettle(rotate_about(pose, Q, an.points[i]), an.planes[i].n);
  }

  // After a rotation: if A now penetrates B, back it off along n until clear; then press it
  // against B along -n.
  std::optional<Pose> resettle(const Pose& rotated, const Vec3& n) {
    Pose p = rotated;
    const Analysis an = analyse(ga_, gb_, p, kTouchTol);
    if (an.contact() && !an.penetrating) return p;
    if (an.penetrating) {
      p = translated(p, 40 * n);
      const Analysis clear = analyse(ga_, gb_, p, kTouchTol);
      if (clear.contact()) return std::nullopt;
    }
    return guarded(p, -n, -1e-9);
  }

  const Generated& g_;
  ModelGeom ga_, gb_;
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
  const ModelGeom ex_ga(*g.A), ex_gb(*g.B);
  for (const auto& [pcs, v] : st.missing) {
    if (++n > 25) break;
    std::string why;
    const double clearance = search.verify(PcSet(pcs), v.first, &why);
    os << "  {" << cf::to_string(PcSet(pcs)) << "} at " << pose_str(v.first)
       << " (clearance of that pose " << pose_clearance(ex_ga, ex_gb, v.first, 1.0)
       << " mm; cfgen's verify: "
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

// docs/spec.md, section 4: neighbouring PCs, one step through a degenerate touch, "under the
// matching boundary relations". `x` is the PC with the larger element(s).
bool neighbour_dir(const Pc& x, const Pc& y, const Polyhedron& A, const Polyhedron& B) {
  auto edge_bounds = [](const Polyhedron& m, int e, int f) {
    return within_closure(m, K::kEdge, e, K::kFace, f);
  };
  auto vertex_ends = [](const Polyhedron& m, int v, int e) {
    return within_closure(m, K::kVertex, v, K::kEdge, e);
  };
  using T = PcType;
  if (x.type == T::kFF && y.type == T::kEF) return x.b == y.b && edge_bounds(A, y.a, x.a);
  if (x.type == T::kFF && y.type == T::kFE) return x.a == y.a && edge_bounds(B, y.b, x.b);
  if (x.type == T::kEF && y.type == T::kVF) return x.b == y.b && vertex_ends(A, y.a, x.a);
  if (x.type == T::kEF && y.type == T::kEE) return x.a == y.a && edge_bounds(B, y.b, x.b);
  if (x.type == T::kFE && y.type == T::kFV) return x.a == y.a && vertex_ends(B, y.b, x.b);
  if (x.type == T::kFE && y.type == T::kEE) return x.b == y.b && edge_bounds(A, y.a, x.a);
  if (x.type == T::kVF && y.type == T::kEE)
    return vertex_ends(A, x.a, y.a) && edge_bounds(B, y.b, x.b);
  if (x.type == T::kFV && y.type == T::kEE)
    return vertex_ends(B, x.b, y.b) && edge_bounds(A, y.a, x.a);
  return false;
}
bool neighbours(const Pc& x, const Pc& y, const Polyhedron& A, const Polyhedron& B) {
  return neighbour_dir(x, y, A, B) || neighbour_dir(y, x, A, B);
}

// Same size, different, and some pairing maps each PC to an equal or neighbouring PC.
bool is_change(const PcSet& s, const PcSet& t, const Polyhedron& A, const Polyhedron& B) {
  if (s.size() != t.size() || s == t) return false;
  std::vector<int> perm(static_cast<std::size_t>(t.size()));
  for (int i = 0; i < t.size(); ++i) perm[static_cast<std::size_t>(i)] = i;
  do {
    bool ok = true;
    for (int i = 0; i < s.size() && ok; ++i) {
      const Pc& x = s[i];
      const Pc& y = t[perm[static_cast<std::size_t>(i)]];
      ok = x == y || neighbours(x, y, A, B);
    }
    if (ok) return true;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return false;
}
bool is_subset_plus_one(const PcSet& small, const PcSet& big) {
  if (big.size() != small.size() + 1) return false;
  for (const Pc& p : small)
    if (!big.contains(p)) return false;
  return true;
}

void check_transitions(const Generated& g, const std::string& label) {
  const cf::CfGraph& G = *g.graph;
  const Polyhedron& A = *g.A;
  const Polyhedron& B = *g.B;
  const std::size_t n = G.num_cfs();
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
    all.insert({t.from.value(), t.to.value(), static_cast<int>(t.kind)});
    ++kinds[static_cast<int>(t.kind)];
    const std::string desc = std::string(cf::to_string(t.kind)) + " {" + cf::to_string(from) +
                             "} -> {" + cf::to_string(to) + "}";
    if (t.kind == cf::TransitionKind::kGain && !is_subset_plus_one(from, to))
      fail(desc + ": not exactly one PC gained");
    if (t.kind == cf::TransitionKind::kLose && !is_subset_plus_one(to, from))
      fail(desc + ": not exactly one PC lost");
    if (t.kind == cf::TransitionKind::kChange && !is_change(from, to, A, B))
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
        if (!is_change(s, t, A, B)) continue;
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
std::set<std::vector<Pc>> allowed_single_pcs(const Polyhedron& A, const Polyhedron& B) {
  std::set<int> nonpointed;
  for (const cf::Edge& e : B.edges())
    if (!e.convex) {
      nonpointed.insert(e.v0.value());
      nonpointed.insert(e.v1.value());
    }
  std::set<std::vector<Pc>> out;
  for (PcType t : {PcType::kFF, PcType::kEF, PcType::kFE, PcType::kVF, PcType::kFV, PcType::kEE})
    for (int a = 0; a < count(A, cf::a_kind(t)); ++a)
      for (int b = 0; b < count(B, cf::b_kind(t)); ++b) {
        if ((t == PcType::kFE || t == PcType::kEE) &&
            !B.edges()[static_cast<std::size_t>(b)].convex)
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
  const auto allowed = allowed_single_pcs(*g.A, *g.B);
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
// outward normal dst[k], cube centred at `center`. Returns the pose and checks with this
// file's own analysis that it realises exactly those f-f PCs.
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

// A CF derived by hand, with a witness built by hand: this file's analysis must confirm the
// witness, and the graph must hold the CF. When it does not, the message says what cfgen's
// own pose verification thinks of the hand witness (accepted: its search missed the CF).
void check_hand_cf(const Generated& g, const ModelGeom& ga, const ModelGeom& gb, const PcSet& s,
                   const Pose& p) {
  const Analysis an = analyse(ga, gb, p, kTouchTol);
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
// like a hand witness (this file's analysis must confirm the PCs; the graph must hold them).
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
  const ModelGeom ga(*g.A), gb(*g.B);
  for (const KnownPose* k = begin; k != end; ++k) {
    std::vector<Pc> pcs;
    std::stringstream ss(k->pcs);
    for (std::string item; std::getline(ss, item, ';');) pcs.push_back(*cf::pc_from_string(item));
    Pose p;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p.R_BA(r, c) = k->R[static_cast<std::size_t>(3 * r + c)];
    p.t_BA = Vec3(k->t[0], k->t[1], k->t[2]);
    check_hand_cf(g, ga, gb, PcSet(pcs), p);
  }
}

}  // namespace

// =======================================================================================
// 0. The oracle: this file's contact analysis on poses whose answer is known
// =======================================================================================

TEST_CASE("cfgen test oracle: contact analysis of known poses", "[cfgen][oracle]") {
  const Polyhedron A = load("cube.off"), B = load("l_block.off");
  const ModelGeom ga(A), gb(B);
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
  const Analysis flat = analyse(ga, gb, at(Mat3::Identity(), Vec3(70, 35, 40)), kTouchTol);
  CHECK(flat.clean());
  CHECK(flat.pcs == PcSet({Pc{PcType::kFF, bottom, floor}}));
  CHECK(flat.touching.size() == 9);  // the face, its 4 edges, its 4 vertices
  // 1 micrometre into the floor, or above it.
  CHECK(analyse(ga, gb, at(Mat3::Identity(), Vec3(70, 35 - 1e-3, 40)), kTouchTol).penetrating);
  CHECK_FALSE(analyse(ga, gb, at(Mat3::Identity(), Vec3(70, 35 + 1e-3, 40)), kTouchTol).contact());
  // Against the wall as well (x = 20): two f-f, with distinct contact planes.
  const Analysis corner = analyse(ga, gb, at(Mat3::Identity(), Vec3(35, 35, 40)), kTouchTol);
  CHECK(corner.clean());
  CHECK(corner.pcs ==
        PcSet({Pc{PcType::kFF, bottom, floor},
               Pc{PcType::kFF, cube_face(A, -Vec3::UnitX()), face_with(B, Vec3::UnitX(), 20)}}));
  // On an edge: 45 degrees about z, the lowest edge (along z) on the floor.
  const Mat3 Rz = axis_angle(Vec3::UnitZ(), M_PI / 4);
  const Analysis edge = analyse(ga, gb, at(Rz, Vec3(70, 20 + 15 * std::sqrt(2.0), 40)), kTouchTol);
  CHECK(edge.clean());
  REQUIRE(edge.pcs.size() == 1);
  CHECK(edge.pcs[0].type == PcType::kEF);
  CHECK(edge.pcs[0].b == floor);
  // On a vertex: a generic tilt, the lowest vertex on the floor.
  const Mat3 Rg = axis_angle(Vec3(0.3, 0.5, 0.8), 0.4);
  int lo = 0;
  for (int v = 1; v < 8; ++v)
    if ((Rg * A.vertices()[v].p).y() < (Rg * A.vertices()[lo].p).y()) lo = v;
  const Analysis vertex =
      analyse(ga, gb, at(Rg, Vec3(70, 20 - (Rg * A.vertices()[lo].p).y(), 40)), kTouchTol);
  CHECK(vertex.clean());
  CHECK(vertex.pcs == PcSet({Pc{PcType::kVF, lo, floor}}));
  // A vertex on a convex edge of B (the top edge of the floor's end, x = 120, y = 20), the
  // cube beyond the plane through the edge square to its bisector: a degenerate v-e touch.
  const Vec3 bis = Vec3(1, 1, 0).normalized();
  int ext = 0;
  for (int v = 1; v < 8; ++v)
    if ((Rg * A.vertices()[v].p).dot(bis) < (Rg * A.vertices()[ext].p).dot(bis)) ext = v;
  const Analysis ve =
      analyse(ga, gb, at(Rg, Vec3(120, 20, 40) - Rg * A.vertices()[ext].p), kTouchTol);
  CHECK_FALSE(ve.penetrating);
  CHECK(ve.degenerate == 1);
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
  const Analysis ee = analyse(ga, gb, at(Rc, Vec3(120, 20, 40) - Rc * mid), kTouchTol);
  INFO(ee.describe());
  CHECK(ee.clean());
  REQUIRE(ee.pcs.size() == 1);
  CHECK(ee.pcs[0].type == PcType::kEE);
  CHECK(ee.pcs[0].a == e_lo);
  // The same pushed 1 micrometre further into B along the bisector: penetrating.
  CHECK(analyse(ga, gb, at(Rc, Vec3(120, 20, 40) - Rc * mid - 1e-3 * bis), kTouchTol).penetrating);
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
      "cube/big_box", [] { return load("cube.off"); }, [] { return big_box(200); });
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
  const ModelGeom ga(A), gb(B);
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
        check_hand_cf(g, ga, gb, s, p);
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
  const ModelGeom ga(A), gb(B);
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
        check_hand_cf(g, ga, gb, s, p);
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
            check_hand_cf(g, ga, gb, s, p);
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
          check_hand_cf(g, ga, gb, s, p);
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
  const ModelGeom ga(A), gb(B);
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
    check_hand_cf(g, ga, gb, PcSet({Pc{PcType::kFF, cube_face(A, n), floor}}), p);
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
    check_hand_cf(g, ga, gb, PcSet({Pc{PcType::kVF, lo, floor}}), p);
    p.t_BA = Vec3(20 - (R * A.vertices()[lx].p).x(), 50, 40);
    check_hand_cf(g, ga, gb, PcSet({Pc{PcType::kVF, lx, left}}), p);
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
    check_hand_cf(g, ga, gb, PcSet({Pc{PcType::kFE, cube_face(A, n), front_edge}}), p);
  }

  // Two PCs. Opposite cube faces (30 mm apart) can never lie on both walls (40 mm apart):
  // the search must find no witness for {f-f(a, left wall), f-f(opposite of a, right wall)}.
  // Across the slot's two reflex edges, floor (y = 20) with either wall, with adjacent cube
  // faces: 2 x 6 x 4 = 48 CFs that must be found, with witnesses this file confirms.
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
             << pose_str(w.pose) << ": " << analyse(ga, gb, w.pose, kTouchTol).describe());
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
        // This file's own witness first: the cube in the slot's corner.
        const Vec3 wn = side == 0 ? Vec3(Vec3::UnitX()) : Vec3(-Vec3::UnitX());
        const Pose p = seat_pose({n1, n2}, {Vec3::UnitY(), wn}, Vec3(side == 0 ? 35 : 45, 35, 40));
        const Analysis hand = analyse(ga, gb, p, kTouchTol);
        INFO("hand witness for {" << cf::to_string(s) << "}: " << pose_str(p) << ": "
                                  << hand.describe());
        CHECK(hand.clean());
        CHECK(hand.pcs == s);
        const cf::gen::Witness w = search.find(s, seeds(s));
        INFO("cfgen's witness search for {" << cf::to_string(s) << "}");
        CHECK(w.found);
        if (!w.found) continue;
        ++found;
        const Analysis an = analyse(ga, gb, w.pose, kTouchTol);
        INFO("its witness " << pose_str(w.pose) << ": " << an.describe());
        CHECK(an.clean());
        CHECK(an.pcs == s);
      }
  CHECK(found == 48);
  check_witnesses(g, "cube vs U-channel");
}

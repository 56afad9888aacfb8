// Certificate checker: the file (header, tolerances against the graph's parameters, summary),
// the rules, the dispatch of each set and the report. The cells are in certificate_cells.cpp,
// the pieces and programs in certificate_program.cpp.

#include "certificate_check.hpp"

#include "certificate_internal.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

namespace oracle {

const char* outcome_name(CertOutcome o) {
  switch (o) {
    case CertOutcome::Accepted:
      return "accepted";
    case CertOutcome::Rejected:
      return "rejected";
    case CertOutcome::NotCertified:
      return "not certified";
    case CertOutcome::Undecided:
      return "undecided";
  }
  return "?";
}

namespace cert {

std::string fmt(double x) {
  char buf[40];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip text
  return std::string(buf, res.ptr);
}

Vec3 get_vec3(const json& j, const char* key) {
  const json& a = j.at(key);
  if (!a.is_array() || a.size() != 3)
    throw std::runtime_error(std::string(key) + " is not 3 numbers");
  return Vec3(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
}

std::vector<int> closure_vertices(const Poly& P, int kind, int index) {
  if (kind == 0) return {index};
  if (kind == 1) return {P.E[index].v0, P.E[index].v1};
  return P.F[index].verts;
}

std::string pc_text(const SetPc& p) {
  return std::string(type_name(p.type)) + ":" + std::to_string(p.a) + ":" + std::to_string(p.b);
}

namespace {

int count_of(const Poly& P, int kind) {
  return static_cast<int>(kind == 0 ? P.V.size() : kind == 1 ? P.E.size() : P.F.size());
}

}  // namespace

std::vector<SetPc> parse_pcs(const Graph& g, const std::string& text) {
  std::vector<SetPc> out;
  for (const Pc& pc : parse_pc_list(text)) {
    const std::string item =
        type_name(pc.type) + (":" + std::to_string(pc.a)) + ":" + std::to_string(pc.b);
    if (pc.a < 0 || pc.a >= count_of(g.A, kind_a(pc.type)) || pc.b < 0 ||
        pc.b >= count_of(g.B, kind_b(pc.type)))
      throw std::runtime_error("\"" + item + "\" names an element the models do not have");
    out.push_back({pc.type, pc.a, pc.b});
  }
  if (out.empty() || out.size() > 3) throw std::runtime_error("a set has 1 to 3 PCs");
  return out;
}

SetKey set_key(const std::vector<SetPc>& pcs) {
  SetKey key;
  for (const auto& p : pcs) key.emplace_back(static_cast<int>(p.type), p.a, p.b);
  std::sort(key.begin(), key.end());
  return key;
}

// A tree's tolerances replace the file's for its own claims only; each must be at least as
// loose as the file's (compared exactly), so that refuting the tree's looser poses refutes
// the file's too. Keys the spec does not list are refused rather than ignored: a tree that
// relies on one would be checked with another value than it was built with.
std::string tree_tolerances(const Tol& file, const json& cells, Tol* out) {
  *out = file;
  out->deep_extra = 0;
  if (!cells.is_object() || !cells.contains("tolerances")) return "";
  const json& t = cells["tolerances"];
  if (!t.is_object()) return "cells.tolerances is not an object";
  static const std::set<std::string> keys = {"touch_tol_mm", "min_margin_mm",  "local_slack",
                                             "rot_tol_rad",  "off_circle_rad", "deep_extra_mm"};
  for (const auto& [k, v] : t.items()) {
    if (!keys.count(k)) return "cells.tolerances." + k + " is not a tree tolerance";
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      return "cells.tolerances." + k + " is not a finite number";
  }
  auto get = [&](const char* k, double def) { return t.contains(k) ? t[k].get<double>() : def; };
  out->touch = get("touch_tol_mm", file.touch);
  out->margin = get("min_margin_mm", file.margin);
  out->slack = get("local_slack", file.slack);
  out->rot = get("rot_tol_rad", file.rot);
  out->off_circle = get("off_circle_rad", file.off_circle);
  out->deep_extra = get("deep_extra_mm", 0.0);
  auto tighter = [](const char* k, double mine, double theirs, const char* rule) {
    return "cells.tolerances." + std::string(k) + " " + fmt(mine) + " is tighter than the file's " +
           fmt(theirs) + " (it must be " + rule + ")";
  };
  if (out->touch < file.touch) return tighter("touch_tol_mm", out->touch, file.touch, "no smaller");
  if (out->rot < file.rot) return tighter("rot_tol_rad", out->rot, file.rot, "no smaller");
  if (out->off_circle < file.off_circle)
    return tighter("off_circle_rad", out->off_circle, file.off_circle, "no smaller");
  if (out->margin > file.margin)
    return tighter("min_margin_mm", out->margin, file.margin, "no larger");
  if (out->slack > file.slack) return tighter("local_slack", out->slack, file.slack, "no larger");
  if (out->margin < 0) return "cells.tolerances.min_margin_mm " + fmt(out->margin) + " is negative";
  if (out->deep_extra < 0)
    return "cells.tolerances.deep_extra_mm " + fmt(out->deep_extra) + " is negative";
  // The spec's off_circle_rad is at least twice the alignment accepted (2 x is exact).
  if (out->off_circle < 2 * out->rot)
    return "cells.tolerances: off_circle_rad " + fmt(out->off_circle) +
           " is less than twice rot_tol_rad " + fmt(out->rot);
  return "";
}

namespace {

// ---- tolerances ----

double positive(const json& t, const char* key, std::vector<std::string>& problems) {
  if (!t.contains(key) || !t[key].is_number()) {
    problems.push_back(std::string("tolerances.") + key + " is missing");
    return 0;
  }
  const double v = t[key].get<double>();
  if (!(v > 0) || !std::isfinite(v))
    problems.push_back(std::string("tolerances.") + key + " = " + fmt(v) + " is not positive");
  return v;
}

// The certificate's tolerances, made no stronger than the verifier's (the graph's
// parameters): a certificate with a smaller touch tolerance, a larger margin or a larger local
// slack would refute witnesses the verifier accepts. Such a file is a problem; the checks then
// use the weaker value.
Tol read_tolerances(const Graph& g, const json& params, const json& cert, CertificateReport& rep) {
  auto& pr = rep.file_problems;
  Tol tol;
  const json t = cert.contains("tolerances") ? cert["tolerances"] : json::object();
  if (!t.is_object()) pr.push_back("tolerances is not an object");
  tol.touch = positive(t, "touch_tol_mm", pr);
  tol.margin = positive(t, "min_margin_mm", pr);
  tol.slack = positive(t, "local_slack", pr);
  tol.rounding = positive(t, "rounding_mm", pr);
  // Files that predate rot_tol_rad were built with the fixed 1e-8 it replaces.
  tol.rot = t.is_object() && t.contains("rot_tol_rad") ? positive(t, "rot_tol_rad", pr) : kAlignTol;
  tol.off_circle = positive(t, "off_circle_rad", pr);
  tol.size = positive(t, "size_mm", pr);
  // Below the verifier's alignment a tree would refute witnesses the verifier accepts.
  if (tol.rot > 0 && tol.rot < kAlignTol) {
    pr.push_back("tolerances.rot_tol_rad " + fmt(tol.rot) + " is below the verifier's " +
                 fmt(kAlignTol));
    tol.rot = kAlignTol;
  }
  if (tol.rot > kAlignTol)
    rep.warnings.push_back("tolerances.rot_tol_rad " + fmt(tol.rot) +
                           " is above the 1e-8 the rules are stated with: a rule proves its "
                           "set at 1e-8 only");
  if (tol.off_circle > 0 && tol.off_circle < 2 * tol.rot)
    pr.push_back("tolerances.off_circle_rad " + fmt(tol.off_circle) +
                 " is less than twice rot_tol_rad " + fmt(tol.rot));
  double vmax = 0;
  for (const Poly* P : {&g.A, &g.B})
    for (const auto& v : P->V) vmax = std::max(vmax, v.p.norm());
  const double size = std::max(g.A.diag, g.B.diag);
  tol.scale = size + vmax;
  if (std::abs(tol.size - size) > 1e-9 * size)
    pr.push_back("tolerances.size_mm = " + fmt(tol.size) + " is not the larger diagonal " +
                 fmt(size) + " mm");
  if (std::abs(tol.rounding - 1e-12 * size) > 1e-6 * 1e-12 * size)
    rep.warnings.push_back("tolerances.rounding_mm = " + fmt(tol.rounding) +
                           " is not 1e-12 x size (the checker bounds its own rounding anyway)");
  if (params.is_object()) {
    auto num = [&](const char* k) {
      return params.contains(k) && params[k].is_number() ? params[k].get<double>() : -1.0;
    };
    const double gt = num("touch_tol_mm"), gm = num("min_margin_mm"), ga = num("angle_margin_rad");
    if (gt > 0 && tol.touch < gt * (1 - 1e-12)) {
      pr.push_back("tolerances.touch_tol_mm " + fmt(tol.touch) + " is below the graph's " +
                   fmt(gt));
      tol.touch = gt;
    }
    if (gm > 0 && tol.margin > gm * (1 + 1e-12)) {
      pr.push_back("tolerances.min_margin_mm " + fmt(tol.margin) + " is above the graph's " +
                   fmt(gm));
      tol.margin = gm;
    }
    const double gs = ga > 0 ? 0.5 * std::sin(ga) : -1;
    if (gs > 0 && tol.slack > gs * (1 + 1e-12)) {
      pr.push_back("tolerances.local_slack " + fmt(tol.slack) +
                   " is above half the sine of the graph's angle_margin_rad (" + fmt(gs) + ")");
      tol.slack = gs;
    }
    if (gt <= 0 || gm <= 0 || ga <= 0)
      rep.warnings.push_back(
          "the graph's parameters lack touch_tol_mm, min_margin_mm or "
          "angle_margin_rad: those tolerances are the certificate's, unchecked");
  } else {
    rep.warnings.push_back(
        "the graph has no parameters: the tolerances are the certificate's, "
        "unchecked");
  }
  return tol;
}

// ---- rules ----

std::pair<int, int> two_involved(const json& set, std::size_t n) {
  const auto inv = set.at("pcs_involved").get<std::vector<int>>();
  if (inv.size() != 2 || inv[0] == inv[1] || inv[0] < 0 || inv[1] < 0 ||
      inv[0] >= static_cast<int>(n) || inv[1] >= static_cast<int>(n))
    throw std::runtime_error("pcs_involved is not two distinct PCs of the set");
  return {inv[0], inv[1]};
}

std::string vertex_in_two(const std::vector<SetPc>& pcs, int i, int j) {
  const SetPc &p = pcs[i], &q = pcs[j];
  if (kind_a(p.type) == 0 && kind_a(q.type) == 0 && p.a == q.a) return "";
  if (kind_b(p.type) == 0 && kind_b(q.type) == 0 && p.b == q.b) return "";
  return "PCs " + pc_text(p) + " and " + pc_text(q) + " share no vertex";
}

// Both elements of one PC in the closures of the other's. The table's wording ("both
// elements of one PC lie in the closures of the other PC's elements") is symmetric; the
// parenthesis orders them (the first is the boundary touch). Either order proves the set
// invalid, so either is accepted.
std::string dominated(const Graph& g, const std::vector<SetPc>& pcs, int i, int j) {
  auto dom = [&](const SetPc& x, const SetPc& y) {
    return g.A.in_closure(kind_a(x.type), x.a, kind_a(y.type), y.a) &&
           g.B.in_closure(kind_b(x.type), x.b, kind_b(y.type), y.b);
  };
  const SetPc &p = pcs[i], &q = pcs[j];
  if (p.type == q.type && p.a == q.a && p.b == q.b) return "the two PCs are the same";
  if (dom(p, q) || dom(q, p)) return "";
  return "neither of " + pc_text(p) + " and " + pc_text(q) + " lies in the other's closures";
}

// Two faces in one plane: normals parallel and each face's vertices on the other's plane, to
// 1e-11 of the models' scale (the rounding of coplanar faces written in doubles is ~1e-15 of
// it; faces that far apart are distinct planes in any reading).
bool coplanar(const Poly& P, int f1, int f2, double scale) {
  if (f1 == f2) return true;
  const Face &a = P.F[f1], &b = P.F[f2];
  if (a.n.cross(b.n).norm() > 1e-11) return false;
  for (int v : b.verts)
    if (std::abs(a.n.dot(P.V[v].p) - a.d) > 1e-11 * scale) return false;
  for (int v : a.verts)
    if (std::abs(b.n.dot(P.V[v].p) - b.d) > 1e-11 * scale) return false;
  return true;
}

std::string one_plane(const Graph& g, const Tol& tol, const std::vector<SetPc>& pcs, int i, int j) {
  const SetPc &p = pcs[i], &q = pcs[j];
  if (kind_b(p.type) == 2 && kind_b(q.type) == 2 && coplanar(g.B, p.b, q.b, tol.scale)) return "";
  if (kind_a(p.type) == 2 && kind_a(q.type) == 2 && coplanar(g.A, p.a, q.a, tol.scale)) return "";
  return "PCs " + pc_text(p) + " and " + pc_text(q) + " have no faces of A or of B in one plane";
}

// With the f-f holding (|R n_a + n_b| <= 1e-8 and its faces within touch_tol), a point x of A
// at depth h below a's plane is at height h + e over b's plane, |e| <= 1e-8 |x - x0| +
// touch_tol (x0 a contact point of the f-f); the other PC's points are within touch_tol of
// each other. So the heights must be more than 1e-8 diag(A) + 2 touch_tol apart. The spec's
// 1e-9 size + touch_tol is not enough (see the README); the checker uses the sound bound.
std::string heights(const Graph& g, const Tol& tol, const std::vector<SetPc>& pcs, int i, int j) {
  const SetPc &ff = pcs[i], &o = pcs[j];
  if (ff.type != PcType::FF) return "pcs_involved[0] is not an f-f";
  const Face &fa = g.A.F[ff.a], &fb = g.B.F[ff.b];
  double amin = kInf, amax = -kInf, bmin = kInf, bmax = -kInf;
  for (int v : closure_vertices(g.A, kind_a(o.type), o.a)) {
    const double h = fa.d - fa.n.dot(g.A.V[v].p);
    amin = std::min(amin, h);
    amax = std::max(amax, h);
  }
  for (int v : closure_vertices(g.B, kind_b(o.type), o.b)) {
    const double h = fb.n.dot(g.B.V[v].p) - fb.d;
    bmin = std::min(bmin, h);
    bmax = std::max(bmax, h);
  }
  const double gap = std::max(bmin - amax, amin - bmax);
  const double need = kAlignTol * g.A.diag + 2 * tol.touch + kRelRound * tol.scale;
  if (gap > need) return "";
  return "depths of A's element [" + fmt(amin) + ", " + fmt(amax) + "] and heights of B's [" +
         fmt(bmin) + ", " + fmt(bmax) + "] are not more than " + fmt(need) + " apart";
}

// With an f-f (a = n_A, b = n_B) the rotations are R0 Rot(a, theta), R0 a = -b, up to a turn
// of 1e-8 (the f-f's own alignment). Each other condition is a function of theta with a
// Lipschitz bound; [-pi, pi] is split until on every interval some condition fails by more
// than its tolerance (1e-8) plus that turn (1e-8) plus rounding.
std::string rotational(const Graph& g, const std::vector<SetPc>& pcs, const json& set) {
  std::vector<int> inv;
  if (set.contains("pcs_involved")) inv = set["pcs_involved"].get<std::vector<int>>();
  if (inv.empty())
    for (std::size_t k = 0; k < pcs.size(); ++k) inv.push_back(static_cast<int>(k));
  int ff = -1;
  for (int k : inv) {
    if (k < 0 || k >= static_cast<int>(pcs.size()))
      throw std::runtime_error("pcs_involved names no PC of the set");
    if (ff < 0 && pcs[k].type == PcType::FF) ff = k;
  }
  if (ff < 0) return "no f-f among the PCs involved: this rule does not refute sets without one";
  const Vec3 a = g.A.F[pcs[ff].a].n, b = g.B.F[pcs[ff].b].n;
  const Vec3 ua = any_perp(a), ub = any_perp(-b);
  Mat3 Fa, Fb;
  Fa << a, ua, a.cross(ua);
  Fb << -b, ub, (-b).cross(ub);
  const Mat3 R0 = Fb * Fa.transpose();  // a rotation (both frames right-handed), R0 a = -b
  struct Cond {
    bool ff;
    Vec3 v, w;
    double lip;
  };
  std::vector<Cond> conds;
  for (int k : inv) {
    const SetPc& p = pcs[k];
    if (k == ff) continue;
    if (p.type == PcType::FF)
      conds.push_back({true, g.A.F[p.a].n, R0.transpose() * g.B.F[p.b].n, 0});
    else if (p.type == PcType::EF)
      conds.push_back({false, g.A.E[p.a].dir, R0.transpose() * g.B.F[p.b].n, 0});
    else if (p.type == PcType::FE)
      conds.push_back({false, g.A.F[p.a].n, R0.transpose() * g.B.E[p.b].dir, 0});
  }
  if (conds.empty()) return "the f-f is the only rotational condition among the PCs involved";
  for (auto& c : conds) c.lip = c.v.cross(a).norm() * c.w.norm() * (1 + 1e-12);
  const double tolc = 2 * kAlignTol + 1e-12;
  std::vector<std::pair<double, double>> stack = {{0.0, kPi + 1e-15}};
  long budget = 1 << 22;
  while (!stack.empty()) {
    auto [c, h] = stack.back();
    stack.pop_back();
    const Mat3 Rc = rot_about(a, c);
    bool refuted = false;
    for (const auto& k : conds) {
      const Vec3 rv = Rc * k.v;
      const double val = k.ff ? (rv + k.w).norm() : std::abs(rv.dot(k.w));
      refuted = refuted || val - k.lip * h > tolc;
    }
    if (refuted) continue;
    if (--budget < 0 || h < 1e-13)
      return "the conditions may all hold near theta = " + fmt(c) + " (within 1e-8)";
    stack.push_back({c - h / 2, h / 2});
    stack.push_back({c + h / 2, h / 2});
  }
  return "";
}

// ---- mirror-corners: two e-e PCs at nearly mirror-image corners (robust, in doubles) ----

// Every quantity below is a product of the checker's unit vectors (edge directions, Newell
// face normals), computed in double: its error is a few ulps, far below kUnitEval. Condition 1
// must hold by more than kUnitEval. Condition 7 bounds each face normal's tilt off the corner's
// edges on that face by kMirrorTilt (t = 1e-9, + kUnitEval); such a tilt turns an edge's cone
// by at most about 2 t, so conditions 2, 3 and 6 must hold by more than kMirrorMargin = 4 t
// (+ kUnitEval), and 4 and 5 are evaluated with x raised by 4 t: a bound holds with kUnitEval
// added to its left side, and the threshold T is taken below its computed value.
constexpr double kMirrorTilt = 1e-9;
constexpr double kMirrorMargin = 4 * kMirrorTilt;

// Short text of a measured value (3 significant digits).
std::string sci(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// One solid's corner: the shared end `vertex` (v or w) of the two PCs' edges, their common
// face (G or F), each edge's other face (G_k or F_k), the unit vectors a_k (b_k) from the
// vertex along edge k and the faces' outward unit normals.
struct MirrorCorner {
  char solid = 'A';
  std::string v, f, e;  // "v", "G", "a" on A; "w", "F", "b" on B
  int vertex = -1, face = -1;
  int edge[2] = {-1, -1}, other[2] = {-1, -1};
  Vec3 d[2], n, nk[2];
  std::string edge_name(int k) const {
    return e + "_" + std::to_string(k + 1) + " (edge " + std::to_string(edge[k]) + " of " + solid +
           ")";
  }
  std::string vertex_name() const {
    return v + " (vertex " + std::to_string(vertex) + " of " + solid + ")";
  }
  std::string face_k(int k) const { return f + "_" + std::to_string(k + 1); }
};

// The structure the rule needs: two edges with one shared end and exactly one common face.
// "" and *c filled, else why not.
std::string mirror_corner(const Poly& P, char solid, int e1, int e2, MirrorCorner* c) {
  const std::string who =
      std::string(1, solid) + "'s edges " + std::to_string(e1) + " and " + std::to_string(e2);
  if (e1 == e2) return "the two PCs have the same edge " + std::to_string(e1) + " of " + solid;
  const Edge &E1 = P.E[e1], &E2 = P.E[e2];
  c->vertex = (E1.v0 == E2.v0 || E1.v0 == E2.v1)   ? E1.v0
              : (E1.v1 == E2.v0 || E1.v1 == E2.v1) ? E1.v1
                                                   : -1;
  if (c->vertex < 0) return who + " share no end vertex";
  std::vector<int> common;
  for (int f1 : E1.face)
    for (int f2 : E2.face)
      if (f1 == f2) common.push_back(f1);
  if (common.size() != 1)
    return who + (common.empty() ? " lie on no common face" : " lie on two common faces");
  const bool a = solid == 'A';
  c->solid = solid;
  c->v = a ? "v" : "w";
  c->f = a ? "G" : "F";
  c->e = a ? "a" : "b";
  c->face = common[0];
  c->n = P.F[c->face].n;
  for (int k = 0; k < 2; ++k) {
    const Edge& E = P.E[k == 0 ? e1 : e2];
    c->edge[k] = k == 0 ? e1 : e2;
    c->other[k] = E.face[0] == c->face ? E.face[1] : E.face[0];
    c->nk[k] = P.F[c->other[k]].n;
    c->d[k] = E.v0 == c->vertex ? E.dir : Vec3(-E.dir);
  }
  return "";
}

// (1): each edge convex, (n(L) x n(R)) . d > 0 with L the face whose loop runs the edge along
// d (face[0] runs it v0 -> v1, d = dir) and R its other face.
std::string convex_edges(const Poly& P, const MirrorCorner& c) {
  for (int k = 0; k < 2; ++k) {
    const Edge& E = P.E[c.edge[k]];
    const double s = P.F[E.face[0]].n.cross(P.F[E.face[1]].n).dot(E.dir);
    if (!(s > kUnitEval))
      return c.edge_name(k) + " is not convex (condition 1): (n(L) x n(R)) . d = " + sci(s) +
             " (needs > " + sci(kUnitEval) + ")";
  }
  return "";
}

// (7): every normal the rule uses within kMirrorTilt of perpendicular to the corner's edges on
// its face, |n(G) . a_k| and |n(G_k) . a_k| (|n(F) . b_k|, |n(F_k) . b_k|) at most t.
std::string normals_perpendicular(const MirrorCorner& c) {
  for (int k = 0; k < 2; ++k)
    for (int other = 0; other < 2; ++other) {
      const double p = (other ? c.nk[k] : c.n).dot(c.d[k]);
      if (!(std::abs(p) <= kMirrorTilt + kUnitEval))
        return "n(" + (other ? c.face_k(k) : c.f) + ") . " + c.e + "_" + std::to_string(k + 1) +
               " = " + sci(p) +
               " (condition 7: a face normal more than 1e-9 from perpendicular to the edge)";
    }
  return "";
}

// (2) on A (sign -1: n(G_1) . a_2 < 0 and n(G_2) . a_1 < 0) and (3) on B (sign +1: the saddle),
// each by more than kMirrorMargin.
std::string corner_kind(const MirrorCorner& c, int sign) {
  const char* kind =
      sign < 0 ? " is not convex (condition 2): " : " is not a saddle (condition 3): ";
  for (int k = 0; k < 2; ++k) {
    const double s = c.nk[k].dot(c.d[1 - k]);
    if (!(sign * s > kMirrorMargin + kUnitEval))
      return c.vertex_name() + kind + "n(" + c.face_k(k) + ") . " + c.e + "_" +
             std::to_string(2 - k) + " = " + sci(s) + " (needs " + (sign < 0 ? "< " : "> ") +
             sci(sign * (kMirrorMargin + kUnitEval)) + ")";
  }
  return "";
}

// (4): x = max(0, -n(G) . n(G_k), -n(F) . n(F_k)), the sine by which the widest of the four
// normal cones exceeds pi/2, must be below the slack s, with x raised by kMirrorMargin. "" and
// *x set (not raised), else why not.
std::string cone_excess(const MirrorCorner& A, const MirrorCorner& B, double s, double* x) {
  *x = 0;
  for (const MirrorCorner* c : {&A, &B})
    for (int k = 0; k < 2; ++k) {
      const double xk = -c->n.dot(c->nk[k]);
      if (!(xk + kMirrorMargin + kUnitEval < s))
        return "the dihedral angle at " + c->edge_name(k) +
               " is below 90 degrees by as much as the slack (condition 4): x = -n(" + c->f +
               ") . n(" + c->face_k(k) + ") = " + sci(xk) +
               " >= s - 4e-09 = " + sci(s - kMirrorMargin);
      *x = std::max(*x, xk);
    }
  return "";
}

// Theorem R's threshold T = (s/2) E sigma mu2 (docs/certificates.md, "Rules"), from below: x
// raised by kMirrorMargin (condition 7's allowance) and kUnitEval, each cosine moved by kUnitEval
// towards a smaller T, kUnitEval taken off E (its subtraction may cancel), and the product's
// remaining rounding (a few ulps of each factor) covered by the factor 1 - 1e-9.
double mirror_threshold(double s, double x, double ca, double cb) {
  const double xe = std::min(1.0, x + kMirrorMargin + kUnitEval);
  const double E = s * std::sqrt(1 - xe * xe) - xe * std::sqrt(1 - s * s) - kUnitEval;
  const double cmax = std::max(ca, cb) + kUnitEval;
  const double cabs = std::max(std::abs(ca), std::abs(cb)) + kUnitEval;
  const double cneg = std::min({ca, cb, 0.0}) < 0 ? std::min(ca, cb) - kUnitEval : 0.0;
  const double sigma = std::sqrt(std::max(0.0, 1 - cabs * cabs));
  const double mu2 = std::min((1 - cmax) / 2, 1 - cneg * cneg);
  if (!(E > 0 && mu2 > 0)) return 0;
  return s / 2 * E * sigma * mu2 * (1 - 1e-9);
}

// (5) nearly equal angles, |c_A - c_B| < T; (6) opposite handedness,
// det(a_1, a_2, n(G)) det(b_1, b_2, n(F)) < 0 by more than kMirrorMargin.
std::string mirror_image(const MirrorCorner& A, const MirrorCorner& B, double s, double x) {
  const double ca = A.d[0].dot(A.d[1]), cb = B.d[0].dot(B.d[1]);
  const double T = mirror_threshold(s, x, ca, cb), diff = std::abs(ca - cb);
  if (!(diff + kUnitEval < T))
    return "the corners' angles differ by more than the tolerance (condition 5): |c_A - c_B| = " +
           sci(diff) + " >= T = " + sci(T);
  const double h = A.d[0].cross(A.d[1]).dot(A.n) * B.d[0].cross(B.d[1]).dot(B.n);
  if (!(h < -(kMirrorMargin + kUnitEval)))
    return "the corners have the same handedness (condition 6): det(a_1, a_2, n(G)) det(b_1, "
           "b_2, n(F)) = " +
           sci(h) + " (needs < " + sci(-(kMirrorMargin + kUnitEval)) + ")";
  return "";
}

// Two e-e PCs at a convex corner v of A and a saddle corner w of B that are mirror images to
// within Theorem R's tolerance, no edge's dihedral angle below 90 degrees by the slack: no
// pose realises both with local margins of at least the slack (docs/certificates.md, "Rules";
// the theorem behind the rule). Only the conditions are checked here.
std::string mirror_corners(const Graph& g, const Tol& tol, const std::vector<SetPc>& pcs, int i,
                           int j) {
  for (int k : {i, j})
    if (pcs[k].type != PcType::EE)
      return "PC " + pc_text(pcs[k]) + " (pcs_involved[" + std::to_string(k == i ? 0 : 1) +
             "]) is not an e-e";
  const double s = tol.slack;
  if (!(s > 0 && s < 1)) return "local_slack " + fmt(s) + " is not between 0 and 1";
  MirrorCorner A, B;
  double x = 0;
  std::string why = mirror_corner(g.A, 'A', pcs[i].a, pcs[j].a, &A);
  if (why.empty()) why = mirror_corner(g.B, 'B', pcs[i].b, pcs[j].b, &B);
  if (why.empty()) why = convex_edges(g.A, A);
  if (why.empty()) why = convex_edges(g.B, B);
  if (why.empty()) why = normals_perpendicular(A);
  if (why.empty()) why = normals_perpendicular(B);
  if (why.empty()) why = corner_kind(A, -1);
  if (why.empty()) why = corner_kind(B, +1);
  if (why.empty()) why = cone_excess(A, B, s, &x);
  if (why.empty()) why = mirror_image(A, B, s, x);
  return why;
}

std::string check_rule(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& set,
                       const std::string& rule) {
  const Graph& g = ctx.g;
  if (rule == "rotational-conditions") return rotational(g, pcs, set);
  const auto [i, j] = two_involved(set, pcs.size());
  if (rule == "vertex-in-two-pcs") return vertex_in_two(pcs, i, j);
  if (rule == "dominated-pc") return dominated(g, pcs, i, j);
  if (rule == "one-contact-plane") return one_plane(g, ctx.tol, pcs, i, j);
  if (rule == "heights-over-ff") return heights(g, ctx.tol, pcs, i, j);
  if (rule == "mirror-corners") return mirror_corners(g, ctx.tol, pcs, i, j);
  return "unknown rule \"" + rule + "\"";
}

// ---- a thin set ----

// A THIN set's claim: its pose realises exactly these PCs, without penetration, every other
// pair apart. The oracle's classifier reads the pose with the file's touch tolerance (the
// pose's contacts are within it; its clearance, at least four times it, is not).
std::string check_thin(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& set) {
  const json& pose = set.at("pose");
  Pose X;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) X.R(r, c) = pose.at("R").at(r).at(c).get<double>();
  for (int c = 0; c < 3; ++c) X.t(c) = pose.at("t").at(c).get<double>();
  const double claimed = set.at("clearance_mm").get<double>();
  if ((X.R.transpose() * X.R - Mat3::Identity()).norm() > 1e-9 || X.R.determinant() <= 0)
    return "the pose's R is not a rotation";
  Tolerances t = default_tolerances(ctx.g.A, ctx.g.B);
  t.len = ctx.tol.touch + ctx.tol.rounding;
  const Classifier C(ctx.g.A, ctx.g.B, t);
  const Verdict v = C.classify(X);
  CfKey want;
  for (const SetPc& p : pcs) want.push_back({p.type, p.a, p.b});
  std::sort(want.begin(), want.end());
  if (v.penetrating) return "the pose penetrates: " + v.why;
  if (!v.valid_cf() || v.key() != want) return "the pose realises " + v.describe();
  const double clearance = C.clearance_outside(X, want);
  if (clearance <= ctx.tol.touch) return "another pair touches at the pose";
  // The generator measures the same distance with other arithmetic.
  if (std::abs(clearance - claimed) > 1e-6 * ctx.tol.size)
    return "clearance " + std::to_string(clearance) + " mm, not the " + std::to_string(claimed) +
           " mm claimed";
  return "";
}

// ---- one set ----

// What every set's check shares: the file's context, the graph's CFs, the piece tables of
// trees with their own min_margin_mm (a side's margin depends on it), and, for image entries
// (checked after every other set), the other sets' verdicts and the maps seen.
struct Run {
  const Ctx& ctx;
  const json& pieces_json;
  std::set<SetKey> cf_keys;
  std::map<double, PieceTables> by_margin;
  std::map<SetKey, DecidedSet> decided;
  SymmetryCache symmetries;

  const PieceTables& pieces_for(const Tol& t) {
    if (t.margin == ctx.tol.margin) return ctx.pieces;
    auto it = by_margin.find(t.margin);
    if (it == by_margin.end()) {
      // The file's tables were checked already: only the sides' margins differ here.
      std::vector<std::string> problems, warnings;
      it =
          by_margin.emplace(t.margin, check_piece_tables(ctx.g, t, pieces_json, problems, warnings))
              .first;
    }
    return it->second;
  }
};

bool is_image_entry(const json& set) {
  return set.is_object() && set.contains("image_of") && set.value("outcome", json()) == "invalid";
}

// `tree`, when not null, receives a cells set's tree tolerances.
CertSetResult check_set(Run& run, const json& set, int index, Tol* tree) {
  const Ctx& ctx = run.ctx;
  CertSetResult r;
  r.index = index;
  r.kind = "malformed";
  try {
    r.pcs = set.at("pcs").get<std::string>();
    const std::vector<SetPc> pcs = parse_pcs(ctx.g, r.pcs);
    const std::string outcome = set.at("outcome").get<std::string>();
    if (outcome == "undecided") {
      r.kind = "undecided";
      r.outcome = CertOutcome::Undecided;
      return r;
    }
    if (outcome == "thin") {
      r.kind = "thin";
      r.reason = check_thin(ctx, pcs, set);
      r.outcome = r.reason.empty() ? CertOutcome::Accepted : CertOutcome::Rejected;
      return r;
    }
    if (outcome != "invalid") throw std::runtime_error("outcome \"" + outcome + "\"");
    const bool has_rule = set.contains("rule"), has_cells = set.contains("cells"),
               has_image = set.contains("image_of");
    if (has_rule + has_cells + has_image != 1)
      throw std::runtime_error("an invalid set has one of rule, cells or image_of");
    r.kind = has_rule ? set["rule"].get<std::string>() : has_cells ? "cells" : "image";
    if (run.cf_keys.count(set_key(pcs))) {
      r.reason = "the graph holds this set as a CF with a witness";
    } else if (r.kind == "finite-rotations") {
      r.outcome = CertOutcome::NotCertified;
      r.reason = "finite-rotations is evidence, not a certificate";
      return r;
    } else if (has_rule) {
      r.reason = check_rule(ctx, pcs, set, r.kind);
    } else if (has_image) {
      r.reason = check_image(ctx, pcs, set["image_of"], run.decided, run.symmetries);
    } else {
      Tol t;
      const std::string why = tree_tolerances(ctx.tol, set["cells"], &t);
      if (tree) *tree = t;
      if (!why.empty()) {
        r.node_fails.push_back({-1, why});
      } else {
        const Ctx mine{ctx.g, t, run.pieces_for(t)};
        check_cells(mine, pcs, set["cells"], r);
      }
      if (!r.node_fails.empty()) {
        const auto& f = r.node_fails.front();
        r.reason = (f.node >= 0 ? "node " + std::to_string(f.node) + ": " : "tree: ") + f.why;
        if (r.node_fails.size() > 1)
          r.reason += " (and " + std::to_string(r.node_fails.size() - 1) + " more)";
      }
    }
  } catch (const std::exception& e) {
    r.reason = std::string("malformed: ") + e.what();
  }
  r.outcome = r.reason.empty() ? CertOutcome::Accepted : CertOutcome::Rejected;
  return r;
}

void check_summary(const json& cert, CertificateReport& rep) {
  if (!cert.contains("summary")) {
    rep.file_problems.push_back("summary is missing");
    return;
  }
  const json& s = cert["summary"];
  int rule = 0, cells = 0, und = 0, thin = 0, images = 0;
  for (const auto& set : cert["sets"]) {
    if (!set.is_object()) continue;  // rejected as malformed on its own
    if (set.value("outcome", json()) == "undecided") ++und;
    if (set.value("outcome", json()) == "thin") ++thin;
    if (set.contains("rule")) ++rule;
    if (set.contains("cells")) ++cells;
    if (set.contains("image_of")) ++images;
  }
  // The spec's summary does not list the image entries; cfgen counts them in
  // `invalid_as_image`, checked when present.
  if (s.contains("invalid_as_image") &&
      (!s["invalid_as_image"].is_number_integer() || s["invalid_as_image"].get<int>() != images))
    rep.file_problems.push_back("summary.invalid_as_image is not " + std::to_string(images));
  const std::pair<const char*, int> want[] = {{"sets", static_cast<int>(cert["sets"].size())},
                                              {"invalid_by_rule", rule},
                                              {"invalid_by_cells", cells},
                                              {"thin", thin},
                                              {"undecided", und}};
  for (const auto& [k, n] : want)
    if (!s.contains(k) || !s[k].is_number_integer() || s[k].get<int>() != n)
      rep.file_problems.push_back(std::string("summary.") + k + " is not " + std::to_string(n));
}

}  // namespace
}  // namespace cert

CertificateReport check_certificates(const Graph& g, const nlohmann::json& graph_parameters,
                                     const nlohmann::json& cert) {
  using namespace cert;
  if (!cert.is_object()) throw CertificateInputError("the certificate file is not a JSON object");
  const std::string format = cert.value("format", std::string("(none)"));
  if (format != "cf-certificates")
    throw CertificateInputError("format is \"" + format + "\", expected \"cf-certificates\"");
  if (!cert.contains("version") || cert["version"] != 1)
    throw CertificateInputError(
        "version is " +
        (cert.contains("version") ? cert["version"].dump() : std::string("missing")) +
        ", expected 1");
  if (!cert.contains("sets") || !cert["sets"].is_array())
    throw CertificateInputError("sets is missing or not an array");
  CertificateReport rep;
  rep.graph_path = g.path;
  const Tol tol = read_tolerances(g, graph_parameters, cert, rep);
  static const json kNoPieces;
  const json& pieces_json = cert.contains("pieces") ? cert["pieces"] : kNoPieces;
  const PieceTables pieces =
      check_piece_tables(g, tol, pieces_json, rep.file_problems, rep.warnings);
  check_summary(cert, rep);
  const Ctx ctx{g, tol, pieces};
  Run run{ctx, pieces_json, {}, {}, {}, {}};
  for (const auto& cf : g.cfs) {
    std::vector<SetPc> k;
    for (const auto& p : cf.key) k.push_back({p.type, p.a, p.b});
    run.cf_keys.insert(set_key(k));
  }
  const bool tol_ok = tol.touch > 0 && tol.margin > 0 && tol.slack > 0 && tol.off_circle > 0 &&
                      tol.size > 0 && tol.rounding > 0 && tol.rot > 0;
  const json& sets = cert["sets"];
  std::vector<CertSetResult> results(sets.size());
  auto check_one = [&](int index, Tol* tree) {
    const json& set = sets[index];
    CertSetResult r;
    const bool undecided = set.is_object() && set.value("outcome", json()) == "undecided";
    if (!tol_ok && !undecided) {
      r.index = index;
      r.pcs = set.is_object() && set.value("pcs", json()).is_string()
                  ? set["pcs"].get<std::string>()
                  : "?";
      r.kind = !set.is_object()           ? "rule"
               : set.contains("cells")    ? "cells"
               : set.contains("image_of") ? "image"
                                          : "rule";
      r.reason = "the file's tolerances are unusable";
      return r;
    }
    return check_set(run, set, index, tree);
  };
  // Two passes: an image entry needs its decided set's verdict, and the file (sorted by PC
  // list) may list it before that set.
  for (int i = 0; i < static_cast<int>(sets.size()); ++i) {
    if (is_image_entry(sets[i])) continue;
    Tol tree = tol;
    results[i] = check_one(i, &tree);
    try {
      const SetKey key = set_key(parse_pcs(g, results[i].pcs));
      run.decided.insert({key, {i, results[i].kind, results[i].outcome, tree}});
    } catch (const std::exception&) {  // malformed: rejected on its own, decides nothing
    }
  }
  for (int i = 0; i < static_cast<int>(sets.size()); ++i)  // so that images of images are named
    if (is_image_entry(sets[i])) {
      try {
        const SetKey key = set_key(parse_pcs(g, sets[i].at("pcs").get<std::string>()));
        run.decided.insert({key, {i, "image", CertOutcome::Rejected, tol}});
      } catch (const std::exception&) {
      }
    }
  for (int i = 0; i < static_cast<int>(sets.size()); ++i)
    if (is_image_entry(sets[i])) results[i] = check_one(i, nullptr);
  std::set<std::string> seen;
  for (CertSetResult& r : results) {
    if (!seen.insert(r.pcs).second && r.outcome != CertOutcome::Rejected) {
      r.outcome = CertOutcome::Rejected;
      r.reason = "the set is listed twice";
    }
    switch (r.outcome) {
      case CertOutcome::Accepted:
        ++rep.accepted;
        break;
      case CertOutcome::Rejected:
        ++rep.rejected;
        break;
      case CertOutcome::NotCertified:
        ++rep.not_certified;
        break;
      case CertOutcome::Undecided:
        ++rep.undecided;
        break;
    }
    rep.by_kind[r.kind][static_cast<int>(r.outcome)]++;
    for (const auto& [k, c] : r.leaves) {
      rep.leaves[k][0] += c[0];
      rep.leaves[k][1] += c[1];
    }
    rep.sets.push_back(std::move(r));
  }
  return rep;
}

CertificateReport check_certificate_files(const std::string& graph_path,
                                          const std::string& cert_path) {
  auto read_json = [](const std::string& path, const char* what) {
    std::ifstream in(path);
    if (!in) throw CertificateInputError(std::string("cannot open ") + what + " " + path);
    try {
      return nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw CertificateInputError(std::string(what) + " " + path + ": not JSON (" + e.what() + ")");
    }
  };
  Graph g;
  try {
    g = read_graph(graph_path);
  } catch (const std::exception& e) {
    throw CertificateInputError(e.what());
  }
  const nlohmann::json gj = read_json(graph_path, "graph");
  const nlohmann::json cj = read_json(cert_path, "certificate file");
  try {
    CertificateReport rep =
        check_certificates(g, gj.contains("parameters") ? gj["parameters"] : nlohmann::json(), cj);
    rep.cert_path = cert_path;
    return rep;
  } catch (const CertificateInputError& e) {
    throw CertificateInputError("certificate file " + cert_path + ": " + e.what());
  }
}

std::string CertificateReport::summary_line() const {
  std::ostringstream o;
  o << "sets " << sets.size() << ", accepted " << accepted << ", rejected " << rejected
    << ", not certified " << not_certified << ", undecided " << undecided;
  if (!file_problems.empty()) o << ", file problems " << file_problems.size();
  o << " | by kind (accepted/rejected/not certified):";
  for (const auto& [k, c] : by_kind)
    if (k != "undecided") o << " " << k << " " << c[0] << "/" << c[1] << "/" << c[2];
  o << " | leaves (accepted/rejected):";
  for (const auto& [k, c] : leaves) o << " " << k << " " << c[0] << "/" << c[1];
  return o.str();
}

std::vector<std::string> CertificateReport::rejection_lines() const {
  std::vector<std::string> out;
  for (const auto& p : file_problems) out.push_back("FILE PROBLEM: " + p);
  for (const auto& s : sets)
    if (s.outcome == CertOutcome::Rejected)
      out.push_back("REJECTED set " + std::to_string(s.index) + " {" + s.pcs + "} " + s.kind +
                    ": " + s.reason);
  return out;
}

}  // namespace oracle

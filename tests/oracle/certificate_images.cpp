// Certificate checker: sets invalid as the image of a set invalid by cells under a symmetry of
// the two models (docs/certificates.md, "Images"). How far the maps miss (eps) and turn
// (delta) is computed in exact rationals from the file's numbers and the models' coordinates
// and rounded upwards, so the loosening the decided set's tree must carry is compared with
// true upper bounds, with no allowance for the checker's own rounding needed.

#include "certificate_internal.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace oracle::cert {

namespace {

using RVec = std::array<Rational, 3>;
using RMat = std::array<Rational, 9>;  // by rows

RVec rv(const Vec3& v) { return {Rational(v.x()), Rational(v.y()), Rational(v.z())}; }

Rational dot(const RVec& a, const RVec& b) {
  return Rational(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

RVec cross(const RVec& a, const RVec& b) {
  return {Rational(a[1] * b[2] - a[2] * b[1]), Rational(a[2] * b[0] - a[0] * b[2]),
          Rational(a[0] * b[1] - a[1] * b[0])};
}

RVec sub(const RVec& a, const RVec& b) {
  return {Rational(a[0] - b[0]), Rational(a[1] - b[1]), Rational(a[2] - b[2])};
}

RVec add(const RVec& a, const RVec& b) {
  return {Rational(a[0] + b[0]), Rational(a[1] + b[1]), Rational(a[2] + b[2])};
}

RVec mul(const RMat& H, const RVec& x) {
  RVec y;
  for (int i = 0; i < 3; ++i) y[i] = H[3 * i] * x[0] + H[3 * i + 1] * x[1] + H[3 * i + 2] * x[2];
  return y;
}

// The least double found at or above q: to_double may round either way.
double up(const Rational& q) {
  double d = to_double(q);
  while (Rational(d) < q) d = std::nextafter(d, kInf);
  return d;
}

// A double at or above sqrt(q), q >= 0.
double sqrt_up(const Rational& q) {
  double s = std::sqrt(std::max(0.0, to_double(q)));
  while (Rational(Rational(s) * Rational(s)) < q) s = std::nextafter(s, kInf);
  return s;
}

// An upper bound of the angle between a and b, or -1 when they are 90 deg or more apart: for
// theta < pi/2, theta <= tan(theta) = |a x b| / (a . b), exact up to the final square root.
double angle_up(const RVec& a, const RVec& b) {
  const Rational d = dot(a, b);
  if (!(d > 0)) return -1;
  const RVec c = cross(a, b);
  return sqrt_up(Rational(dot(c, c) / (d * d)));
}

// The area vector of a face's outer loop (twice its area times its outward normal): the
// direction of the Newell normal the checker's poly.cpp uses, here exactly.
RVec newell(const Poly& P, int f) {
  RVec n = {Rational(0), Rational(0), Rational(0)};
  const auto& L = P.F[f].loops[0];
  for (std::size_t i = 0; i < L.size(); ++i)
    n = add(n, cross(rv(P.V[L[i]].p), rv(P.V[L[(i + 1) % L.size()]].p)));
  return n;
}

std::string set_text(const std::vector<SetPc>& pcs) {
  std::string s;
  for (const auto& p : pcs) s += (s.empty() ? "" : ";") + pc_text(p);
  return s;
}

}  // namespace

// Steps 1 to 3 of the spec for one model. The argument of the spec holds for an isometry; H
// as written is orthogonal only to rounding, so eps and delta are bounded for H', the
// orthogonal matrix nearest H (its polar factor): |H - H'| <= dH = |H^T H - I|_F (spectral
// norms; with s the singular values of H, |s - 1| <= |s^2 - 1|), which moves h(v) by at most
// dH |v - c| and turns a vector by at most asin(dH) <= dH (1 + dH) off H's image.
SolidMap match_symmetry(const Poly& P, const std::string& name, const Mat3& Hd, const Vec3& cd,
                        double scale) {
  SolidMap m;
  RMat H;
  for (int i = 0; i < 9; ++i) H[i] = Rational(Hd(i / 3, i % 3));
  Rational f2(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Rational e(H[i] * H[j] + H[3 + i] * H[3 + j] + H[6 + i] * H[6 + j] - (i == j ? 1 : 0));
      f2 += e * e;
    }
  const double dH = sqrt_up(f2);
  // Orthogonal to rounding, as the spec's "orthogonal" reads for doubles; a looser H would
  // still be sound through H', but is no symmetry the generator meant.
  if (dH > kGross) {
    m.problem = name + ".R is not orthogonal (|R^T R - I| = " + fmt(dH) + ")";
    return m;
  }
  const Rational det(H[0] * (H[4] * H[8] - H[5] * H[7]) - H[1] * (H[3] * H[8] - H[5] * H[6]) +
                     H[2] * (H[3] * H[7] - H[4] * H[6]));
  m.det_sign = det > 0 ? 1 : det < 0 ? -1 : 0;
  // Each vertex to the vertex nearest its image, found in doubles: any one-to-one matching is
  // sound, since eps is then measured exactly.
  const int nv = static_cast<int>(P.V.size());
  const RVec c = rv(cd);
  m.v.assign(nv, -1);
  std::vector<int> hit(nv, -1);
  Rational worst(0), reach(0);
  for (int i = 0; i < nv; ++i) {
    const Vec3 img = Hd * (P.V[i].p - cd) + cd;
    int best = 0;
    for (int j = 1; j < nv; ++j)
      if ((P.V[j].p - img).squaredNorm() < (P.V[best].p - img).squaredNorm()) best = j;
    if (hit[best] >= 0) {
      m.problem = name + ": vertices " + std::to_string(hit[best]) + " and " + std::to_string(i) +
                  " both map nearest to vertex " + std::to_string(best) + " (not one to one)";
      return m;
    }
    hit[best] = i;
    m.v[i] = best;
    const RVec x = sub(rv(P.V[i].p), c);
    const RVec d = sub(add(mul(H, x), c), rv(P.V[best].p));
    worst = std::max(worst, dot(d, d));
    reach = std::max(reach, dot(x, x));
  }
  m.eps = up(Rational(Rational(sqrt_up(worst)) + Rational(dH) * Rational(sqrt_up(reach))));
  // "Near": eps far below every feature of the model, where the spec's argument (elements
  // within eps of their images' elements, points deeper than eps staying inside) holds.
  if (m.eps > kGross * scale) {
    m.problem = name + ": a vertex's image lies " + fmt(m.eps) +
                " mm from its nearest vertex, more than " + fmt(kGross * scale) +
                " mm: not a symmetry of the model";
    return m;
  }
  // Edges to the edge of the matched ends, their directions following those ends.
  double delta = 0;
  m.e.assign(P.E.size(), -1);
  for (std::size_t e = 0; e < P.E.size(); ++e) {
    const Edge& E = P.E[e];
    const int a = m.v[E.v0], b = m.v[E.v1];
    const auto it = P.edge_of.find({std::min(a, b), std::max(a, b)});
    if (it == P.edge_of.end()) {
      m.problem = name + ": edge " + std::to_string(e) + "'s ends map to vertices " +
                  std::to_string(a) + " and " + std::to_string(b) + ", which no edge joins";
      return m;
    }
    m.e[e] = it->second;
    const double th =
        angle_up(mul(H, sub(rv(P.V[E.v1].p), rv(P.V[E.v0].p))), sub(rv(P.V[b].p), rv(P.V[a].p)));
    if (th < 0) {
      m.problem = name + ": edge " + std::to_string(e) + " turns by 90 deg or more onto edge " +
                  std::to_string(m.e[e]);
      return m;
    }
    delta = std::max(delta, th);
  }
  // Faces to the face of the matched vertex set, whose boundary edges must be the images of
  // the face's (the same polygon, not only the same corners); outward normal onto outward
  // normal (an isometry of the solid onto itself keeps the outside outside).
  std::map<std::vector<int>, int> by_verts;
  for (std::size_t f = 0; f < P.F.size(); ++f) {
    std::vector<int> vs = P.F[f].verts;
    std::sort(vs.begin(), vs.end());
    by_verts.emplace(vs, static_cast<int>(f));
  }
  m.f.assign(P.F.size(), -1);
  for (std::size_t f = 0; f < P.F.size(); ++f) {
    std::vector<int> vs;
    for (int v : P.F[f].verts) vs.push_back(m.v[v]);
    std::sort(vs.begin(), vs.end());
    const auto it = by_verts.find(vs);
    if (it == by_verts.end()) {
      m.problem = name + ": face " + std::to_string(f) + "'s vertices map to no face's";
      return m;
    }
    const int g = it->second;
    std::set<int> mine, theirs(P.F[g].edges.begin(), P.F[g].edges.end());
    for (int e : P.F[f].edges) mine.insert(m.e[e]);
    if (mine != theirs) {
      m.problem = name + ": face " + std::to_string(f) + "'s edges do not map onto face " +
                  std::to_string(g) + "'s";
      return m;
    }
    m.f[f] = g;
    const double th = angle_up(mul(H, newell(P, static_cast<int>(f))), newell(P, g));
    if (th < 0) {
      m.problem = name + ": face " + std::to_string(f) + "'s normal turns by 90 deg or more onto " +
                  "face " + std::to_string(g) + "'s";
      return m;
    }
    delta = std::max(delta, th);
  }
  m.delta = up(Rational(Rational(delta) + Rational(dH) * Rational(1 + Rational(dH))));
  return m;
}

std::string check_image(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& image_of,
                        const std::map<SetKey, DecidedSet>& decided, SymmetryCache& cache) {
  if (!image_of.is_object()) throw std::runtime_error("image_of is not an object");
  const std::string src_text = image_of.at("pcs").get<std::string>();
  const std::vector<SetPc> src = parse_pcs(ctx.g, src_text);
  auto map_of = [&](char solid) -> const SolidMap& {
    const std::string name(1, solid);
    const json& j = image_of.at(name);
    const json& R = j.at("R");
    if (!R.is_array() || R.size() != 9)
      throw std::runtime_error("image_of." + name + ".R is not 9 numbers");
    std::array<double, 12> key;
    Mat3 H;
    for (int i = 0; i < 9; ++i) H(i / 3, i % 3) = key[i] = R[i].get<double>();
    const Vec3 c = get_vec3(j, "c");
    for (int i = 0; i < 3; ++i) key[9 + i] = c[i];
    auto it = cache.find({solid, key});
    if (it == cache.end())
      it = cache
               .emplace(std::make_pair(solid, key),
                        match_symmetry(solid == 'A' ? ctx.g.A : ctx.g.B, name, H, c, ctx.tol.scale))
               .first;
    return it->second;
  };
  const SolidMap &mA = map_of('A'), &mB = map_of('B');
  // 1-3: both maps symmetries, both rotations or both reflections (g X h^-1 a rotation).
  for (const SolidMap* m : {&mA, &mB})
    if (!m->problem.empty()) return "not a symmetry: " + m->problem;
  if (mA.det_sign != mB.det_sign)
    return "A.R and B.R are not both rotations or both reflections (det signs " +
           std::to_string(mA.det_sign) + ", " + std::to_string(mB.det_sign) + ")";
  // 4: this set is the image of the decided set, which is accepted as invalid by cells.
  std::vector<SetPc> img;
  for (const SetPc& p : src) {
    auto el = [](const SolidMap& m, int kind, int i) {
      return kind == 0 ? m.v[i] : kind == 1 ? m.e[i] : m.f[i];
    };
    img.push_back({p.type, el(mA, kind_a(p.type), p.a), el(mB, kind_b(p.type), p.b)});
  }
  if (set_key(img) != set_key(pcs))
    return "the set is not the image of {" + src_text + "}: the maps take it to {" + set_text(img) +
           "}";
  const auto it = decided.find(set_key(src));
  if (it == decided.end()) return "the decided set {" + src_text + "} is not listed in the file";
  const DecidedSet& d = it->second;
  const std::string which = "the decided set {" + src_text + "} (set " + std::to_string(d.index);
  if (d.kind == "image") return which + ") is itself an image: an image of an image is refused";
  if (d.kind != "cells") return which + ") is not invalid by cells (" + d.kind + ")";
  if (d.outcome != CertOutcome::Accepted) return which + ") is not accepted";
  // 5: the decided tree's tolerances looser than the file's by what the maps miss, compared
  // exactly (eps and delta are upper bounds already).
  const Tol &f = ctx.tol, &t = d.tree;
  const Rational eps = Rational(mA.eps) + Rational(mB.eps);
  const Rational del = Rational(mA.delta) + Rational(mB.delta);
  const std::string em = " (eps " + fmt(up(eps)) + " mm, delta " + fmt(up(del)) + " rad)";
  auto fails = [&](const char* key, double have, const Rational& bound, bool at_least) {
    return which + ")'s tree has " + key + " " + fmt(have) + ", not " + (at_least ? ">= " : "<= ") +
           fmt(to_double(bound)) + em;
  };
  // The spec's "min_margin_mm by eps (or 0)": a margin of 0 where eps exceeds the file's leaves
  // contact points up to eps - margin outside their elements at the decided set's pose; moved
  // onto their elements, they touch within touch_tol_mm + 2 eps, which the checker requires then.
  const bool margin_dropped = t.margin == 0 && Rational(f.margin) < eps;
  const Rational touch_need = Rational(f.touch) + (margin_dropped ? Rational(2 * eps) : eps);
  if (Rational(t.touch) < touch_need) return fails("touch_tol_mm", t.touch, touch_need, true);
  const Rational margin_need = Rational(f.margin) - eps;
  if (t.margin != 0 && Rational(t.margin) > margin_need)
    return fails("min_margin_mm", t.margin, margin_need, false);
  const Rational rot_need = Rational(f.rot) + del;
  if (Rational(t.rot) < rot_need) return fails("rot_tol_rad", t.rot, rot_need, true);
  const Rational off_need = Rational(f.off_circle) + 2 * del;
  if (Rational(t.off_circle) < off_need)
    return fails("off_circle_rad", t.off_circle, off_need, true);
  const Rational slack_need = Rational(f.slack) - 2 * del * (1 + Rational(1) / Rational(f.slack));
  if (Rational(t.slack) > slack_need) return fails("local_slack", t.slack, slack_need, false);
  if (Rational(t.deep_extra) < eps) return fails("deep_extra_mm", t.deep_extra, eps, true);
  return "";
}

}  // namespace oracle::cert

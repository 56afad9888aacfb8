#include "cfgen/enumerate/symmetry.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

namespace cf::gen {
namespace {

// Orthonormal frame (columns) built from two independent vectors; `hand` -1 flips the third
// axis, so that a map between two such frames of opposite hands is a reflection.
Mat3 frame(const Vec3& x, const Vec3& y, double hand) {
  Mat3 F;
  F.col(0) = x.normalized();
  F.col(2) = hand * x.cross(y).normalized();
  F.col(1) = (hand * F.col(2)).cross(F.col(0));
  return F;
}

// The vertex whose offset from the centroid is within tol of q, or -1. `order` sorts the
// vertices by the x of their offsets.
int find_vertex(const std::vector<Vec3>& P, const std::vector<int>& order, const Vec3& q,
                double tol) {
  auto lo = std::lower_bound(order.begin(), order.end(), q.x() - tol, [&](int i, double x) {
    return P[static_cast<std::size_t>(i)].x() < x;
  });
  for (; lo != order.end() && P[static_cast<std::size_t>(*lo)].x() <= q.x() + tol; ++lo)
    if ((P[static_cast<std::size_t>(*lo)] - q).norm() <= tol) return *lo;
  return -1;
}

// The symmetry that maps vertex offsets by R (to within tol), or none.
bool complete(const Polyhedron& m, const std::vector<Vec3>& P, const std::vector<int>& order,
              Mat3 R, double tol, Symmetry& out) {
  const std::size_t n = P.size();
  double shortest = HUGE_VAL;
  for (const Edge& e : m.edges()) shortest = std::min(shortest, e.length);
  constexpr double kNormalTol = 1e-9;  // an exact model's normals match to rounding
  const double normal_tol = std::min(0.1, std::max(kNormalTol, 4 * tol / shortest));
  std::vector<int> perm(n);
  for (std::size_t i = 0; i < n; ++i)
    if ((perm[i] = find_vertex(P, order, R * P[i], tol)) < 0) return false;
  std::vector<int> sorted = perm;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;
  // The orthogonal map that fits every correspondence best (Kabsch), of the same hand: the
  // two vertices R was built from carry the rounding of their own coordinates.
  Mat3 H = Mat3::Zero();
  for (std::size_t i = 0; i < n; ++i) H += P[static_cast<std::size_t>(perm[i])] * P[i].transpose();
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 S = Mat3::Identity();
  const double hand = R.determinant() > 0 ? 1.0 : -1.0;
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() * hand < 0) S(2, 2) = -1;
  R = svd.matrixU() * S * svd.matrixV().transpose();
  for (std::size_t i = 0; i < n; ++i)
    if ((R * P[i] - P[static_cast<std::size_t>(perm[i])]).norm() > tol) return false;
  std::map<std::pair<int, int>, int> edge_of;
  for (std::size_t e = 0; e < m.num_edges(); ++e)
    edge_of[{static_cast<int>(m.edges()[e].v0.index()),
             static_cast<int>(m.edges()[e].v1.index())}] = static_cast<int>(e);
  std::map<std::vector<int>, int> face_of;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    std::vector<int> vs;
    for (VertexId v : m.faces()[f].vertices) vs.push_back(static_cast<int>(v.index()));
    face_of[vs] = static_cast<int>(f);
  }
  out.R = R;
  out.vertex = perm;
  out.edge.assign(m.num_edges(), -1);
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const auto& E = m.edges()[e];
    const int a = perm[E.v0.index()], b = perm[E.v1.index()];
    auto it = edge_of.find({std::min(a, b), std::max(a, b)});
    if (it == edge_of.end()) return false;
    out.edge[e] = it->second;
  }
  out.face.assign(m.num_faces(), -1);
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    std::vector<int> vs;
    for (VertexId v : m.faces()[f].vertices) vs.push_back(perm[v.index()]);
    std::sort(vs.begin(), vs.end());
    auto it = face_of.find(vs);
    if (it == face_of.end()) return false;
    // A face's image has the image normal, not its opposite: to within how far vertices
    // matched (tol) turns a face's plane, at most tol / (half its shortest edge) each way.
    if ((R * m.faces()[f].normal - m.faces()[static_cast<std::size_t>(it->second)].normal).norm() >
        normal_tol)
      return false;
    out.face[f] = it->second;
  }
  return true;
}

// The identity map of m.
Symmetry identity(const Polyhedron& m) {
  Symmetry s;
  s.c = m.vertex_centroid();
  for (auto [perm, count] :
       {std::make_pair(&s.vertex, m.num_vertices()), std::make_pair(&s.edge, m.num_edges()),
        std::make_pair(&s.face, m.num_faces())}) {
    perm->resize(count);
    std::iota(perm->begin(), perm->end(), 0);
  }
  return s;
}

}  // namespace

std::vector<Symmetry> symmetries(const Polyhedron& m, double tol) {
  const std::size_t n = m.num_vertices();
  const Vec3 c = m.vertex_centroid();
  std::vector<Vec3> P(n);
  for (std::size_t i = 0; i < n; ++i) P[i] = m.vertices()[i].p - c;
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int i, int j) {
    return P[static_cast<std::size_t>(i)].x() < P[static_cast<std::size_t>(j)].x();
  });
  std::vector<Symmetry> out{identity(m)};
  if (n < 3) return out;
  // A symmetry maps the vertex farthest from the centroid, i0, to one as far, and the vertex
  // i1 that spans the widest angle with it to one as far at the same dot product: the two
  // frames fix the map.
  std::size_t i0 = 0, i1 = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (P[i].norm() > P[i0].norm()) i0 = i;
  for (std::size_t i = 0; i < n; ++i)
    if (P[i].cross(P[i0]).norm() > P[i1].cross(P[i0]).norm()) i1 = i;
  if (P[i1].cross(P[i0]).norm() <= tol * std::max(1.0, P[i0].norm())) return out;
  const double r0 = P[i0].norm(), r1 = P[i1].norm(), d01 = P[i0].dot(P[i1]);
  for (double hand : {1.0, -1.0}) {
    const Mat3 F0 = frame(P[i0], P[i1], 1.0);
    for (std::size_t j0 = 0; j0 < n; ++j0) {
      if (std::abs(P[j0].norm() - r0) > tol) continue;
      for (std::size_t j1 = 0; j1 < n; ++j1) {
        if (j1 == j0 || std::abs(P[j1].norm() - r1) > tol ||
            std::abs(P[j0].dot(P[j1]) - d01) > tol * (r0 + r1))
          continue;
        if (P[j1].cross(P[j0]).norm() <= tol * std::max(1.0, r0)) continue;
        const Mat3 R = frame(P[j0], P[j1], hand) * F0.transpose();
        Symmetry s;
        s.c = c;
        if (!complete(m, P, order, R, tol, s)) continue;
        if (std::any_of(out.begin(), out.end(),
                        [&](const Symmetry& t) { return t.vertex == s.vertex; }))
          continue;
        out.push_back(std::move(s));
      }
    }
  }
  // The maps found must form a group (the orbits rest on it). A model symmetric only to about
  // the tolerance could yield some maps and not their products: then none is used.
  for (const Symmetry& s : out)
    for (const Symmetry& t : out) {
      std::vector<int> st(n);
      for (std::size_t i = 0; i < n; ++i) st[i] = s.vertex[static_cast<std::size_t>(t.vertex[i])];
      if (std::none_of(out.begin(), out.end(), [&](const Symmetry& u) { return u.vertex == st; }))
        return {out.front()};
    }
  return out;
}

namespace {

// m with each vertex at the mean of its preimages under `maps` (a group): c + mean over g of
// R_g^T (v_{g(i)} - c). With maps that compose exactly the result is exactly symmetric; with
// maps fitted to a rounded model, to about the square of their error.
Polyhedron mean_over(const Polyhedron& m, const std::vector<Symmetry>& maps) {
  const Vec3 c = m.vertex_centroid();
  std::vector<Vec3> v(m.num_vertices(), Vec3::Zero());
  for (const Symmetry& g : maps)
    for (std::size_t i = 0; i < v.size(); ++i)
      v[i] += g.R.transpose() * (m.vertices()[static_cast<std::size_t>(g.vertex[i])].p - c);
  for (Vec3& x : v) x = c + x / static_cast<double>(maps.size());
  return m.with_vertices(std::move(v));
}

}  // namespace

Polyhedron symmetrized(const Polyhedron& m, double loose_tol, double strict_tol, double* moved) {
  if (moved) *moved = 0;
  const std::size_t exact = symmetries(m, strict_tol).size();
  const std::vector<Symmetry> loose = symmetries(m, loose_tol);
  if (loose.size() <= exact) return m;
  // Twice: the second mean uses maps refitted to the first, exact to the square of the
  // rounding (docs/features.md, "Precision").
  Polyhedron s = mean_over(m, loose);
  const std::vector<Symmetry> refit = symmetries(s, loose_tol);
  if (refit.size() != loose.size()) return m;
  s = mean_over(s, refit);
  if (symmetries(s, strict_tol).size() != loose.size()) return m;
  if (moved)
    for (std::size_t i = 0; i < m.num_vertices(); ++i)
      *moved = std::max(*moved, (s.vertices()[i].p - m.vertices()[i].p).norm());
  return s;
}

namespace {

// The angle between unit vectors u and w, from their chord (exact for any angle).
double angle_between(const Vec3& u, const Vec3& w) {
  return 2 * std::asin(std::min(1.0, 0.5 * (u - w).norm()));
}

// How far map s of m misses: each vertex's image from the vertex it is taken to, each edge's
// turned direction from its image edge's (the sign following the ends), each face's turned
// normal from its image face's. Rounded up by a few units of rounding of the arithmetic.
MapError map_error(const Polyhedron& m, const Symmetry& s) {
  MapError e;
  for (std::size_t i = 0; i < m.num_vertices(); ++i) {
    const Vec3 image = s.R * (m.vertices()[i].p - s.c) + s.c;
    e.length =
        std::max(e.length, (image - m.vertices()[static_cast<std::size_t>(s.vertex[i])].p).norm());
  }
  for (std::size_t k = 0; k < m.num_edges(); ++k) {
    const Edge& E = m.edges()[k];
    const Edge& F = m.edges()[static_cast<std::size_t>(s.edge[k])];
    const double sign = s.vertex[E.v0.index()] == static_cast<int>(F.v0.index()) ? 1.0 : -1.0;
    e.angle = std::max(e.angle, angle_between(s.R * E.dir, sign * F.dir));
  }
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    e.angle =
        std::max(e.angle, angle_between(s.R * m.faces()[f].normal,
                                        m.faces()[static_cast<std::size_t>(s.face[f])].normal));
  const double size = (m.bbox_max() - m.bbox_min()).norm();
  e.length += 1e-14 * size;
  e.angle += 1e-14;
  return e;
}

// The largest misses over a model's maps.
MapError worst_error(const Polyhedron& m, const std::vector<Symmetry>& maps) {
  MapError out;
  for (const Symmetry& s : maps) {
    const MapError e = map_error(m, s);
    out = {std::max(out.length, e.length), std::max(out.angle, e.angle)};
  }
  return out;
}

}  // namespace

const Symmetry& PairSymmetries::map_a(std::size_t k) const {
  return a_[static_cast<std::size_t>(pairs_[k].first)];
}
const Symmetry& PairSymmetries::map_b(std::size_t k) const {
  return b_[static_cast<std::size_t>(pairs_[k].second)];
}

PairSymmetries::PairSymmetries(const Polyhedron& A, const Polyhedron& B, double tol, bool enabled) {
  a_ = enabled ? symmetries(A, tol) : std::vector<Symmetry>{identity(A)};
  b_ = enabled ? symmetries(B, tol) : std::vector<Symmetry>{identity(B)};
  if (a_.size() * b_.size() > 1) {
    const MapError ea = worst_error(A, a_), eb = worst_error(B, b_);
    error_ = {ea.length + eb.length, ea.angle + eb.angle};
  }
  for (std::size_t i = 0; i < a_.size(); ++i) {
    a_first_.push_back(pairs_.size());
    for (std::size_t j = 0; j < b_.size(); ++j)
      if ((a_[i].R.determinant() > 0) == (b_[j].R.determinant() > 0))
        pairs_.push_back({static_cast<int>(i), static_cast<int>(j)});
  }
  a_first_.push_back(pairs_.size());
}

Pc PairSymmetries::image(const Pc& pc, std::size_t k) const {
  const Symmetry& h = map_a(k);
  const Symmetry& g = map_b(k);
  return Pc{pc.type, h.of(a_kind(pc.type))[static_cast<std::size_t>(pc.a)],
            g.of(b_kind(pc.type))[static_cast<std::size_t>(pc.b)]};
}

PcSet PairSymmetries::image(const PcSet& s, std::size_t k) const {
  PcSet out;  // insert keeps the canonical order, without allocating
  for (const Pc& pc : s) out.insert(image(pc, k));
  return out;
}

Pose PairSymmetries::image(const Pose& pose, std::size_t k) const {
  const Symmetry& h = map_a(k);
  const Symmetry& g = map_b(k);
  // x_B = g(X(h^-1(x_A))), with h(x) = H (x - c_A) + c_A and g(y) = G (y - c_B) + c_B.
  Pose out;
  out.R_BA = g.R * pose.R_BA * h.R.transpose();
  out.t_BA = g.R * (pose.R_BA * h.c + pose.t_BA - g.c) + g.c - out.R_BA * h.c;
  return out;
}

bool pcset_less(const PcSet& x, const PcSet& y) {
  if (x.size() != y.size()) return x.size() < y.size();
  for (int i = 0; i < x.size(); ++i)
    if (x[i] != y[i]) return x[i] < y[i];
  return false;
}

PcSet PairSymmetries::canonical(const PcSet& s) const {
  if (s.size() == 0 || pairs_.size() == 1) return s;
  // The least image's first PC is the least PC of any image: of s's least type (maps keep
  // types), with the least element of A that a map takes one of those PCs' elements to. Only
  // the maps of A that do can give the least image (a few of A's maps for most sets), so only
  // their pairs are tried.
  const PcType t0 = s[0].type;
  const ElementKind ka = a_kind(t0);
  auto least_a = [&](const Symmetry& h) {
    int m = std::numeric_limits<int>::max();
    for (int j = 0; j < s.size() && s[j].type == t0; ++j)
      m = std::min(m, h.of(ka)[static_cast<std::size_t>(s[j].a)]);
    return m;
  };
  int reach = std::numeric_limits<int>::max();
  for (const Symmetry& h : a_) reach = std::min(reach, least_a(h));
  PcSet best = s;
  for (std::size_t i = 0; i < a_.size(); ++i) {
    if (least_a(a_[i]) != reach) continue;
    for (std::size_t k = a_first_[i]; k < a_first_[i + 1]; ++k) {
      // Images have s's size: one whose smallest PC comes after best's first is not smaller,
      // and is passed by before it is sorted (most are).
      std::array<Pc, PcSet::kMaxPcs> img;
      bool smaller_first = false;
      for (int j = 0; j < s.size(); ++j) {
        img[static_cast<std::size_t>(j)] = image(s[j], k);
        if (!(best[0] < img[static_cast<std::size_t>(j)])) smaller_first = true;
      }
      if (!smaller_first) continue;
      PcSet t;
      for (int j = 0; j < s.size(); ++j) t.insert(img[static_cast<std::size_t>(j)]);
      if (pcset_less(t, best)) best = t;
    }
  }
  return best;
}

}  // namespace cf::gen

#include "cfgen/decide/mirror_corners.hpp"

// GCC 12 reports a static zero in cpp_int.hpp as maybe uninitialized (a false positive in
// Boost's header, not in this file).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/multiprecision/cpp_int.hpp>
#pragma GCC diagnostic pop

#include <array>
#include <optional>

namespace cf::gen {
namespace {

// Exact rationals: a double converts to the rational of exactly its value, so every
// condition below is decided on the coordinates as the model holds them.
using Q = boost::multiprecision::cpp_rational;

struct QVec {
  Q x, y, z;
};
QVec exact(const Vec3& p) { return {Q(p.x()), Q(p.y()), Q(p.z())}; }
QVec operator-(const QVec& a, const QVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
QVec operator+(const QVec& a, const QVec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Q dot(const QVec& a, const QVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
QVec cross(const QVec& a, const QVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
int sign(const Q& q) { return q > 0 ? 1 : q < 0 ? -1 : 0; }

// One model's side of the pair: two edges from a shared vertex v along a common face, and
// the other face at each edge.
struct Corner {
  int v = -1;
  std::array<int, 2> edge{}, other{};
  int face = -1;
};

template <class Id>
int ix(Id id) {
  return static_cast<int>(id.index());
}

int other_end(const Polyhedron& m, int e, int v) {
  const Edge& E = m.edges()[e];
  return ix(E.v0) == v ? ix(E.v1) : ix(E.v0);
}

std::optional<Corner> corner(const Polyhedron& m, int e1, int e2) {
  if (e1 == e2) return std::nullopt;
  const Edge &E1 = m.edges()[e1], &E2 = m.edges()[e2];
  if (!E1.convex || !E2.convex) return std::nullopt;
  Corner c;
  for (int v : {ix(E1.v0), ix(E1.v1)})
    if (v == ix(E2.v0) || v == ix(E2.v1)) c.v = v;
  if (c.v < 0) return std::nullopt;
  for (int f : {ix(E1.left), ix(E1.right)})
    if (f == ix(E2.left) || f == ix(E2.right)) c.face = f;
  if (c.face < 0) return std::nullopt;
  c.edge = {e1, e2};
  c.other[0] = ix(E1.left) == c.face ? ix(E1.right) : ix(E1.left);
  c.other[1] = ix(E2.left) == c.face ? ix(E2.right) : ix(E2.left);
  return c;
}

Vec3 leg(const Polyhedron& m, const Corner& c, int k) {
  return (m.vertices()[other_end(m, c.edge[k], c.v)].p - m.vertices()[c.v].p).normalized();
}

// The conditions in floating point, each allowed 1e-9 of slack (unit vectors, so a few ulps of
// rounding at most): a pair that fails one by more cannot pass it exactly.
bool screen(const Polyhedron& A, const Corner& ca, const Polyhedron& B, const Corner& cb) {
  constexpr double kSlack = 1e-9;
  const Vec3 a1 = leg(A, ca, 0), a2 = leg(A, ca, 1), b1 = leg(B, cb, 0), b2 = leg(B, cb, 1);
  auto n = [](const Polyhedron& m, int f) -> const Vec3& { return m.faces()[f].normal; };
  const Vec3 &G = n(A, ca.face), &F = n(B, cb.face);
  return n(A, ca.other[0]).dot(a2) < kSlack && n(A, ca.other[1]).dot(a1) < kSlack &&
         n(B, cb.other[0]).dot(b2) > -kSlack && n(B, cb.other[1]).dot(b1) > -kSlack &&
         G.dot(n(A, ca.other[0])) > -kSlack && G.dot(n(A, ca.other[1])) > -kSlack &&
         F.dot(n(B, cb.other[0])) > -kSlack && F.dot(n(B, cb.other[1])) > -kSlack &&
         std::abs(a1.dot(a2) - b1.dot(b2)) < kSlack &&
         a1.cross(a2).dot(G) * b1.cross(b2).dot(F) < kSlack;
}

// Newell's normal of face f (outward: its loops run counter-clockwise seen from outside),
// exact; nullopt when a vertex of the face lies off that normal's plane.
std::optional<QVec> face_normal(const Polyhedron& m, int f) {
  const Face& F = m.faces()[f];
  QVec n{0, 0, 0};
  for (const auto& loop : F.loops)
    for (std::size_t i = 0; i < loop.size(); ++i)
      n = n + cross(exact(m.vertices()[loop[i].index()].p),
                    exact(m.vertices()[loop[(i + 1) % loop.size()].index()].p));
  const QVec p0 = exact(m.vertices()[F.loops[0][0].index()].p);
  for (VertexId v : F.vertices)
    if (sign(dot(n, exact(m.vertices()[v.index()].p) - p0)) != 0) return std::nullopt;
  return n;
}

// The corner's exact legs a_1, a_2: from v to the other ends of its edges.
std::array<QVec, 2> exact_legs(const Polyhedron& m, const Corner& c) {
  const QVec v = exact(m.vertices()[c.v].p);
  return {exact(m.vertices()[other_end(m, c.edge[0], c.v)].p) - v,
          exact(m.vertices()[other_end(m, c.edge[1], c.v)].p) - v};
}

// Condition (5): the angles between the legs are equal (their cosines' squares and signs).
bool equal_angles(const std::array<QVec, 2>& a, const std::array<QVec, 2>& b) {
  const Q ca = dot(a[0], a[1]), cb = dot(b[0], b[1]);
  return sign(ca) == sign(cb) &&
         ca * ca * dot(b[0], b[0]) * dot(b[1], b[1]) == cb * cb * dot(a[0], a[0]) * dot(a[1], a[1]);
}

// The corner's exact vectors: its legs, the common face's normal and the other faces'.
struct ExactCorner {
  std::array<QVec, 2> leg;
  QVec face;
  std::array<QVec, 2> other;
};

// nullopt when a face is not exactly planar or an edge is not convex (condition 1).
std::optional<ExactCorner> exact_corner(const Polyhedron& m, const Corner& c,
                                        const std::array<QVec, 2>& legs) {
  const auto nf = face_normal(m, c.face), n1 = face_normal(m, c.other[0]),
             n2 = face_normal(m, c.other[1]);
  if (!nf || !n1 || !n2) return std::nullopt;
  ExactCorner x{legs, *nf, {*n1, *n2}};
  for (int k = 0; k < 2; ++k) {
    // Convex edge: (n(L) x n(R)) . d > 0, d the edge's direction along its left face's loop.
    const Edge& E = m.edges()[c.edge[k]];
    const QVec& nl = ix(E.left) == c.face ? x.face : x.other[k];
    const QVec& nr = ix(E.left) == c.face ? x.other[k] : x.face;
    const QVec d = exact(m.vertices()[ix(E.v1)].p) - exact(m.vertices()[ix(E.v0)].p);
    if (sign(dot(cross(nl, nr), d)) <= 0) return std::nullopt;
  }
  return x;
}

// Conditions (2), (3), (4) and (6) of docs/certificates.md, `mirror-corners`, exactly.
bool mirror(const ExactCorner& a, const ExactCorner& b) {
  if (!(dot(a.other[0], a.leg[1]) < 0 && dot(a.other[1], a.leg[0]) < 0)) return false;
  if (!(dot(b.other[0], b.leg[1]) > 0 && dot(b.other[1], b.leg[0]) > 0)) return false;
  for (int k = 0; k < 2; ++k)
    if (dot(a.face, a.other[k]) < 0 || dot(b.face, b.other[k]) < 0) return false;
  return sign(dot(cross(a.leg[0], a.leg[1]), a.face)) *
             sign(dot(cross(b.leg[0], b.leg[1]), b.face)) <
         0;
}

}  // namespace

bool mirror_corners(const Polyhedron& A, const Polyhedron& B, const Pc& p, const Pc& q) {
  if (p.type != PcType::kEE || q.type != PcType::kEE) return false;
  const auto ca = corner(A, p.a, q.a);
  const auto cb = corner(B, p.b, q.b);
  if (!ca || !cb || !screen(A, *ca, B, *cb)) return false;
  // Exact arithmetic from here: the angles first, the cheapest test that the files' rounding
  // fails (corners of irrational angle, as regular polygons have).
  const auto la = exact_legs(A, *ca), lb = exact_legs(B, *cb);
  if (!equal_angles(la, lb)) return false;
  const auto xa = exact_corner(A, *ca, la);
  const auto xb = exact_corner(B, *cb, lb);
  return xa && xb && mirror(*xa, *xb);
}

}  // namespace cf::gen

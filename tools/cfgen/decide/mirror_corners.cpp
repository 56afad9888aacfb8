#include "cfgen/decide/mirror_corners.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace cf::gen {
namespace {

// Every quantity below is a product of unit vectors computed in floating point (a few ulps of
// error); the oracle's checker, which rebuilds the normals its own way, allows 1e-13 on top
// of the margins below: the generator claims only what it accepts.
constexpr double kRounding = 1e-12;
// Condition (7): a face normal at most this far from perpendicular to the corner's edges on
// its face (a file's rounding leaves ~1e-16). It turns an edge's cone by at most about twice
// as much, so the sign conditions need 4 kTilt more and the cones' excess x gets 4 kTilt added.
constexpr double kTilt = 1e-9;
constexpr double kSign = 4 * kTilt + kRounding;

// One model's side of the pair: two edges from a shared vertex v along a common face, and
// the other face at each edge.
struct Corner {
  int v = -1;
  std::array<int, 2> edge{}, other{};
  int face = -1;
};

int other_end(const Polyhedron& m, int e, int v) {
  const Edge& E = m.edges()[e];
  return E.v0.value() == v ? E.v1.value() : E.v0.value();
}

std::optional<Corner> corner(const Polyhedron& m, int e1, int e2) {
  if (e1 == e2) return std::nullopt;
  const Edge &E1 = m.edges()[e1], &E2 = m.edges()[e2];
  if (!E1.convex || !E2.convex) return std::nullopt;
  Corner c;
  for (int v : {E1.v0.value(), E1.v1.value()})
    if (v == E2.v0.value() || v == E2.v1.value()) c.v = v;
  if (c.v < 0) return std::nullopt;
  for (int f : {E1.left.value(), E1.right.value()})
    if (f == E2.left.value() || f == E2.right.value()) c.face = f;
  if (c.face < 0) return std::nullopt;
  c.edge = {e1, e2};
  c.other[0] = E1.left.value() == c.face ? E1.right.value() : E1.left.value();
  c.other[1] = E2.left.value() == c.face ? E2.right.value() : E2.left.value();
  return c;
}

// The corner's unit vectors: its legs along the edges from v, the common face's normal and
// the other faces' normals.
struct Frame {
  std::array<Vec3, 2> leg, other;
  Vec3 face;
};

Frame frame(const Polyhedron& m, const Corner& c) {
  const Vec3& p = m.vertices()[c.v].p;
  auto leg = [&](int k) { return (m.vertices()[other_end(m, c.edge[k], c.v)].p - p).normalized(); };
  auto n = [&](int f) { return m.faces()[f].normal; };
  return {{leg(0), leg(1)}, {n(c.other[0]), n(c.other[1])}, n(c.face)};
}

// Condition (7): the normals perpendicular to the corner's edges on their faces.
bool perpendicular(const Frame& c) {
  for (int k = 0; k < 2; ++k)
    if (std::abs(c.face.dot(c.leg[k])) > kTilt || std::abs(c.other[k].dot(c.leg[k])) > kTilt)
      return false;
  return true;
}

// Conditions (2), (3) and (6) of docs/certificates.md, `mirror-corners`, each by more than
// kSign: v convex, w a saddle, opposite handedness.
bool shapes_hold(const Frame& a, const Frame& b) {
  if (!(a.other[0].dot(a.leg[1]) < -kSign && a.other[1].dot(a.leg[0]) < -kSign)) return false;
  if (!(b.other[0].dot(b.leg[1]) > kSign && b.other[1].dot(b.leg[0]) > kSign)) return false;
  const double ha = a.leg[0].cross(a.leg[1]).dot(a.face);
  const double hb = b.leg[0].cross(b.leg[1]).dot(b.face);
  return std::abs(ha) > kSign && std::abs(hb) > kSign && ha * hb < 0;
}

// Conditions (4) and (5): the cones at most the slack wider than pi/2, the angles within the
// tolerance T of docs/certificates.md (the bound of the theorem with rounded hypotheses).
bool nearly_congruent(const Frame& a, const Frame& b, double s) {
  double x = 0;
  for (int k = 0; k < 2; ++k) x = std::max({x, -a.face.dot(a.other[k]), -b.face.dot(b.other[k])});
  x += 4 * kTilt + kRounding;
  if (!(x < s)) return false;
  const double ca = a.leg[0].dot(a.leg[1]), cb = b.leg[0].dot(b.leg[1]);
  const double e = s * std::sqrt(1 - x * x) - x * std::sqrt(1 - s * s);
  const double sigma = std::sqrt(std::max(0.0, 1 - std::max(ca * ca, cb * cb)));
  const double lo = std::min({ca, cb, 0.0});
  const double mu2 = std::min((1 - std::max(ca, cb)) / 2, 1 - lo * lo);
  const double t = 0.5 * s * e * sigma * mu2 * (1 - 1e-9);
  return std::abs(ca - cb) + kRounding < t;
}

}  // namespace

bool mirror_corners(const Polyhedron& A, const Polyhedron& B, const Pc& p, const Pc& q,
                    double slack) {
  if (p.type != PcType::kEE || q.type != PcType::kEE || !(slack > 0)) return false;
  const auto ca = corner(A, p.a, q.a);
  const auto cb = corner(B, p.b, q.b);
  if (!ca || !cb) return false;
  const Frame fa = frame(A, *ca), fb = frame(B, *cb);
  return perpendicular(fa) && perpendicular(fb) && shapes_hold(fa, fb) &&
         nearly_congruent(fa, fb, slack);
}

}  // namespace cf::gen

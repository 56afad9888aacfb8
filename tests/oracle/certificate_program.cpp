// Certificate checker: the `pieces` table (frames, convex pieces tiling each face, which sides
// really lie on the face's boundary and what margin they soundly carry) and the `program`
// leaves (every row rebuilt from the models, the node, the frames and pieces and the
// tolerances; the Farkas multipliers checked in exact rational arithmetic).
//
// Exact arithmetic: `Rational` (certificate_internal.hpp), exact on the double rows.

#include "certificate_internal.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>

namespace oracle::cert {

namespace {

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Signed distance of p from the line through a, b (positive on the left).
double line_dist(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 d = b - a;
  return cross2(d, p - a) / d.norm();
}

std::string face_name(char solid, int f) {
  return "face " + std::to_string(f) + " of " + std::string(1, solid);
}

// Covers [0, len] by intervals (each clipped); returns the largest uncovered gap.
double largest_gap(std::vector<std::pair<double, double>> iv, double len) {
  std::sort(iv.begin(), iv.end());
  double reach = 0, gap = 0;
  for (const auto& [a, b] : iv) {
    if (a > reach) gap = std::max(gap, a - reach);
    reach = std::max(reach, b);
    if (reach >= len) break;
  }
  return std::max(gap, len - reach);
}

// ---- one face's table ----

class FaceCheck {
 public:
  FaceCheck(const Poly& P, int f, char solid, const Tol& tol)
      : P_(P), F_(P.F[f]), name_(face_name(solid, f)), tol_(tol), tg_(kGross * tol.scale) {}

  FaceTable run(const json& entry, std::vector<std::string>& warnings);

 private:
  bool frame(const json& fr, FaceTable& T);
  bool parse_pieces(const json& ps, FaceTable& T);
  bool against_face(const FaceTable& T);
  bool boundary_sides(FaceTable& T, std::vector<std::string>& warnings);
  bool disjoint(const FaceTable& T);
  bool diagonals_matched(const FaceTable& T);
  bool area(const FaceTable& T);
  void margins(FaceTable& T) const;
  double side_margin(const Piece& p, std::size_t k, double m2) const;

  Vec2 mine(const FaceTable& T, const Vec2& uv) const {  // (u, v) -> the oracle's face 2D
    return F_.to2(T.offset * T.n + uv.x() * T.U + uv.y() * T.V);
  }
  double out_of_plane(const FaceTable& T, const Vec2& uv) const {
    const Vec3 x = T.offset * T.n + uv.x() * T.U + uv.y() * T.V;
    return std::abs(F_.n.dot(x) - F_.d);
  }
  bool fail(const std::string& why) {
    problem_ = name_ + ": " + why;
    return false;
  }

  const Poly& P_;
  const Face& F_;
  std::string name_;
  Tol tol_;
  double tg_;       // gross threshold: a piece off by more is not this face's
  double tau_ = 0;  // largest deviation measured (corners, sides, overlaps, matchings)
  std::string problem_;
};

bool FaceCheck::frame(const json& fr, FaceTable& T) {
  T.n = get_vec3(fr, "n");
  T.U = get_vec3(fr, "U");
  T.V = get_vec3(fr, "V");
  T.offset = fr.at("offset").get<double>();
  // Orthonormality defect: the reconstruction offset n + u U + v V of a point moves by at most
  // a few eta |x| when {n, U, V} is eta away from orthonormal.
  double eta =
      std::max({std::abs(T.n.squaredNorm() - 1), std::abs(T.U.squaredNorm() - 1),
                std::abs(T.V.squaredNorm() - 1), std::abs(T.U.dot(T.V)), std::abs(T.U.dot(T.n)),
                std::abs(T.V.dot(T.n)), (T.U.cross(T.V) - T.n).norm()});
  if (eta > kGross)
    return fail("frame is not orthonormal with U x V = n (defect " + fmt(eta) + ")");
  const double dn = (T.n - F_.n).norm();
  if (dn > kGross) return fail("frame normal differs from the face's outward normal by " + fmt(dn));
  // The frame's plane against the face's vertices: n.x - offset is affine, so its largest
  // value over the face (inside the hull of its vertices) is at a vertex.
  double e_plane = 0, cmax = std::abs(T.offset);
  for (int v : F_.verts) {
    e_plane = std::max(e_plane, std::abs(T.n.dot(P_.V[v].p) - T.offset));
    cmax = std::max(cmax, P_.V[v].p.norm() + std::abs(T.offset));
  }
  if (e_plane > tg_) return fail("frame offset is " + fmt(e_plane) + " mm off the face's plane");
  T.e_frame = e_plane + 4 * eta * cmax + kRelRound * cmax;
  return true;
}

bool FaceCheck::parse_pieces(const json& ps, FaceTable& T) {
  if (!ps.is_array() || ps.empty()) return fail("no pieces");
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const json& pj = ps[i];
    const json& pts = pj.at("points");
    const json& bd = pj.at("boundary");
    const std::string pn = "piece " + std::to_string(i);
    if (!pts.is_array() || pts.size() < 3) return fail(pn + " has fewer than 3 corners");
    if (!bd.is_array() || bd.size() != pts.size())
      return fail(pn + ": boundary has " + std::to_string(bd.size()) + " flags for " +
                  std::to_string(pts.size()) + " sides");
    std::vector<Vec2> q;
    for (const auto& p : pts) q.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
    Piece piece;
    piece.lo = piece.hi = q[0];
    const std::size_t n = q.size();
    for (std::size_t k = 0; k < n; ++k) {
      PieceSide s;
      s.q0 = q[k];
      s.q1 = q[(k + 1) % n];
      const Vec2 e = s.q1 - s.q0;
      if (!(e.norm() > 0)) return fail(pn + " has a side of zero length");
      s.o = Vec2(e.y(), -e.x()) / e.norm();
      s.claimed = bd[k].get<bool>();
      piece.lo = piece.lo.cwiseMin(q[k]);
      piece.hi = piece.hi.cwiseMax(q[k]);
      piece.area += cross2(s.q0, s.q1) / 2;
      // Convex and counter-clockwise: every turn to the left (a collinear corner, within
      // rounding, is allowed; its rows coincide).
      const Vec2 e2 = q[(k + 2) % n] - s.q1;
      if (cross2(e, e2) < -kRelRound * e.norm() * e2.norm() * 100)
        return fail(pn + " is not convex and counter-clockwise at corner " +
                    std::to_string((k + 1) % n));
      piece.sides.push_back(s);
    }
    if (!(piece.area > 0)) return fail(pn + " is not counter-clockwise (area <= 0)");
    T.pieces.push_back(piece);
  }
  return true;
}

// Every corner on or inside the face (within the measured deviation), no face vertex inside a
// piece, no piece side crossing the face's boundary: each convex piece lies in the face.
bool FaceCheck::against_face(const FaceTable& T) {
  for (std::size_t i = 0; i < T.pieces.size(); ++i) {
    const Piece& p = T.pieces[i];
    std::vector<Vec2> c;
    for (const auto& s : p.sides) {
      const Vec2 x = mine(T, s.q0);
      double dev = out_of_plane(T, s.q0);
      if (!inside_loops(F_.loops2, x)) dev += dist_to_loops(F_.loops2, x);
      if (dev > tg_)
        return fail("piece " + std::to_string(i) + " has a corner " + fmt(dev) +
                    " mm outside the face");
      tau_ = std::max(tau_, dev);
      c.push_back(x);
    }
    const std::size_t n = c.size();
    for (const auto& L : F_.loops2)
      for (std::size_t a = 0; a < L.size(); ++a) {
        const Vec2& w = L[a];
        const Vec2& w2 = L[(a + 1) % L.size()];
        double inward = kInf;
        for (std::size_t k = 0; k < n; ++k)
          inward = std::min(inward, line_dist(c[k], c[(k + 1) % n], w));
        if (inward > tg_)
          return fail("a vertex of the face lies inside piece " + std::to_string(i));
        for (std::size_t k = 0; k < n; ++k) {
          const Vec2 &s0 = c[k], &s1 = c[(k + 1) % n];
          const double d0 = line_dist(s0, s1, w), d1 = line_dist(s0, s1, w2);
          const double e0 = line_dist(w, w2, s0), e1 = line_dist(w, w2, s1);
          if (std::min(std::abs(d0), std::abs(d1)) > tg_ && d0 * d1 < 0 &&
              std::min(std::abs(e0), std::abs(e1)) > tg_ && e0 * e1 < 0)
            return fail("side " + std::to_string(k) + " of piece " + std::to_string(i) +
                        " crosses the face's boundary");
        }
      }
  }
  return true;
}

// A side lies on the face's boundary when boundary segments collinear with it (its two ends
// within tg of their line) cover it; its deviation is the largest distance of its ends from
// those lines (the distance to a line is convex along the side) plus any gap in the cover.
bool FaceCheck::boundary_sides(FaceTable& T, std::vector<std::string>& warnings) {
  for (std::size_t i = 0; i < T.pieces.size(); ++i)
    for (std::size_t k = 0; k < T.pieces[i].sides.size(); ++k) {
      PieceSide& s = T.pieces[i].sides[k];
      const Vec2 a = mine(T, s.q0), b = mine(T, s.q1);
      const double len = (b - a).norm();
      const Vec2 d = (b - a) / len;
      const double oop = std::max(out_of_plane(T, s.q0), out_of_plane(T, s.q1));
      std::vector<std::pair<double, double>> cover;
      double dev = 0;
      for (const auto& L : F_.loops2)
        for (std::size_t j = 0; j < L.size(); ++j) {
          const Vec2 &p = L[j], &q = L[(j + 1) % L.size()];
          const double da = std::abs(line_dist(p, q, a)), db = std::abs(line_dist(p, q, b));
          if (da > tg_ || db > tg_) continue;
          const double tp = (p - a).dot(d), tq = (q - a).dot(d);
          const double lo = std::max(0.0, std::min(tp, tq)), hi = std::min(len, std::max(tp, tq));
          if (hi <= lo) continue;
          cover.emplace_back(lo, hi);
          dev = std::max({dev, da, db});
        }
      const double gap = cover.empty() ? len : largest_gap(cover, len);
      s.boundary = gap <= tg_;
      if (s.boundary) tau_ = std::max(tau_, dev + gap + oop);
      if (s.boundary != s.claimed)
        warnings.push_back(name_ + ": piece " + std::to_string(i) + " side " + std::to_string(k) +
                           " is flagged " + (s.claimed ? "on" : "off") +
                           " the face's boundary but lies " + (s.boundary ? "on" : "off") +
                           " it; the checker uses its own decision");
    }
  return true;
}

// Pairwise interior-disjoint convex pieces (separating axes among the sides' normals): the
// overlap along the best axis is measured and must be within the gross threshold.
bool FaceCheck::disjoint(const FaceTable& T) {
  auto pen = [](const Piece& P, const Piece& Q) {
    double best = kInf;
    for (const auto& s : P.sides) {
      double qmin = kInf;
      for (const auto& t : Q.sides) qmin = std::min(qmin, s.o.dot(t.q0));
      best = std::min(best, std::max(0.0, s.o.dot(s.q0) - qmin));
    }
    return best;
  };
  for (std::size_t i = 0; i < T.pieces.size(); ++i)
    for (std::size_t j = i + 1; j < T.pieces.size(); ++j) {
      const double d = std::min(pen(T.pieces[i], T.pieces[j]), pen(T.pieces[j], T.pieces[i]));
      if (d > tg_)
        return fail("pieces " + std::to_string(i) + " and " + std::to_string(j) + " overlap (by " +
                    fmt(d) + " mm)");
      tau_ = std::max(tau_, d);
    }
  return true;
}

// Every side not on the face's boundary is covered by sides of other pieces running the other
// way along the same line: with the pieces inside the face and disjoint, no part of the face
// is left out except slivers as wide as the deviations measured.
bool FaceCheck::diagonals_matched(const FaceTable& T) {
  for (std::size_t i = 0; i < T.pieces.size(); ++i)
    for (std::size_t k = 0; k < T.pieces[i].sides.size(); ++k) {
      const PieceSide& s = T.pieces[i].sides[k];
      if (s.boundary) continue;
      const double len = (s.q1 - s.q0).norm();
      const Vec2 d = (s.q1 - s.q0) / len;
      std::vector<std::pair<double, double>> cover;
      double dev = 0;
      for (std::size_t j = 0; j < T.pieces.size(); ++j) {
        if (j == i) continue;
        for (const auto& t : T.pieces[j].sides) {
          if ((t.q1 - t.q0).dot(d) >= 0) continue;
          // The longer side's line is the accurate one.
          const bool mine_longer = len >= (t.q1 - t.q0).norm();
          const double e0 = mine_longer ? std::abs(line_dist(s.q0, s.q1, t.q0))
                                        : std::abs(line_dist(t.q0, t.q1, s.q0));
          const double e1 = mine_longer ? std::abs(line_dist(s.q0, s.q1, t.q1))
                                        : std::abs(line_dist(t.q0, t.q1, s.q1));
          if (e0 > tg_ || e1 > tg_) continue;
          const double ta = (t.q0 - s.q0).dot(d), tb = (t.q1 - s.q0).dot(d);
          const double lo = std::max(0.0, std::min(ta, tb)), hi = std::min(len, std::max(ta, tb));
          if (hi <= lo) continue;
          cover.emplace_back(lo, hi);
          dev = std::max({dev, e0, e1});
        }
      }
      const double gap = cover.empty() ? len : largest_gap(cover, len);
      if (gap > tg_)
        return fail("side " + std::to_string(k) + " of piece " + std::to_string(i) +
                    " is neither on the face's boundary nor shared with another piece");
      tau_ = std::max(tau_, dev + gap);
    }
  return true;
}

bool FaceCheck::area(const FaceTable& T) {
  double sum = 0, per = 0;
  for (const auto& p : T.pieces) {
    sum += p.area;
    for (const auto& s : p.sides) per += (s.q1 - s.q0).norm();
  }
  // Rounding of the two sums (1e-12 relative) plus the slivers the deviations allow.
  const double allowed = 1e-12 * F_.area + 4 * tau_ * per + kRelRound * F_.area;
  if (std::abs(sum - F_.area) > allowed)
    return fail("pieces' areas sum to " + fmt(sum) + " mm^2, the face's area is " + fmt(F_.area) +
                " mm^2");
  return true;
}

// The margin a boundary side soundly carries. A point x of the piece at distance >= m2 from
// the side's segment is at distance >= m2 from its line when it projects inside the segment.
// Beyond an end q, where the piece turns by phi (0 < phi < pi) to its next side: x lies in the
// piece's wedge at q, so with x = q + a e + b n_in (a > 0), b >= a tan(phi); then
// m2 <= |x - q| <= b / sin(phi), i.e. b >= m2 sin(phi). No point of the piece lies beyond q
// when phi >= pi/2, and when the next side is also on the boundary and at least m2 / sin(phi)
// long, x projects inside it at distance b cos(phi) - a sin(phi) < m2 from it unless b >= m2.
// Collinear boundary sides continue the segment (a chain). The spec's rows use m on every
// boundary side, which is not implied at a reflex corner of the face where a diagonal starts
// (see the README): the checker uses this margin instead.
double FaceCheck::side_margin(const Piece& p, std::size_t k, double m2) const {
  const std::size_t n = p.sides.size();
  auto dir = [&](std::size_t j) { return Vec2((p.sides[j].q1 - p.sides[j].q0).normalized()); };
  auto turn = [](const Vec2& from, const Vec2& to) {
    return std::atan2(cross2(from, to), from.dot(to));
  };
  constexpr double kCollinearTurn = 1e-9;  // rad: corners this flat continue the segment
  const PieceSide& s = p.sides[k];
  const Vec2 e = dir(k);
  double dev = 0, chain = (s.q1 - s.q0).norm();
  // The factor at one end of the chain of collinear boundary sides through side k.
  auto factor = [&](bool forward) {
    std::size_t j = k;
    for (std::size_t steps = 0; steps + 1 < n; ++steps) {
      const std::size_t nb = forward ? (j + 1) % n : (j + n - 1) % n;
      const PieceSide& t = p.sides[nb];
      const double phi = forward ? turn(dir(j), dir(nb)) : turn(dir(nb), dir(j));
      if (t.boundary && std::abs(phi) <= kCollinearTurn) {
        dev = std::max(
            {dev, std::abs(line_dist(s.q0, s.q1, t.q0)), std::abs(line_dist(s.q0, s.q1, t.q1))});
        chain += (t.q1 - t.q0).norm();
        j = nb;
        continue;
      }
      const double phi_e = forward ? turn(e, dir(nb)) : turn(dir(nb), e);
      if (phi_e >= kPi / 2) return 1.0;
      if (phi_e <= 0) return 0.0;  // the piece goes on straight (a diagonal) past this end
      const double sn = std::sin(phi_e);
      if (t.boundary && (t.q1 - t.q0).norm() >= m2 / sn) return 1.0;
      return sn;
    }
    return 0.0;  // not reached for a piece of positive area
  };
  const double g = std::min(factor(true), factor(false));
  dev += kCollinearTurn * (chain + 2 * m2);  // the chain's own bend, at most 1e-9 rad a corner
  return std::max(0.0, (m2 - dev) * g);
}

void FaceCheck::margins(FaceTable& T) const {
  // A deep point x* may lie up to rho outside every piece (slivers of the tiling, the frame's
  // reconstruction): its nearest point of a piece is then m - rho deep, and each side's own
  // deviation from the boundary (tau) takes that much more.
  const double m2 = tol_.margin - T.rho - tau_;
  for (auto& p : T.pieces)
    for (std::size_t k = 0; k < p.sides.size(); ++k)
      p.sides[k].mu = p.sides[k].boundary && m2 > 0 ? side_margin(p, k, m2) : 0.0;
}

FaceTable FaceCheck::run(const json& entry, std::vector<std::string>& warnings) {
  FaceTable T;
  try {
    bool ok = frame(entry.at("frame"), T) && parse_pieces(entry.at("pieces"), T) &&
              against_face(T) && boundary_sides(T, warnings) && disjoint(T) &&
              diagonals_matched(T) && area(T);
    if (ok) {
      // Every point at least m inside the face is within 2 tau of a piece (the slivers
      // between matched sides are at most tau wide on either side), and the frame moves it
      // by e_frame; a rounding floor keeps the allowance above the checker's own arithmetic.
      T.rho = 2 * tau_ + T.e_frame + kRelRound * tol_.scale;
      margins(T);
      T.ok = true;
    }
  } catch (const std::exception& e) {
    problem_ = name_ + ": malformed entry (" + e.what() + ")";
  }
  T.problem = problem_;
  return T;
}

}  // namespace

PieceTables check_piece_tables(const Graph& g, const Tol& tol, const json& pieces,
                               std::vector<std::string>& problems,
                               std::vector<std::string>& warnings) {
  PieceTables out;
  if (pieces.is_null()) return out;
  if (!pieces.is_object()) {
    problems.push_back("pieces is not an object");
    return out;
  }
  for (char solid : {'A', 'B'}) {
    const std::string key(1, solid);
    if (!pieces.contains(key)) continue;
    const Poly& P = solid == 'A' ? g.A : g.B;
    auto& tables = solid == 'A' ? out.A : out.B;
    for (const auto& entry : pieces.at(key)) {
      int f = -1;
      try {
        f = entry.at("face").get<int>();
      } catch (const std::exception&) {
      }
      if (f < 0 || f >= static_cast<int>(P.F.size())) {
        problems.push_back("pieces." + key + ": an entry names no face of " + key);
        continue;
      }
      if (tables.count(f)) {
        problems.push_back("pieces." + key + ": face " + std::to_string(f) + " listed twice");
        continue;
      }
      FaceTable T = FaceCheck(P, f, solid, tol).run(entry, warnings);
      if (!T.ok) problems.push_back("pieces: " + T.problem);
      tables[f] = std::move(T);
    }
  }
  return out;
}

// ---- programs ----

namespace {

// One row a.z <= b of a program, with what the checker needs to bound its own rounding.
struct Row {
  std::vector<double> a, amag;  // coefficients; bounds on the magnitudes they were computed from
  double b = 0, bmag = 0;       // right side; sum of |terms| it was computed from
  double extra = 0;             // deviations that are not arithmetic (frames, tiling slivers)
  bool has_w = false;           // carries W, hence the spec's rounding_mm
};

struct Program {
  std::vector<double> lo, hi;  // variable bounds
  std::vector<Row> rows;
  int add_var(double l, double h) {
    lo.push_back(l);
    hi.push_back(h);
    for (auto& r : rows) {
      r.a.push_back(0);
      r.amag.push_back(0);
    }
    return static_cast<int>(lo.size()) - 1;
  }
  Row row() const {
    Row r;
    r.a.assign(lo.size(), 0);
    r.amag.assign(lo.size(), 0);
    return r;
  }
};

// The image of A's contact point: z = cz + sum_k col_k var_k + t, widened by
// W + ws * var_is (an A edge's chord of beta in its parameter; otherwise ws = 0, is = -1).
struct Image {
  Vec3 cz;
  std::vector<std::pair<int, Vec3>> cols;
  double czmag = 0;    // |cz| as computed
  double e_frame = 0;  // A's face: reconstruction error of the contact point
  double W = 0;        // the widening at var_is = 0, with touch and rounding
  int is = -1;         // A's edge parameter, which the chord's slope multiplies
  double ws = 0;       // the chord's slope beta(x_1 - p) - beta(x_0 - p), as computed
  double wsmag = 0;    // beta(x_0 - p) + beta(x_1 - p): what ws was computed from
  double Wmax = 0;     // the largest widening over the parameter's [0, 1]
};

const FaceTable* table(const Ctx& ctx, char solid, int f, std::string* why) {
  const auto& tabs = solid == 'A' ? ctx.pieces.A : ctx.pieces.B;
  auto it = tabs.find(f);
  if (it == tabs.end()) {
    *why = "no pieces for face " + std::to_string(f) + " of " + std::string(1, solid);
    return nullptr;
  }
  if (!it->second.ok) {
    *why = "the pieces of face " + std::to_string(f) + " of " + std::string(1, solid) +
           " are not valid (" + it->second.problem + ")";
    return nullptr;
  }
  return &it->second;
}

// Edge parameter bounds [m/L, 1 - m/L], loosened by 1e-12 relative so that the double
// quotient never excludes the true bound.
std::pair<double, double> edge_bounds(double m, double len) {
  const double l = m / len * (1 - 1e-12);
  return {l, 1 - l};
}

// Rows of A's face piece: o_k.(u, v) <= o_k.q_k - mu_k, plus the tiling allowance.
void piece_rows(Program& P, const FaceTable& T, const Piece& pc, int iu) {
  for (const auto& s : pc.sides) {
    Row r = P.row();
    r.a[iu] = s.o.x();
    r.a[iu + 1] = s.o.y();
    r.amag[iu] = r.amag[iu + 1] = 1;
    r.b = s.o.dot(s.q0) - s.mu;
    r.bmag = std::abs(s.o.dot(s.q0)) + s.mu;
    r.extra = T.rho;
    P.rows.push_back(r);
  }
}

// n.z <= c + W written as a row (sign +1) or its negation (sign -1) applied to the image.
Row dot_row(const Program& P, const Image& im, const Vec3& n, double sign, double c, double cmag) {
  Row r = P.row();
  for (int j = 0; j < 3; ++j) {
    r.a[j] = sign * n[j];
    r.amag[j] = std::abs(n[j]);
  }
  for (const auto& [k, col] : im.cols) {
    r.a[k] += sign * n.dot(col);
    r.amag[k] += n.norm() * col.norm();
  }
  // The widening's s term on the left, times |a| = 1 (the spec's unit row vectors). Its
  // slope is one rounded subtraction of the two betas: off by at most an ulp of |ws|, which
  // kRelRound of wsmag times |s| <= 1 covers in widen().
  if (im.is >= 0) {
    r.a[im.is] -= im.ws;
    r.amag[im.is] += im.wsmag;
  }
  r.b = sign * (c - n.dot(im.cz)) + im.W;
  r.bmag = cmag + n.norm() * im.czmag + im.W;
  // The contact implies n.z <= n.y + |n| W(s): where the checker's n (a frame's, to its
  // defect) is longer than 1, the excess of |n| over the spec's 1 times the widening.
  r.extra = n.norm() * im.e_frame + std::max(0.0, n.norm() - 1) * im.Wmax;
  r.has_w = true;
  return r;
}

std::string build_rows(const Ctx& ctx, const std::vector<SetPc>& pcs, const Vec3& p,
                       const Turn& turn, const std::vector<int>& choice, Program& P) {
  const Poly &A = ctx.g.A, &B = ctx.g.B;
  const Tol& tol = ctx.tol;
  std::size_t next = 0;  // next index into choice
  std::string why;
  for (const SetPc& pc : pcs) {
    const int ka = kind_a(pc.type), kb = kind_b(pc.type);
    Image im;
    const FaceTable* TA = nullptr;
    const Piece* pa = nullptr;
    int iu = -1;
    if (ka == 0) {
      im.cz = turn.M * (A.V[pc.a].p - p);
    } else if (ka == 1) {
      const Edge& E = A.E[pc.a];
      const Vec3 x0 = A.V[E.v0].p, x1 = A.V[E.v1].p;
      im.cz = turn.M * (x0 - p);
      auto [l, h] = edge_bounds(tol.margin, E.len);
      im.is = P.add_var(l, h);
      im.cols.push_back({im.is, turn.M * (x1 - x0)});
    } else {
      if (!(TA = table(ctx, 'A', pc.a, &why))) return why;
      if (choice[next] < 0 || choice[next] >= static_cast<int>(TA->pieces.size()))
        return "choice names no piece of face " + std::to_string(pc.a) + " of A";
      pa = &TA->pieces[choice[next++]];
      // The piece's box, grown by the tiling allowance (a deep point may lie that far out).
      const double g = TA->rho + kRelRound * tol.scale;
      iu = P.add_var(pa->lo.x() - g, pa->hi.x() + g);
      P.add_var(pa->lo.y() - g, pa->hi.y() + g);
      im.cz = turn.M * (TA->offset * TA->n - p);
      im.cols.push_back({iu, turn.M * TA->U});
      im.cols.push_back({iu + 1, turn.M * TA->V});
      im.e_frame = TA->e_frame * (1 + 1e-9);
    }
    im.czmag = im.cz.norm();
    double wmax = 0;
    if (pa) {
      // The contact point lies in the chosen piece (its rows), up to the piece's box growth
      // and the tiling allowance: beta is convex, so its largest value there is at a corner,
      // plus how far that margin lets the point move.
      for (const PieceSide& sd : pa->sides) {
        const Vec3 corner = TA->offset * TA->n + sd.q0.x() * TA->U + sd.q0.y() * TA->V;
        wmax = std::max(wmax, turn.beta(corner - p));
      }
      wmax += turn.unit() * (TA->rho + kRelRound * tol.scale + TA->e_frame);
    } else if (ka == 1) {
      // The chord of beta between the edge's ends, W0 + s ws: beta is convex (a norm, or a
      // sum of norms of linear maps of x), so on the segment it lies below its chord; each
      // end's computed beta bounds the exact one (kRcErr), and s is in [0, 1].
      const Edge& E = A.E[pc.a];
      const double b0 = turn.beta(A.V[E.v0].p - p), b1 = turn.beta(A.V[E.v1].p - p);
      wmax = b0;
      im.ws = b1 - b0;
      im.wsmag = b0 + b1;
    } else {
      wmax = turn.beta(A.V[pc.a].p - p);
    }
    im.W = wmax + tol.touch + tol.rounding;
    im.Wmax = im.W + std::max(0.0, im.ws);
    if (pa) piece_rows(P, *TA, *pa, iu);
    if (kb == 0 || kb == 1) {
      Vec3 y0 = kb == 0 ? B.V[pc.b].p : B.V[B.E[pc.b].v0].p;
      int is = -1;
      Vec3 dy = Vec3::Zero();
      if (kb == 1) {
        dy = B.V[B.E[pc.b].v1].p - y0;
        auto [l, h] = edge_bounds(tol.margin, B.E[pc.b].len);
        is = P.add_var(l, h);
      }
      for (int j = 0; j < 3; ++j)
        for (double sign : {1.0, -1.0}) {
          Row r = dot_row(P, im, Vec3::Unit(j), sign, y0[j], std::abs(y0[j]));
          if (is >= 0) {
            r.a[is] = -sign * dy[j];
            r.amag[is] = std::abs(dy[j]);
          }
          P.rows.push_back(r);
        }
    } else {
      const FaceTable* TB = table(ctx, 'B', pc.b, &why);
      if (!TB) return why;
      if (choice[next] < 0 || choice[next] >= static_cast<int>(TB->pieces.size()))
        return "choice names no piece of face " + std::to_string(pc.b) + " of B";
      const Piece& pb = TB->pieces[choice[next++]];
      for (double sign : {1.0, -1.0}) {
        Row r = dot_row(P, im, TB->n, sign, TB->offset, std::abs(TB->offset));
        r.extra += TB->e_frame;
        P.rows.push_back(r);
      }
      for (const auto& s : pb.sides) {
        const Vec3 gk = s.o.x() * TB->U + s.o.y() * TB->V;
        Row r = dot_row(P, im, gk, 1.0, s.o.dot(s.q0) - s.mu, std::abs(s.o.dot(s.q0)) + s.mu);
        r.extra += TB->e_frame + TB->rho;
        P.rows.push_back(r);
      }
    }
  }
  return "";
}

// Widens each row by a bound on the checker's own error. The row the models imply is
// a_exact.z <= b_exact with W_exact = beta + touch (no rounding_mm; on an A edge W_exact is
// beta's chord, its s term in a_exact); the checker's double row differs by |da|.|z| + |db| <=
// kRelRound (sum amag_j max|z_j| + bmag), plus the deviations of frames and tiling.
// rounding_mm, which the spec adds to every row that carries W, covers that much of it; the
// rest (and all of it on rows without W) is added to b.
void widen(Program& P, double rounding) {
  for (auto& r : P.rows) {
    double err = r.bmag;
    for (std::size_t j = 0; j < r.a.size(); ++j)
      err += r.amag[j] * std::max(std::abs(P.lo[j]), std::abs(P.hi[j]));
    err = kRelRound * err + r.extra;
    r.b += r.has_w ? std::max(0.0, err - rounding) : err;
  }
}

// min over the box of (sum y_i a_i).z - sum y_i b_i, exactly.
Rational farkas_gap(const Program& P, const std::vector<double>& y) {
  const std::size_t nv = P.lo.size();
  std::vector<Rational> c(nv, Rational(0));
  Rational rhs(0);
  for (std::size_t i = 0; i < P.rows.size(); ++i) {
    if (y[i] == 0) continue;
    const Rational yi(y[i]);
    for (std::size_t j = 0; j < nv; ++j)
      if (P.rows[i].a[j] != 0) c[j] += yi * Rational(P.rows[i].a[j]);
    rhs += yi * Rational(P.rows[i].b);
  }
  Rational mn(0);
  for (std::size_t j = 0; j < nv; ++j) {
    if (c[j] > 0) mn += c[j] * Rational(P.lo[j]);
    if (c[j] < 0) mn += c[j] * Rational(P.hi[j]);
  }
  return mn - rhs;
}

// Farkas' lemma over the variables' box: y >= 0, one per row, and the least value of
// (sum y_i a_i).z over the box above sum y_i b_i, in exact rationals on the rows widened by
// the checker's error bounds. Returns "" when y proves P infeasible, else why not.
std::string check_multipliers(Program P, const std::vector<double>& y, double rounding) {
  if (y.size() != P.rows.size())
    return "y has " + std::to_string(y.size()) + " multipliers for " +
           std::to_string(P.rows.size()) + " rows";
  for (std::size_t i = 0; i < y.size(); ++i)
    if (!(y[i] >= 0) || !std::isfinite(y[i]))
      return "multiplier " + std::to_string(i) + " is " + fmt(y[i]) + " (must be >= 0)";
  widen(P, rounding);
  const Rational gap = farkas_gap(P, y);
  if (gap > 0) return "";
  return "Farkas gap " + fmt(to_double(gap)) +
         " <= 0 (min over the box of (sum y a).z does not exceed sum y b)";
}

std::string choice_text(const std::vector<int>& c) {
  std::string s = "[";
  for (std::size_t i = 0; i < c.size(); ++i) s += (i ? "," : "") + std::to_string(c[i]);
  return s + "]";
}

std::string check_choice(const Ctx& ctx, const std::vector<SetPc>& pcs, const Vec3& pivot,
                         const Turn& turn, const Vec3& lo, const Vec3& hi,
                         const std::vector<int>& choice, const std::vector<double>& y) {
  Program P;
  for (int j = 0; j < 3; ++j) P.add_var(lo[j], hi[j]);
  std::string why = build_rows(ctx, pcs, pivot, turn, choice, P);
  if (!why.empty()) return why;
  for (std::size_t j = 0; j < P.lo.size(); ++j)
    if (P.lo[j] > P.hi[j]) return "";  // an empty variable box: no solution whatever y says
  return check_multipliers(P, y, ctx.tol.rounding);
}

}  // namespace

std::string check_program(const Ctx& ctx, const std::vector<SetPc>& pcs, const Vec3& pivot,
                          const Turn& turn, const Vec3& lo, const Vec3& hi, const json& farkas) {
  // The faces whose pieces a choice picks, per PC: A's face, then B's face (docs: "a face of A
  // of an f-f, f-e, f-v, then a face of B of an f-f, e-f, v-f, in PC order").
  std::vector<int> counts;
  std::string why;
  for (const SetPc& pc : pcs) {
    if (kind_a(pc.type) == 2) {
      const FaceTable* T = table(ctx, 'A', pc.a, &why);
      if (!T) return why;
      counts.push_back(static_cast<int>(T->pieces.size()));
    }
    if (kind_b(pc.type) == 2) {
      const FaceTable* T = table(ctx, 'B', pc.b, &why);
      if (!T) return why;
      counts.push_back(static_cast<int>(T->pieces.size()));
    }
  }
  if (!farkas.is_array()) return "farkas is not an array";
  std::map<std::vector<int>, std::vector<double>> given;
  for (const auto& f : farkas) {
    auto c = f.at("choice").get<std::vector<int>>();
    if (c.size() != counts.size())
      return "choice " + choice_text(c) + " has " + std::to_string(c.size()) +
             " entries, the set uses " + std::to_string(counts.size()) + " faces";
    given[c] = f.at("y").get<std::vector<double>>();
  }
  std::vector<int> choice(counts.size(), 0);
  for (;;) {
    auto it = given.find(choice);
    if (it == given.end()) return "choice " + choice_text(choice) + " has no multipliers";
    why = check_choice(ctx, pcs, pivot, turn, lo, hi, choice, it->second);
    if (!why.empty()) return "choice " + choice_text(choice) + ": " + why;
    std::size_t k = 0;
    while (k < choice.size() && ++choice[k] == counts[k]) choice[k++] = 0;
    if (k == choice.size()) break;
  }
  return "";
}

// ---- first-order leaves (docs/certificates.md, "First-order leaves") ----

namespace {

// A cube node's rotations as R = R_c Q, Q a turn by theta <= theta_max about a unit axis w:
// with v = sin(theta) w, |v_k| <= rho, Q x = x + v x x + E(x) and |E(x)| <= gamma |x|. rho and
// gamma are taken upwards: a larger box and larger remainders only loosen the rows (tau, the
// only term that shrinks as they grow, is subtracted).
struct FirstOrder {
  Mat3 M = Mat3::Identity();  // R_c as the checker computes it (within kRcErr of the exact)
  double rho = 0, gamma = 0;
  double slack = 0;
};

// "at least (beta, alpha, r, tau)": the row -beta.v <= alpha + r - tau. `amag` bounds the
// magnitudes each coefficient was computed from and `alpha_mag` alpha's (the checker's own
// rounding, widen()); `extra` bounds how far the row's data (R_c^T y, the model's unit
// directions) move it over the box of v.
void at_least(Program& P, const Vec3& beta, double alpha, double r, double tau, double amag,
              double alpha_mag, double extra) {
  Row row = P.row();
  for (int j = 0; j < 3; ++j) {
    row.a[j] = -beta[j];
    row.amag[j] = amag;
  }
  row.b = alpha + r - tau;
  row.bmag = alpha_mag + r + std::abs(tau);
  row.extra = extra;
  P.rows.push_back(row);
}

// y' = M^T y is within kRcErr |y| of R_c^T y, so beta = x cross y' moves by kRcErr |x| |y|,
// which |v| <= sqrt(3) rho < 1.23 scales, and alpha = x . y' by as much: 3 kRcErr |x| |y|.
// kUnitEval covers the checker's unit directions (normalised, crossed), as in its other leaves.
double turned_extra(double xy) { return 3 * kRcErr * xy + kUnitEval; }

// "turned at least (x, y, tau)": (R x) . y >= tau.
void turned_at_least(Program& P, const FirstOrder& F, const Vec3& x, const Vec3& y, double tau) {
  const Vec3 yp = F.M.transpose() * y;
  const double xy = x.norm() * y.norm();
  at_least(P, x.cross(yp), x.dot(yp), F.gamma * xy, tau, 2 * xy, 2 * xy, turned_extra(xy));
}

// "turned within (x, y, eps)": |(R x) . y| <= eps, two rows.
void turned_within(Program& P, const FirstOrder& F, const Vec3& x, const Vec3& y, double eps) {
  const Vec3 yp = F.M.transpose() * y;
  const double xy = x.norm() * y.norm();
  const Vec3 beta = x.cross(yp);
  const double alpha = x.dot(yp), r = F.gamma * xy;
  at_least(P, beta, alpha, r, -eps, 2 * xy, 2 * xy, turned_extra(xy));
  at_least(P, -beta, -alpha, r, -eps, 2 * xy, 2 * xy, turned_extra(xy));
}

// The unit directions from vertex v along its edges, in ascending order of edge index.
std::vector<Vec3> edge_rays(const Poly& P, int v) {
  std::vector<int> es = P.V[v].edges;
  std::sort(es.begin(), es.end());
  std::vector<Vec3> d;
  for (int e : es) {
    const int o = P.E[e].v0 == v ? P.E[e].v1 : P.E[e].v0;
    d.push_back((P.V[o].p - P.V[v].p).normalized());
  }
  return d;
}

// An e-e's four rows for the sign sigma. w_1, w_2 are the into-face directions toward the
// edge's left then right face: the left face is the one whose loop runs the edge from
// edges[e][0] to edges[e][1] (`edge_info[].left`, schemas/model.schema.json), the checker's
// face[0], and m[0] points into it; m[1] into face[1], the right face.
// Data error: b', w' (unit, within kRcErr of R_c^T e_B, R_c^T w) enter B's coefficients at
// most four times and A's three, alpha twice and tau once (tau <= slack <= 1 per unit):
// 16 kRcErr bounds each row over the box (|v| < 1.23).
void ee_rows(Program& P, const FirstOrder& F, const Edge& ea, const Edge& eb, double sigma) {
  const Vec3 eA = ea.dir, bp = F.M.transpose() * eb.dir;
  const Vec3 m = eA.cross(bp);
  const double c = eA.dot(bp);
  const double tau = F.slack * std::max(0.0, m.norm() - F.rho - F.gamma);
  const double extra = 16 * kRcErr + kUnitEval;
  for (const Vec3& w : {eb.m[0], eb.m[1]}) {
    const Vec3 wp = F.M.transpose() * w;
    at_least(P, sigma * (c * wp - wp.dot(eA) * bp), -sigma * wp.dot(m), F.gamma, tau, 4, 2, extra);
  }
  const double g = F.gamma, rho = F.rho;
  const double rA = 2 * g + rho * rho + 2 * rho * g + g * g;
  for (const Vec3& w : {ea.m[0], ea.m[1]})
    at_least(P, sigma * (w.dot(eA) * bp - c * w + w.cross(m)), sigma * w.dot(m), rA, tau, 6, 2,
             extra);
}

// The rows of one choice of signs, PCs in order.
Program first_order_rows(const Ctx& ctx, const std::vector<SetPc>& pcs, const FirstOrder& F,
                         const std::vector<double>& signs) {
  const Poly &A = ctx.g.A, &B = ctx.g.B;
  const double s = F.slack;
  Program P;
  for (int j = 0; j < 3; ++j) P.add_var(-F.rho, F.rho);
  std::size_t next = 0;  // next sign
  for (const SetPc& pc : pcs) {
    switch (pc.type) {
      case PcType::VF:
        for (const Vec3& d : edge_rays(A, pc.a)) turned_at_least(P, F, d, B.F[pc.b].n, s);
        break;
      case PcType::FV:
        for (const Vec3& d : edge_rays(B, pc.b)) turned_at_least(P, F, A.F[pc.a].n, d, s);
        break;
      case PcType::EF: {
        const Edge& e = A.E[pc.a];
        const Vec3& n = B.F[pc.b].n;
        turned_at_least(P, F, e.m[0], n, s);
        turned_at_least(P, F, e.m[1], n, s);
        turned_within(P, F, e.dir, n, ctx.tol.rot);
        break;
      }
      case PcType::FE: {
        const Edge& e = B.E[pc.b];
        const Vec3& n = A.F[pc.a].n;
        turned_at_least(P, F, n, e.m[0], s);
        turned_at_least(P, F, n, e.m[1], s);
        turned_within(P, F, n, e.dir, ctx.tol.rot);
        break;
      }
      case PcType::EE:
        ee_rows(P, F, A.E[pc.a], B.E[pc.b], signs[next++]);
        break;
      default:  // f-f: no rows (fewer rows only make the claim harder to prove)
        break;
    }
  }
  return P;
}

std::string signs_text(const std::vector<double>& s) {
  std::string t = "[";
  for (std::size_t i = 0; i < s.size(); ++i) t += (i ? "," : "") + fmt(s[i]);
  return t + "]";
}

}  // namespace

std::string check_first_order(const Ctx& ctx, const std::vector<SetPc>& pcs, const Turn& turn,
                              const json& farkas) {
  if (turn.arc) return "a first-order leaf needs a cube of rotations (domain \"ball\"), not an arc";
  // theta_max = sqrt(3) h with the node's grown half-width, taken upwards.
  const double theta = std::sqrt(3.0) * turn.h * (1 + 1e-14);
  if (!(theta < kPi / 4)) return "theta_max = sqrt(3) h = " + fmt(theta) + " is not below pi/4";
  FirstOrder F;
  F.M = turn.M;
  F.rho = std::sin(theta) * (1 + 1e-14);
  const double hs = std::sin(theta / 2);
  F.gamma = 2 * hs * hs * (1 + 1e-14);  // 1 - cos(theta) without the cancellation
  F.slack = ctx.tol.slack;
  std::string ee_names;
  std::size_t k = 0;
  for (std::size_t i = 0; i < pcs.size(); ++i)
    if (pcs[i].type == PcType::EE) {
      ee_names +=
          std::string(k++ ? ", " : "") + "PC " + std::to_string(i) + " (" + pc_text(pcs[i]) + ")";
    }
  if (!farkas.is_array()) return "farkas is not an array";
  const std::size_t choices = std::size_t(1) << k;
  if (farkas.size() != choices)
    return "farkas has " + std::to_string(farkas.size()) + " entries, the set's " +
           std::to_string(k) + " e-e PCs make " + std::to_string(choices) + " choices of signs";
  for (std::size_t i = 0; i < choices; ++i) {
    std::vector<double> want(k);
    for (std::size_t j = 0; j < k; ++j) want[j] = (i >> j) & 1 ? -1.0 : 1.0;
    const json& f = farkas[i];
    const auto got = f.at("signs").get<std::vector<double>>();
    if (got != want)
      return "entry " + std::to_string(i) + ": signs " + signs_text(got) + ", expected " +
             signs_text(want) + " (one per e-e PC" + (k ? " [" + ee_names + "]" : "") +
             ", the first counting fastest, +1 first)";
    const std::string why =
        check_multipliers(first_order_rows(ctx, pcs, F, want), f.at("y").get<std::vector<double>>(),
                          ctx.tol.rounding);
    if (!why.empty()) return "signs " + signs_text(want) + ": " + why;
  }
  return "";
}

}  // namespace oracle::cert

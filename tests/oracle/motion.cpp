#include "motion.hpp"

#include <algorithm>
#include <cmath>

namespace oracle {

Pose apply_motion(const Pose& X0, const Motion& M, double lambda) {
  Pose X = X0;
  if (!M.rotation) {
    X.t = X0.t + lambda * M.u;
    return X;
  }
  Mat3 Q = Eigen::AngleAxisd(lambda, M.w).toRotationMatrix();
  X.R = Q * X0.R;
  X.t = M.c + Q * (X0.t - M.c);
  return X;
}

namespace {

bool in_closed_face(const Face& f, const Vec3& x, double tol) {
  Vec2 p = f.to2(x);
  return inside_loops(f.loops2, p) || dist_to_loops(f.loops2, p) <= tol;
}

double toi_translation(const Poly& A, const Poly& B, const Pose& X0, const Vec3& u, double lam_max,
                       double tol) {
  const double lam_min = 1e-9 * std::min(A.diag, B.diag);
  double best = lam_max;
  bool hit = false;
  std::vector<Vec3> pa(A.V.size());
  for (std::size_t i = 0; i < A.V.size(); ++i) pa[i] = X0.apply(A.V[i].p);
  // vertex of A -> face of B
  for (const Vec3& x : pa)
    for (const Face& f : B.F) {
      double nu = f.n.dot(u);
      if (nu > -1e-12) continue;
      double h = f.n.dot(x) - f.d;
      if (h < -tol) continue;
      if (h <= tol && nu < -1e-9 && in_closed_face(f, x, tol)) return 0;  // pushes into a contact
      double s = h / -nu;
      if (s <= lam_min || s >= best) continue;
      if (in_closed_face(f, x + s * u, tol)) {
        best = s;
        hit = true;
      }
    }
  // vertex of B -> face of A (in A's frame B moves by -R^T u)
  Vec3 ua = -(X0.R.transpose() * u);
  for (const Vertex& vb : B.V) {
    Vec3 y = X0.inv(vb.p);
    for (const Face& g : A.F) {
      double nu = g.n.dot(ua);
      if (nu > -1e-12) continue;
      double h = g.n.dot(y) - g.d;
      if (h < -tol) continue;
      if (h <= tol && nu < -1e-9 && in_closed_face(g, y, tol)) return 0;
      double s = h / -nu;
      if (s <= lam_min || s >= best) continue;
      if (in_closed_face(g, y + s * ua, tol)) {
        best = s;
        hit = true;
      }
    }
  }
  // edge - edge
  for (const Edge& ea : A.E) {
    const Vec3& a0 = pa[ea.v0];
    Vec3 dA = pa[ea.v1] - a0;
    for (const Edge& eb : B.E) {
      const Vec3& b0 = B.V[eb.v0].p;
      Vec3 dB = B.V[eb.v1].p - b0;
      Mat3 M;
      M.col(0) = dA;
      M.col(1) = -dB;
      M.col(2) = u;
      double det = M.determinant();
      if (std::abs(det) < 1e-12 * ea.len * eb.len) continue;
      Vec3 sol = M.inverse() * (b0 - a0);
      double s = sol.z();
      if (s <= lam_min || s >= best) continue;
      double ta = tol / ea.len, tb = tol / eb.len;
      if (sol.x() < -ta || sol.x() > 1 + ta || sol.y() < -tb || sol.y() > 1 + tb) continue;
      best = s;
      hit = true;
    }
  }
  return hit ? best : kInf;
}

// x(theta) = P0 + P1 cos + P2 sin for a point rotating about (c, w).
struct Circ {
  Vec3 P0, P1, P2;
  Vec3 at(double c, double s) const { return P0 + P1 * c + P2 * s; }
};
Circ circ(const Vec3& x, const Vec3& c, const Vec3& w) {
  Vec3 v = x - c;
  Circ r;
  r.P0 = c + w * w.dot(v);
  r.P1 = v - w * w.dot(v);
  r.P2 = w.cross(v);
  return r;
}

// Roots in (lo, hi) of A cos + B sin + C = 0 where the function decreases (or touches).
void trig_roots(double A, double B, double C, double lo, double hi, std::vector<double>* out) {
  double r = std::hypot(A, B);
  if (r <= 0 || std::abs(C) > r * (1 + 1e-12)) return;
  double phi = std::atan2(B, A);
  double del = std::acos(std::clamp(-C / r, -1.0, 1.0));
  for (double th : {phi - del, phi + del}) {
    for (int k = -2; k <= 2; ++k) {
      double t = th + 2 * kPi * k;
      if (t <= lo || t >= hi) continue;
      double der = -A * std::sin(t) + B * std::cos(t);
      if (der < 1e-9 * r || del < 1e-7) out->push_back(t);
    }
  }
}

double toi_rotation(const Poly& A, const Poly& B, const Pose& X0, const Vec3& c, const Vec3& w,
                    double lam_max, double tol) {
  const double scale = std::max(A.diag, B.diag);
  const double th_min = 1e-9;
  double best = lam_max;
  bool hit = false;
  std::vector<Circ> ca(A.V.size());
  for (std::size_t i = 0; i < A.V.size(); ++i) ca[i] = circ(X0.apply(A.V[i].p), c, w);
  std::vector<double> roots;
  // vertex of A -> face of B: h = n.(P0 + P1 cos + P2 sin) - d
  for (const Circ& x : ca)
    for (const Face& f : B.F) {
      double Ac = f.n.dot(x.P1), Bs = f.n.dot(x.P2), C = f.n.dot(x.P0) - f.d;
      if (std::hypot(Ac, Bs) < 1e-12 * scale) continue;
      if (std::abs(C + Ac) <= tol && Bs < -1e-9 * scale && in_closed_face(f, x.at(1, 0), tol))
        return 0;
      roots.clear();
      trig_roots(Ac, Bs, C, th_min, best, &roots);
      for (double t : roots)
        if (t < best && in_closed_face(f, x.at(std::cos(t), std::sin(t)), tol)) {
          best = t;
          hit = true;
        }
    }
  // vertex of B -> face of A: B's vertex turns by -theta relative to A.
  std::vector<Vec3> an(A.F.size());
  std::vector<double> ad(A.F.size());
  for (std::size_t i = 0; i < A.F.size(); ++i) {
    an[i] = X0.R * A.F[i].n;
    ad[i] = A.F[i].d + an[i].dot(X0.t);
  }
  for (const Vertex& vb : B.V) {
    Circ q = circ(vb.p, c, w);
    for (std::size_t g = 0; g < A.F.size(); ++g) {
      double Ac = an[g].dot(q.P1), Bs = -an[g].dot(q.P2), C = an[g].dot(q.P0) - ad[g];
      if (std::hypot(Ac, Bs) < 1e-12 * scale) continue;
      if (std::abs(C + Ac) <= tol && Bs < -1e-9 * scale &&
          in_closed_face(A.F[g], X0.inv(q.at(1, 0)), tol))
        return 0;
      roots.clear();
      trig_roots(Ac, Bs, C, th_min, best, &roots);
      for (double t : roots) {
        if (t >= best) continue;
        Vec3 qw = q.at(std::cos(t), -std::sin(t));
        if (in_closed_face(A.F[g], X0.inv(qw), tol)) {
          best = t;
          hit = true;
        }
      }
    }
  }
  // edge - edge: f = det[a1 - a0, b1 - b0, b0 - a0]
  const int N = 96;
  std::vector<double> cs(N + 1), sn(N + 1), th(N + 1);
  for (int k = 0; k <= N; ++k) {
    th[k] = k == 0 ? 10 * th_min : lam_max * k / N;
    cs[k] = std::cos(th[k]);
    sn[k] = std::sin(th[k]);
  }
  // axis-relative ranges for culling: radius and height of points about the axis
  auto rz = [&](const Vec3& x, double* rho, double* z) {
    Vec3 v = x - c;
    *z = w.dot(v);
    *rho = (v - w * *z).norm();
  };
  for (const Edge& ea : A.E) {
    const Circ& p = ca[ea.v0];
    const Circ& q = ca[ea.v1];
    double r0, z0, r1, z1;
    rz(p.at(1, 0), &r0, &z0);
    rz(q.at(1, 0), &r1, &z1);
    double zlo = std::min(z0, z1), zhi = std::max(z0, z1), rhi = std::max(r0, r1);
    for (const Edge& eb : B.E) {
      const Vec3& b0 = B.V[eb.v0].p;
      const Vec3& b1 = B.V[eb.v1].p;
      double s0, y0, s1, y1;
      rz(b0, &s0, &y0);
      rz(b1, &s1, &y1);
      if (std::max(y0, y1) < zlo - tol || std::min(y0, y1) > zhi + tol) continue;
      // smallest radius of the B edge about the axis vs the largest of the A edge
      {
        double sB;
        Vec3 dir = b1 - b0;
        // closest approach of segment b0b1 to the axis line
        Vec3 v0 = b0 - c;
        Vec3 dperp = dir - w * w.dot(dir), v0perp = v0 - w * w.dot(v0);
        double den = dperp.squaredNorm();
        sB = den > 0 ? std::clamp(-v0perp.dot(dperp) / den, 0.0, 1.0) : 0.0;
        double rmin = (v0perp + sB * dperp).norm();
        if (rmin > rhi + tol) continue;
      }
      Vec3 dB = b1 - b0;
      auto f = [&](double cc, double ss) {
        Vec3 a0 = p.at(cc, ss), a1 = q.at(cc, ss);
        return (a1 - a0).dot(dB.cross(b0 - a0));
      };
      double fprev = f(cs[0], sn[0]);
      double amp = std::abs(fprev);
      std::vector<double> fv(N + 1);
      fv[0] = fprev;
      for (int k = 1; k <= N; ++k) {
        fv[k] = f(cs[k], sn[k]);
        amp = std::max(amp, std::abs(fv[k]));
      }
      if (amp < 1e-12 * ea.len * eb.len * scale) continue;
      for (int k = 1; k <= N; ++k) {
        if (th[k - 1] >= best) break;
        if ((fv[k - 1] > 0) == (fv[k] > 0)) continue;
        double lo = th[k - 1], hi = th[k], flo = fv[k - 1];
        for (int it = 0; it < 80 && hi - lo > 1e-15; ++it) {
          double mid = 0.5 * (lo + hi);
          double fm = f(std::cos(mid), std::sin(mid));
          if ((fm > 0) == (flo > 0)) {
            lo = mid;
            flo = fm;
          } else {
            hi = mid;
          }
        }
        double t = hi;
        if (t <= th_min || t >= best) continue;
        Vec3 a0 = p.at(std::cos(t), std::sin(t)), a1 = q.at(std::cos(t), std::sin(t));
        double sa, sb;
        double d = seg_seg_dist(a0, a1, b0, b1, &sa, &sb);
        if (d <= 10 * tol + 1e-9 * scale) {
          best = t;
          hit = true;
          break;
        }
      }
    }
  }
  return hit ? best : kInf;
}

}  // namespace

double time_of_impact(const Poly& A, const Poly& B, const Pose& X0, const Motion& M, double lam_max,
                      double tol) {
  if (!M.rotation) return toi_translation(A, B, X0, M.u, lam_max, tol);
  return toi_rotation(A, B, X0, M.c, M.w, lam_max, tol);
}

}  // namespace oracle

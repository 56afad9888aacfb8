#include "sampler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace oracle {

std::string SamplerStats::str() const {
  std::ostringstream o;
  o << rounds << " rounds, " << poses << " poses: " << accepted << " accepted, " << penetrating
    << " penetrating, " << free << " free, " << uncertain << " near-degenerate, " << low_clearance
    << " low clearance, " << degenerate << " degenerate PC, " << too_many << " >3 PCs, "
    << same_plane << " shared plane; " << seconds << " s";
  return o.str();
}

Sampler::Sampler(const Classifier& C, SamplerOptions o)
    : C_(C), A_(C.A()), B_(C.B()), o_(o), rng_(o.seed) {
  for (std::size_t e = 0; e < A_.E.size(); ++e)
    if (A_.E[e].convex) convex_a_.push_back(static_cast<int>(e));
  for (std::size_t e = 0; e < B_.E.size(); ++e)
    if (B_.E[e].convex) convex_b_.push_back(static_cast<int>(e));
}

Vec3 Sampler::unit() {
  std::normal_distribution<double> N(0, 1);
  Vec3 v(N(rng_), N(rng_), N(rng_));
  return v.normalized();
}

static Vec3 point_in_face(const Face& f, std::mt19937_64& rng) {
  double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
  for (const Vec2& p : f.loops2[0]) {
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y());
    y1 = std::max(y1, p.y());
  }
  std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1);
  for (int i = 0; i < 200; ++i) {
    Vec2 p(ux(rng), uy(rng));
    if (inside_loops(f.loops2, p)) return f.to3(p);
  }
  return f.centroid;
}

Vec3 Sampler::point_on_b(int kind, int idx) {
  if (kind == 2) return point_in_face(B_.F[idx], rng_);
  if (kind == 1) {
    const Edge& e = B_.E[idx];
    return B_.V[e.v0].p + U(0.02, 0.98) * (B_.V[e.v1].p - B_.V[e.v0].p);
  }
  return B_.V[idx].p;
}

Vec3 Sampler::point_on_a(int kind, int idx) {
  if (kind == 2) return point_in_face(A_.F[idx], rng_);
  if (kind == 1) {
    const Edge& e = A_.E[idx];
    return A_.V[e.v0].p + U(0.02, 0.98) * (A_.V[e.v1].p - A_.V[e.v0].p);
  }
  return A_.V[idx].p;
}

Vec3 Sampler::outward_b(int kind, int idx) {
  if (kind == 2) return B_.F[idx].n;
  if (kind == 1) {
    const Edge& e = B_.E[idx];
    double a = U(0.1, 0.9);
    Vec3 v = (1 - a) * B_.F[e.face[0]].n + a * B_.F[e.face[1]].n;
    return v.norm() > 1e-9 ? v.normalized() : B_.F[e.face[0]].n;
  }
  Vec3 s = Vec3::Zero();
  for (const Corner& c : B_.V[idx].corners) s += B_.F[c.face].n * c.span;
  return s.norm() > 1e-9 ? s.normalized() : unit();
}

namespace {
Mat3 align(const Vec3& x, const Vec3& y) {
  return Eigen::Quaterniond::FromTwoVectors(x, y).toRotationMatrix();
}
Mat3 spin(const Vec3& k, double phi) { return Eigen::AngleAxisd(phi, k).toRotationMatrix(); }
Mat3 expmap(const Vec3& d) {
  double a = d.norm();
  if (a < 1e-300) return Mat3::Identity();
  return Eigen::AngleAxisd(a, d / a).toRotationMatrix();
}
}  // namespace

bool Sampler::orientation(Mat3* R, Target* T, std::string* fam) {
  const int nfa = static_cast<int>(A_.F.size()), nfb = static_cast<int>(B_.F.size());
  const int nea = static_cast<int>(A_.E.size()), neb = static_cast<int>(B_.E.size());
  double x = U(0, 1);
  if (x < 0.12) {
    *fam = "random";
    std::normal_distribution<double> N(0, 1);
    Eigen::Quaterniond q(N(rng_), N(rng_), N(rng_), N(rng_));
    *R = q.normalized().toRotationMatrix();
    double k = U(0, 1);
    T->kind_b = k < 0.5 ? 2 : k < 0.8 ? 1 : 0;
    T->b = I(0, (T->kind_b == 2 ? nfb : T->kind_b == 1 ? neb : static_cast<int>(B_.V.size())) - 1);
    k = U(0, 1);
    T->kind_a = k < 0.4 ? 0 : k < 0.75 ? 1 : 2;
    T->a = I(0, (T->kind_a == 2 ? nfa : T->kind_a == 1 ? nea : static_cast<int>(A_.V.size())) - 1);
    return true;
  }
  if (x < 0.35) {
    *fam = "f-f";
    int fa = I(0, nfa - 1), fb = I(0, nfb - 1);
    *R = spin(B_.F[fb].n, U(0, 2 * kPi)) * align(A_.F[fa].n, -B_.F[fb].n);
    *T = {2, fb, 2, fa};
    return true;
  }
  if (x < 0.5 && !convex_a_.empty()) {
    *fam = "e-f";
    int ea = convex_a_[I(0, static_cast<int>(convex_a_.size()) - 1)], fb = I(0, nfb - 1);
    const Edge& e = A_.E[ea];
    double a = U(0.02, 0.98);
    Vec3 m = ((1 - a) * A_.F[e.face[0]].n + a * A_.F[e.face[1]].n).normalized();
    *R = spin(B_.F[fb].n, U(0, 2 * kPi)) * align(m, -B_.F[fb].n);
    *T = {2, fb, 1, ea};
    return true;
  }
  if (x < 0.65 && !convex_b_.empty()) {
    *fam = "f-e";
    int eb = convex_b_[I(0, static_cast<int>(convex_b_.size()) - 1)], fa = I(0, nfa - 1);
    const Edge& e = B_.E[eb];
    double a = U(0.02, 0.98);
    Vec3 m = ((1 - a) * B_.F[e.face[0]].n + a * B_.F[e.face[1]].n).normalized();
    *R = spin(m, U(0, 2 * kPi)) * align(A_.F[fa].n, -m);
    *T = {1, eb, 2, fa};
    return true;
  }
  if (x < 0.82) {
    // f-f plus one more condition on the spin angle
    int fa = I(0, nfa - 1), fb = I(0, nfb - 1);
    const Vec3 k = B_.F[fb].n;
    Mat3 R0 = align(A_.F[fa].n, -k);
    for (int tries = 0; tries < 12; ++tries) {
      int c = I(0, 2);
      Vec3 xv, yv;
      double target = 0;
      Target t2;
      if (c == 0) {
        int fa2 = I(0, nfa - 1), fb2 = I(0, nfb - 1);
        if (fa2 == fa || fb2 == fb) continue;
        xv = R0 * A_.F[fa2].n;
        yv = B_.F[fb2].n;
        target = -1;
        t2 = {2, fb2, 2, fa2};
        *fam = "f-f+f-f";
      } else if (c == 1) {
        int ea2 = I(0, nea - 1), fb2 = I(0, nfb - 1);
        if (fb2 == fb) continue;
        xv = R0 * A_.E[ea2].dir;
        yv = B_.F[fb2].n;
        t2 = {2, fb2, 1, ea2};
        *fam = "f-f+e-f";
      } else {
        int fa2 = I(0, nfa - 1), eb2 = I(0, neb - 1);
        if (fa2 == fa) continue;
        xv = R0 * A_.F[fa2].n;
        yv = B_.E[eb2].dir;
        t2 = {1, eb2, 2, fa2};
        *fam = "f-f+f-e";
      }
      double kx = k.dot(xv), ky = k.dot(yv);
      double phi;
      if (c == 0) {
        // R x = -y: possible when k.x = -k.y; then the spin takes x's projection onto -y's
        // (exact; solving the trigonometric equation at its extremum would lose half the digits)
        if (std::abs(kx + ky) > 1e-12) continue;
        Vec3 px = xv - k * kx, py = -yv + k * ky;
        if (px.norm() < 1e-9 || py.norm() < 1e-9) continue;
        phi = std::atan2(k.dot(px.cross(py)), px.dot(py));
      } else {
        double a = xv.dot(yv) - kx * ky, b = k.cross(xv).dot(yv), rhs = target - kx * ky;
        double r = std::hypot(a, b);
        if (r < 1e-9 || std::abs(rhs) > r * (1 + 1e-12)) continue;
        phi = std::atan2(b, a) + (I(0, 1) ? 1 : -1) * std::acos(std::clamp(rhs / r, -1.0, 1.0));
      }
      *R = spin(k, phi) * R0;
      if (I(0, 1))
        *T = {2, fb, 2, fa};
      else
        *T = t2;
      return true;
    }
    return false;
  }
  // two or three conditions by Gauss-Newton on SO(3)
  int nc = I(2, 3);
  std::vector<Vec3> xs, ys;
  std::vector<Target> ts;
  std::string f = "gn";
  for (int i = 0; i < nc; ++i) {
    if (I(0, 1) == 0 || neb == 0) {
      int ea = I(0, nea - 1), fb = I(0, nfb - 1);
      xs.push_back(A_.E[ea].dir);
      ys.push_back(B_.F[fb].n);
      ts.push_back({2, fb, 1, ea});
      f += ":e-f";
    } else {
      int fa = I(0, nfa - 1), eb = I(0, neb - 1);
      xs.push_back(A_.F[fa].n);
      ys.push_back(B_.E[eb].dir);
      ts.push_back({1, eb, 2, fa});
      f += ":f-e";
    }
  }
  std::normal_distribution<double> N(0, 1);
  Eigen::Quaterniond q(N(rng_), N(rng_), N(rng_), N(rng_));
  Mat3 Rc = q.normalized().toRotationMatrix();
  for (int it = 0; it < 40; ++it) {
    Eigen::MatrixXd J(nc, 3);
    Eigen::VectorXd r(nc);
    for (int i = 0; i < nc; ++i) {
      Vec3 rx = Rc * xs[i];
      r(i) = rx.dot(ys[i]);
      J.row(i) = rx.cross(ys[i]).transpose();
    }
    if (r.cwiseAbs().maxCoeff() < 1e-15) break;
    Eigen::MatrixXd JJ = J * J.transpose() + 1e-12 * Eigen::MatrixXd::Identity(nc, nc);
    Vec3 d = -J.transpose() * JJ.ldlt().solve(r);
    Rc = expmap(d) * Rc;
  }
  for (int i = 0; i < nc; ++i)
    if (std::abs((Rc * xs[i]).dot(ys[i])) > 1e-12) return false;
  *R = Rc;
  *T = ts[I(0, nc - 1)];
  *fam = f;
  return true;
}

bool Sampler::approach(const Mat3& R, const Target& T, Pose* out) {
  Vec3 xb = point_on_b(T.kind_b, T.b);
  Vec3 ya = point_on_a(T.kind_a, T.a);
  Vec3 nout = outward_b(T.kind_b, T.b);
  Vec3 u = -(nout + U(0, 0.7) * unit()).normalized();
  bool far = U(0, 1) < 0.35;
  double delta = far ? 1.05 * (A_.diag + B_.diag) : std::exp(U(std::log(1e-3), 0.0)) * A_.diag;
  Pose X0;
  X0.R = R;
  X0.t = xb - delta * u - R * ya;
  Verdict V0 = C_.classify(X0, false);
  if (!V0.free()) return false;
  Motion M;
  M.u = u;
  double s = time_of_impact(A_, B_, X0, M, 1.5 * delta + A_.diag, C_.tol().len);
  if (!(s < kInf)) return false;
  *out = apply_motion(X0, M, s);
  return true;
}

Verdict Sampler::record(const Pose& X, const std::string& how) {
  Verdict V = C_.classify(X, true);
  ++st_.poses;
  if (V.penetrating) {
    ++st_.penetrating;
    return V;
  }
  if (V.free()) {
    ++st_.free;
    return V;
  }
  if (V.degenerate) {
    ++st_.degenerate;
    return V;
  }
  if (V.too_many) {
    ++st_.too_many;
    return V;
  }
  if (V.same_plane) {
    ++st_.same_plane;
    return V;
  }
  if (!V.uncertain.empty()) {
    ++st_.uncertain;
    return V;
  }
  if (V.clearance < C_.tol().gap) {
    ++st_.low_clearance;
    return V;
  }
  ++st_.accepted;
  if (o_.on_accept) o_.on_accept(X, V, how);
  CfKey k = V.key();
  auto it = found_.find(k);
  if (it == found_.end() || it->second.clearance < V.clearance)
    found_[k] = Sample{X, V.clearance, how};
  return V;
}

void Sampler::walk(Pose X, Verdict V, const std::string& fam) {
  std::string how = fam + ">approach";
  for (int step = 0; step < o_.max_walk; ++step) {
    // contact information of the current PCs (all touches if the PCs are degenerate)
    std::vector<Vec3> normals, pts, into_a;
    std::vector<std::pair<Vec3, Vec3>> lines;
    for (int i : V.pcs) {
      const Touch& t = V.touches[i];
      Vec3 n = t.normal;
      if (n.norm() < 0.5) continue;
      normals.push_back(n);
      pts.push_back(t.p0);
      if (t.type == PcType::EF || t.type == PcType::FE) {
        pts.push_back(t.p1);
        pts.push_back(0.5 * (t.p0 + t.p1));
        lines.emplace_back(t.p0, t.p1);
      }
      into_a.push_back(normal_into_a(B_, t));
    }
    if (normals.empty()) return;
    double pick = U(0, 1);
    Motion M;
    double lam_max;
    Pose start = X;
    std::string mv;
    if (pick < 0.35) {
      Eigen::MatrixXd Nm(normals.size(), 3);
      for (std::size_t i = 0; i < normals.size(); ++i) Nm.row(i) = normals[i].transpose();
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(Nm, Eigen::ComputeFullV);
      int rank = 0;
      for (int i = 0; i < svd.singularValues().size(); ++i)
        if (svd.singularValues()(i) > 1e-9) ++rank;
      if (rank >= 3) continue;
      Vec3 u = Vec3::Zero();
      std::normal_distribution<double> N(0, 1);
      for (int c = rank; c < 3; ++c) u += N(rng_) * svd.matrixV().col(c);
      if (u.norm() < 1e-12) continue;
      M.u = u.normalized();
      lam_max = 2 * (A_.diag + B_.diag);
      mv = "slide";
    } else if (pick < 0.8) {
      M.rotation = true;
      int opt = I(0, 3);
      const Vec3& c = pts[I(0, static_cast<int>(pts.size()) - 1)];
      M.c = c;
      if (opt == 0) {
        M.w = unit();
      } else if (opt == 1) {
        M.w = normals[I(0, static_cast<int>(normals.size()) - 1)];
      } else if (opt == 2 && pts.size() >= 2) {
        int i = I(0, static_cast<int>(pts.size()) - 1), j = I(0, static_cast<int>(pts.size()) - 1);
        if ((pts[j] - pts[i]).norm() < 1e-6 * A_.diag) continue;
        M.c = pts[i];
        M.w = (pts[j] - pts[i]).normalized();
      } else if (!lines.empty()) {
        const auto& l = lines[I(0, static_cast<int>(lines.size()) - 1)];
        if ((l.second - l.first).norm() < 1e-9) continue;
        M.c = l.first;
        M.w = (l.second - l.first).normalized();
      } else {
        M.w = normals[I(0, static_cast<int>(normals.size()) - 1)];
      }
      if (I(0, 1)) M.w = -M.w;
      lam_max = U(0.3, 1.0) * kPi;
      mv = "rotate";
    } else {
      Vec3 lift = Vec3::Zero();
      for (const Vec3& m : into_a) lift += m;
      lift = (lift.norm() > 1e-9 ? lift.normalized() : unit());
      Vec3 dir = (lift + U(0, 0.8) * unit()).normalized();
      if (dir.dot(lift) <= 0) continue;
      start.t = X.t + std::exp(U(std::log(1e-3), std::log(0.3))) * A_.diag * dir;
      Verdict V1 = C_.classify(start, false);
      if (!V1.free()) continue;
      M.u = -(lift + U(0, 0.9) * unit()).normalized();
      if (M.u.dot(lift) >= 0) continue;
      lam_max = A_.diag + B_.diag;
      mv = "hop";
    }
    double lam = time_of_impact(A_, B_, start, M, lam_max, C_.tol().len);
    if (!(lam < kInf) || lam <= 0) continue;  // nothing ahead, or the motion is blocked at once
    Pose Y = apply_motion(start, M, lam);
    Verdict W = record(Y, how + ">" + mv);
    if (W.penetrating || W.free() || W.pcs.empty()) continue;
    X = Y;
    V = W;
    how += ">" + mv;
  }
}

void Sampler::run() {
  using clk = std::chrono::steady_clock;
  auto t0 = clk::now();
  auto elapsed = [&]() { return std::chrono::duration<double>(clk::now() - t0).count(); };
  while (elapsed() < o_.budget_s && (o_.max_rounds <= 0 || st_.rounds < o_.max_rounds)) {
    ++st_.rounds;
    Mat3 R;
    Target T;
    std::string fam;
    if (!orientation(&R, &T, &fam)) continue;
    Pose X;
    bool ok = false;
    for (int k = 0; k < 4 && !ok; ++k) ok = approach(R, T, &X);
    if (!ok) continue;
    Verdict V = record(X, fam + ">approach");
    if (V.penetrating || V.free() || V.pcs.empty()) continue;
    walk(X, V, fam);
  }
  st_.seconds = elapsed();
}

}  // namespace oracle

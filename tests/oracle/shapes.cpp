#include "shapes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

namespace oracle {

// ---------------------------------------------------------------------------------------
// OFF, checks, counts
// ---------------------------------------------------------------------------------------

void write_off(const Mesh& m, const std::string& path) {
  std::ofstream o(path);
  if (!o) throw std::runtime_error("cannot write " + path);
  o << "OFF\n# " << m.name << "\n" << m.V.size() << " " << m.F.size() << " 0\n";
  char buf[128];
  for (const Vec3& v : m.V) {
    std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", v.x(), v.y(), v.z());
    o << buf;
  }
  for (const auto& f : m.F) {
    o << f.size();
    for (int i : f) o << " " << i;
    o << "\n";
  }
  if (!o) throw std::runtime_error("error writing " + path);
}

void write_stl_float32(const Mesh& m, const std::string& path) {
  std::vector<std::array<int, 3>> tris;
  for (const auto& f : m.F) {
    // The facet in its plane, in a frame (u, v) with u x v along its outward normal, so that
    // its counter-clockwise loop stays counter-clockwise.
    Vec3 n = Vec3::Zero();
    for (std::size_t k = 0; k < f.size(); ++k) n += m.V[f[k]].cross(m.V[f[(k + 1) % f.size()]]);
    n.normalize();
    const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
    std::vector<Vec2> loop;
    for (int i : f) loop.emplace_back(m.V[i].dot(u), m.V[i].dot(v));
    for (const auto& t : triangulate(loop, {})) tris.push_back({f[t[0]], f[t[1]], f[t[2]]});
  }
  std::ofstream o(path, std::ios::binary);
  if (!o) throw std::runtime_error("cannot write " + path);
  char header[80] = {};
  std::snprintf(header, sizeof header, "%s, float32, written by the test oracle", m.name.c_str());
  o.write(header, sizeof header);
  auto put_u32 = [&](std::uint32_t x) {
    const unsigned char b[4] = {static_cast<unsigned char>(x), static_cast<unsigned char>(x >> 8),
                                static_cast<unsigned char>(x >> 16),
                                static_cast<unsigned char>(x >> 24)};
    o.write(reinterpret_cast<const char*>(b), 4);
  };
  auto put_f32 = [&](double x) {
    const float f = static_cast<float>(x);
    std::uint32_t bits = 0;
    std::memcpy(&bits, &f, 4);
    put_u32(bits);
  };
  put_u32(static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) put_f32(0);
    for (int i : t)
      for (int k = 0; k < 3; ++k) put_f32(m.V[i][k]);
    o.write("\0\0", 2);
  }
  if (!o) throw std::runtime_error("error writing " + path);
}

Mesh read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<std::string> tok;
  std::string line;
  while (std::getline(in, line)) {
    auto h = line.find('#');
    if (h != std::string::npos) line = line.substr(0, h);
    std::istringstream ls(line);
    std::string t;
    while (ls >> t) tok.push_back(t);
  }
  std::size_t k = 0;
  auto next = [&]() -> const std::string& {
    if (k >= tok.size()) throw std::runtime_error(path + ": unexpected end of OFF");
    return tok[k++];
  };
  std::string head = next();
  if (head != "OFF") throw std::runtime_error(path + ": not an OFF file");
  int nv = std::stoi(next()), nf = std::stoi(next());
  next();
  Mesh m;
  m.name = path;
  for (int i = 0; i < nv; ++i) {
    double x = std::stod(next()), y = std::stod(next()), z = std::stod(next());
    m.V.emplace_back(x, y, z);
  }
  for (int i = 0; i < nf; ++i) {
    int c = std::stoi(next());
    std::vector<int> f;
    for (int j = 0; j < c; ++j) f.push_back(std::stoi(next()));
    m.F.push_back(f);
  }
  return m;
}

static Vec3 facet_area_vec(const Mesh& m, const std::vector<int>& f) {
  Vec3 a = Vec3::Zero();
  for (std::size_t i = 0; i < f.size(); ++i) a += m.V[f[i]].cross(m.V[f[(i + 1) % f.size()]]);
  return a / 2;
}

double mesh_volume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.F)
    for (std::size_t i = 1; i + 1 < f.size(); ++i)
      v += m.V[f[0]].dot(m.V[f[i]].cross(m.V[f[i + 1]]));
  return v / 6;
}

double mesh_area(const Mesh& m) {
  double a = 0;
  for (const auto& f : m.F) a += facet_area_vec(m, f).norm();
  return a;
}

static double mesh_diag(const Mesh& m) {
  Box3 b;
  for (const auto& v : m.V) b.add(v);
  return b.diag();
}

std::string check_mesh(const Mesh& m) {
  if (m.F.empty()) return "no facets";
  const double diag = mesh_diag(m);
  std::map<std::pair<int, int>, int> dir;  // directed edge -> count
  for (std::size_t fi = 0; fi < m.F.size(); ++fi) {
    const auto& f = m.F[fi];
    if (f.size() < 3) return "facet " + std::to_string(fi) + " has < 3 vertices";
    std::set<int> s(f.begin(), f.end());
    if (s.size() != f.size()) return "facet " + std::to_string(fi) + " repeats a vertex";
    Vec3 a = facet_area_vec(m, f);
    if (a.norm() <= 1e-12 * diag * diag) return "facet " + std::to_string(fi) + " has zero area";
    Vec3 n = a.normalized();
    for (int v : f)
      if (std::abs(n.dot(m.V[v] - m.V[f[0]])) > 1e-9 * diag)
        return "facet " + std::to_string(fi) + " is not planar";
    for (std::size_t i = 0; i < f.size(); ++i) {
      int p = f[i], q = f[(i + 1) % f.size()];
      if (++dir[{p, q}] > 1)
        return "edge " + std::to_string(p) + "-" + std::to_string(q) + " run twice the same way";
    }
  }
  for (const auto& [e, c] : dir) {
    (void)c;
    if (!dir.count({e.second, e.first}))
      return "open boundary at edge " + std::to_string(e.first) + "-" + std::to_string(e.second);
  }
  // every vertex used; the facets around each vertex form one fan
  std::vector<int> used(m.V.size(), 0);
  for (const auto& f : m.F)
    for (int v : f) used[v] = 1;
  for (std::size_t v = 0; v < m.V.size(); ++v)
    if (!used[v]) return "vertex " + std::to_string(v) + " unused";
  if (mesh_volume(m) <= 0) return "non-positive volume";
  // one fan per vertex: walk around the vertex over outgoing edges
  std::map<int, std::vector<std::pair<int, int>>> around;  // v -> (prev, next) per facet corner
  for (const auto& f : m.F)
    for (std::size_t i = 0; i < f.size(); ++i)
      around[f[i]].emplace_back(f[(i + f.size() - 1) % f.size()], f[(i + 1) % f.size()]);
  for (const auto& [v, corners] : around) {
    // corner (prev, next) at v; the facet across edge v->next has its corner with prev == next
    std::map<int, int> by_prev;
    for (const auto& c : corners)
      if (!by_prev.emplace(c.first, c.second).second)
        return "vertex " + std::to_string(v) + " is not manifold";
    int s0 = corners[0].first, cur = corners[0].second, steps = 1;
    while (cur != s0) {
      auto it = by_prev.find(cur);
      if (it == by_prev.end() || steps > static_cast<int>(corners.size()))
        return "vertex " + std::to_string(v) + " is not manifold";
      cur = it->second;
      ++steps;
    }
    if (steps != static_cast<int>(corners.size()))
      return "vertex " + std::to_string(v) + " joins separate fans";
  }
  return "";
}

namespace {
struct UF {
  std::vector<int> p;
  explicit UF(int n) : p(n) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) { return p[x] == x ? x : p[x] = find(p[x]); }
  void join(int a, int b) { p[find(a)] = find(b); }
};

std::vector<int> planar_face_ids(const Mesh& m) {
  const double diag = mesh_diag(m);
  const int nf = static_cast<int>(m.F.size());
  std::vector<Vec3> n(nf);
  for (int i = 0; i < nf; ++i) n[i] = facet_area_vec(m, m.F[i]).normalized();
  std::map<std::pair<int, int>, int> owner;
  for (int i = 0; i < nf; ++i) {
    const auto& f = m.F[i];
    for (std::size_t k = 0; k < f.size(); ++k) owner[{f[k], f[(k + 1) % f.size()]}] = i;
  }
  UF uf(nf);
  for (int i = 0; i < nf; ++i) {
    const auto& f = m.F[i];
    for (std::size_t k = 0; k < f.size(); ++k) {
      auto it = owner.find({f[(k + 1) % f.size()], f[k]});
      if (it == owner.end()) continue;
      int j = it->second;
      if (n[i].dot(n[j]) < 1 - 1e-9) continue;
      bool coplanar = true;
      for (int v : m.F[j])
        if (std::abs(n[i].dot(m.V[v] - m.V[f[0]])) > 1e-7 * diag) coplanar = false;
      if (coplanar) uf.join(i, j);
    }
  }
  std::vector<int> id(nf);
  for (int i = 0; i < nf; ++i) id[i] = uf.find(i);
  return id;
}
}  // namespace

int count_planar_faces(const Mesh& m) {
  auto id = planar_face_ids(m);
  return static_cast<int>(std::set<int>(id.begin(), id.end()).size());
}

int count_corner_vertices(const Mesh& m) {
  auto id = planar_face_ids(m);
  std::vector<std::set<int>> at(m.V.size());
  for (std::size_t i = 0; i < m.F.size(); ++i)
    for (int v : m.F[i]) at[v].insert(id[i]);
  int c = 0;
  for (const auto& s : at)
    if (s.size() >= 3) ++c;
  return c;
}

Mesh transform(const Mesh& m, const Pose& X) {
  Mesh r = m;
  for (auto& v : r.V) v = X.apply(v);
  return r;
}

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0, 1);
  Eigen::Quaterniond q(N(rng), N(rng), N(rng), N(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Pose random_rigid(std::mt19937_64& rng) {
  Pose X;
  X.R = random_rotation(rng);
  std::uniform_real_distribution<double> U(-40, 40);
  X.t = Vec3(U(rng), U(rng), U(rng));
  return X;
}

// ---------------------------------------------------------------------------------------
// Orthogonal solids from a grid of boxes: every facet is a grid rectangle, so two facets that
// share an edge share both its end points (no T-junctions).
// ---------------------------------------------------------------------------------------

static Mesh grid_mesh(const std::vector<double>& xs, const std::vector<double>& ys,
                      const std::vector<double>& zs, const std::function<bool(int, int, int)>& occ,
                      const std::string& name) {
  const int nx = static_cast<int>(xs.size()) - 1, ny = static_cast<int>(ys.size()) - 1,
            nz = static_cast<int>(zs.size()) - 1;
  auto in = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz && occ(i, j, k);
  };
  Mesh m;
  m.name = name;
  std::map<std::array<int, 3>, int> vid;
  auto V = [&](int i, int j, int k) {
    std::array<int, 3> key{i, j, k};
    auto it = vid.find(key);
    if (it != vid.end()) return it->second;
    int id = static_cast<int>(m.V.size());
    m.V.emplace_back(xs[i], ys[j], zs[k]);
    vid[key] = id;
    return id;
  };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        if (!in(i, j, k)) continue;
        if (!in(i + 1, j, k))
          m.F.push_back(
              {V(i + 1, j, k), V(i + 1, j + 1, k), V(i + 1, j + 1, k + 1), V(i + 1, j, k + 1)});
        if (!in(i - 1, j, k))
          m.F.push_back({V(i, j, k), V(i, j, k + 1), V(i, j + 1, k + 1), V(i, j + 1, k)});
        if (!in(i, j + 1, k))
          m.F.push_back(
              {V(i, j + 1, k), V(i, j + 1, k + 1), V(i + 1, j + 1, k + 1), V(i + 1, j + 1, k)});
        if (!in(i, j - 1, k))
          m.F.push_back({V(i, j, k), V(i + 1, j, k), V(i + 1, j, k + 1), V(i, j, k + 1)});
        if (!in(i, j, k + 1))
          m.F.push_back(
              {V(i, j, k + 1), V(i + 1, j, k + 1), V(i + 1, j + 1, k + 1), V(i, j + 1, k + 1)});
        if (!in(i, j, k - 1))
          m.F.push_back({V(i, j, k), V(i, j + 1, k), V(i + 1, j + 1, k), V(i + 1, j, k)});
      }
  return m;
}

Mesh make_box(double x, double y, double z) {
  return grid_mesh(
      {0, x}, {0, y}, {0, z}, [](int, int, int) { return true; }, "box");
}

Mesh make_l_section(double w, double h, double t1, double t2, double d) {
  return grid_mesh(
      {0, t2, w}, {0, t1, h}, {0, d}, [](int i, int j, int) { return j == 0 || i == 0; },
      "L-section");
}

Mesh make_u_channel(double g, double tw, double tb, double h, double d) {
  return grid_mesh(
      {0, tw, tw + g, 2 * tw + g}, {0, tb, h}, {0, d},
      [](int i, int j, int) { return j == 0 || i == 0 || i == 2; }, "U-channel");
}

Mesh make_t_section(double w, double tf, double tw, double h, double d) {
  double a = (w - tw) / 2;
  return grid_mesh(
      {0, a, a + tw, w}, {0, h - tf, h}, {0, d}, [](int i, int j, int) { return j == 1 || i == 1; },
      "T-section");
}

Mesh make_t_slot(double w, double h, double d, double nw, double nd, double hw, double hd) {
  double c1 = (w - nw) / 2, c2 = c1 + nw, d1 = (w - hw) / 2, d2 = d1 + hw;
  return grid_mesh(
      {0, d1, c1, c2, d2, w}, {0, h - nd - hd, h - nd, h}, {0, d},
      [](int i, int j, int) {
        if (j == 2 && i == 2) return false;
        if (j == 1 && i >= 1 && i <= 3) return false;
        return true;
      },
      "T-slot block");
}

Mesh make_corner_block(double w, double dd, double tf, double t1, double t2, double h) {
  return grid_mesh(
      {0, t2, w}, {0, t1, dd}, {0, tf, h},
      [](int i, int j, int k) { return k == 0 || j == 0 || i == 0; }, "corner block");
}

Mesh make_stairs(const std::vector<double>& runs, const std::vector<double>& rises, double d) {
  std::vector<double> xs{0}, ys{0};
  for (double r : runs) xs.push_back(xs.back() + r);
  for (double r : rises) ys.push_back(ys.back() + r);
  const int n = static_cast<int>(runs.size());
  return grid_mesh(
      xs, ys, {0, d}, [n](int i, int j, int) { return j < n - i; }, "stairs");
}

Mesh make_square_hole_block(double w, double h, double s, double ox, double oy) {
  double a = (w - s) / 2 + ox, b = (w - s) / 2 + oy;
  return grid_mesh(
      {0, a, a + s, w}, {0, b, b + s, w}, {0, h},
      [](int i, int j, int) { return !(i == 1 && j == 1); }, "square-hole block");
}

// ---------------------------------------------------------------------------------------
// Extrusions
// ---------------------------------------------------------------------------------------

namespace {
double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
double loop_area(const std::vector<Vec2>& L) {
  double a = 0;
  for (std::size_t i = 0; i < L.size(); ++i) a += cross2(L[i], L[(i + 1) % L.size()]);
  return a / 2;
}
bool convex_ccw(const std::vector<Vec2>& L) {
  for (std::size_t i = 0; i < L.size(); ++i) {
    const Vec2& a = L[i];
    const Vec2& b = L[(i + 1) % L.size()];
    const Vec2& c = L[(i + 2) % L.size()];
    if (cross2(b - a, c - b) <= 0) return false;
  }
  return true;
}
bool segs_cross_properly(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b) {
  double d1 = cross2(q - p, a - p), d2 = cross2(q - p, b - p), d3 = cross2(b - a, p - a),
         d4 = cross2(b - a, q - a);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}
bool point_in_tri(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
  double d1 = cross2(b - a, p - a), d2 = cross2(c - b, p - b), d3 = cross2(a - c, p - c);
  return d1 >= 0 && d2 >= 0 && d3 >= 0;
}
}  // namespace

std::vector<std::array<int, 3>> triangulate(const std::vector<Vec2>& outer,
                                            const std::vector<std::vector<Vec2>>& holes) {
  std::vector<Vec2> P = outer;
  std::vector<int> poly(outer.size());
  std::iota(poly.begin(), poly.end(), 0);
  std::vector<std::vector<int>> hl;
  for (const auto& h : holes) {
    std::vector<int> ids;
    for (const Vec2& p : h) {
      ids.push_back(static_cast<int>(P.size()));
      P.push_back(p);
    }
    hl.push_back(ids);
  }
  // bridge holes, rightmost first
  std::sort(hl.begin(), hl.end(), [&](const std::vector<int>& a, const std::vector<int>& b) {
    double ma = -kInf, mb = -kInf;
    for (int i : a) ma = std::max(ma, P[i].x());
    for (int i : b) mb = std::max(mb, P[i].x());
    return ma > mb;
  });
  for (std::size_t h = 0; h < hl.size(); ++h) {
    const auto& H = hl[h];
    int mi = 0;
    for (std::size_t i = 1; i < H.size(); ++i)
      if (P[H[i]].x() > P[H[mi]].x()) mi = static_cast<int>(i);
    const Vec2 M = P[H[mi]];
    // candidate vertices of the current polygon, nearest first
    std::vector<int> cand(poly.size());
    std::iota(cand.begin(), cand.end(), 0);
    std::sort(cand.begin(), cand.end(),
              [&](int a, int b) { return (P[poly[a]] - M).norm() < (P[poly[b]] - M).norm(); });
    int pick = -1;
    for (int ci : cand) {
      const Vec2 Q = P[poly[ci]];
      bool ok = true;
      auto test_loop = [&](const std::vector<int>& L) {
        for (std::size_t i = 0; i < L.size() && ok; ++i)
          if (segs_cross_properly(M, Q, P[L[i]], P[L[(i + 1) % L.size()]])) ok = false;
      };
      test_loop(poly);
      for (std::size_t g = h; g < hl.size(); ++g) test_loop(hl[g]);
      if (!ok) continue;
      // the bridge must leave Q into the polygon's interior: inside the corner at Q
      int prv = poly[(ci + poly.size() - 1) % poly.size()], nxt = poly[(ci + 1) % poly.size()];
      Vec2 a = P[prv] - Q, b = P[nxt] - Q, d = M - Q;
      // interior is to the left of the boundary: angle from b ccw to a contains d
      auto ang = [](const Vec2& x, const Vec2& y) {
        double t = std::atan2(cross2(x, y), x.dot(y));
        return t < 0 ? t + 2 * kPi : t;
      };
      double span = ang(b, a), at = ang(b, d);
      if (!(at > 1e-12 && at < span - 1e-12)) continue;
      pick = ci;
      break;
    }
    if (pick < 0) throw std::runtime_error("triangulate: no bridge for a hole");
    std::vector<int> np(poly.begin(), poly.begin() + pick + 1);
    for (std::size_t k = 0; k <= H.size(); ++k) np.push_back(H[(mi + k) % H.size()]);
    np.push_back(poly[pick]);
    np.insert(np.end(), poly.begin() + pick + 1, poly.end());
    poly.swap(np);
  }
  // ear clipping
  std::vector<std::array<int, 3>> tris;
  std::vector<int> cur = poly;
  int guard = 0;
  while (cur.size() > 3 && guard < 100000) {
    ++guard;
    bool cut = false;
    const std::size_t n = cur.size();
    for (std::size_t i = 0; i < n; ++i) {
      int a = cur[(i + n - 1) % n], b = cur[i], c = cur[(i + 1) % n];
      if (cross2(P[b] - P[a], P[c] - P[b]) <= 1e-14) continue;
      bool empty = true;
      for (std::size_t j = 0; j < n && empty; ++j) {
        int v = cur[j];
        if (v == a || v == b || v == c) continue;
        const Vec2& p = P[v];
        if ((p - P[a]).norm() < 1e-12 || (p - P[b]).norm() < 1e-12 || (p - P[c]).norm() < 1e-12)
          continue;
        if (point_in_tri(p, P[a], P[b], P[c])) empty = false;
      }
      if (!empty) continue;
      tris.push_back({a, b, c});
      cur.erase(cur.begin() + static_cast<long>(i));
      cut = true;
      break;
    }
    if (!cut) throw std::runtime_error("triangulate: no ear found");
  }
  if (cur.size() == 3) tris.push_back({cur[0], cur[1], cur[2]});
  // validate: areas add up
  double want = loop_area(outer);
  for (const auto& h : holes) want += loop_area(h);
  double got = 0;
  for (const auto& t : tris) {
    double a = cross2(P[t[1]] - P[t[0]], P[t[2]] - P[t[0]]) / 2;
    if (a <= 0) throw std::runtime_error("triangulate: inverted triangle");
    got += a;
  }
  if (std::abs(got - want) > 1e-9 * std::abs(want))
    throw std::runtime_error("triangulate: areas do not add up");
  return tris;
}

Mesh extrude(const std::vector<Vec2>& outer, const std::vector<std::vector<Vec2>>& holes,
             double d) {
  if (loop_area(outer) <= 0)
    throw std::runtime_error("extrude: outer loop must be counter-clockwise");
  for (const auto& h : holes)
    if (loop_area(h) >= 0) throw std::runtime_error("extrude: holes must be clockwise");
  Mesh m;
  std::vector<Vec2> all = outer;
  for (const auto& h : holes) all.insert(all.end(), h.begin(), h.end());
  const int n = static_cast<int>(all.size());
  for (const Vec2& p : all) m.V.emplace_back(p.x(), p.y(), 0.0);
  for (const Vec2& p : all) m.V.emplace_back(p.x(), p.y(), d);
  // sides
  int base = 0;
  auto sides = [&](int count) {
    for (int i = 0; i < count; ++i) {
      int a = base + i, b = base + (i + 1) % count;
      m.F.push_back({a, b, b + n, a + n});
    }
    base += count;
  };
  sides(static_cast<int>(outer.size()));
  for (const auto& h : holes) sides(static_cast<int>(h.size()));
  // caps
  if (holes.empty() && convex_ccw(outer)) {
    std::vector<int> top, bot;
    for (int i = 0; i < static_cast<int>(outer.size()); ++i) top.push_back(i + n);
    for (int i = static_cast<int>(outer.size()) - 1; i >= 0; --i) bot.push_back(i);
    m.F.push_back(top);
    m.F.push_back(bot);
  } else {
    for (const auto& t : triangulate(outer, holes)) {
      m.F.push_back({t[0] + n, t[1] + n, t[2] + n});
      m.F.push_back({t[2], t[1], t[0]});
    }
  }
  return m;
}

static std::vector<Vec2> ngon(int n, double r, double phase, const Vec2& c, bool ccw) {
  std::vector<Vec2> L;
  for (int i = 0; i < n; ++i) {
    double a = phase + 2 * kPi * i / n;
    L.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a));
  }
  if (!ccw) std::reverse(L.begin(), L.end());
  return L;
}

Mesh make_ngon_hole_block(double w, double h, int n, double r, double phase) {
  std::vector<Vec2> outer{{0, 0}, {w, 0}, {w, w}, {0, w}};
  Mesh m = extrude(outer, {ngon(n, r, phase, Vec2(w / 2, w / 2), false)}, h);
  m.name = std::to_string(n) + "-gon-hole block";
  return m;
}

Mesh make_ngon_prism(int n, double r, double l, double phase) {
  Mesh m = extrude(ngon(n, r, phase, Vec2(0, 0), true), {}, l);
  m.name = std::to_string(n) + "-gon prism";
  return m;
}

Mesh make_wedge(double a, double b, double c, double d) {
  Mesh m = extrude({{0, 0}, {a, 0}, {c, b}}, {}, d);
  m.name = "wedge";
  return m;
}

Mesh make_pyramid(double a, double b, double h, double ox, double oy) {
  Mesh m;
  m.name = "pyramid";
  m.V = {Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, b, 0), Vec3(0, b, 0),
         Vec3(a / 2 + ox, b / 2 + oy, h)};
  m.F = {{3, 2, 1, 0}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  return m;
}

Mesh make_ramp_step(double w1, double run, double w2, double h1, double h2, double g0, double gw,
                    double gd, double d) {
  const double W = w1 + run + w2;
  Mesh m = extrude({{0, 0},
                    {W, 0},
                    {W, h2},
                    {w1 + run, h2},
                    {w1, h1},
                    {g0 + gw, h1},
                    {g0 + gw / 2, h1 - gd},
                    {g0, h1},
                    {0, h1}},
                   {}, d);
  m.name = "ramp step";
  return m;
}

// ---------------------------------------------------------------------------------------
// Pairings
// ---------------------------------------------------------------------------------------

const char* pairing_name(int p) {
  static const char* names[kPairings] = {"n-gon peg in n-gon hole",
                                         "box in corner block",
                                         "prism in U-channel",
                                         "box on stairs",
                                         "cube in square hole",
                                         "L-part against U-channel",
                                         "box against T-section / T-slot",
                                         "wedge against L-section",
                                         "tiny A against big B",
                                         "box larger than the U pocket",
                                         "L-part against corner block / stairs",
                                         "box against L-section"};
  return names[((p % kPairings) + kPairings) % kPairings];
}

namespace {
struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t s) : g(s) {}
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
  double LU(double a, double b) { return std::exp(U(std::log(a), std::log(b))); }
  int I(int a, int b) { return std::uniform_int_distribution<int>(a, b)(g); }
};

std::string f1(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}

struct Made {
  Mesh m;
  std::string d;
};

Made box_r(Rng& r, double lo, double hi) {
  double x = r.U(lo, hi), y = r.U(lo, hi), z = r.U(lo, hi);
  return {make_box(x, y, z), "box " + f1(x) + "x" + f1(y) + "x" + f1(z)};
}
Made l_section_r(Rng& r, double lo, double hi) {
  double w = r.U(lo, hi), h = r.U(lo, hi), d = r.U(lo, hi);
  double t1 = r.U(0.1, 0.5) * h, t2 = r.U(0.1, 0.5) * w;
  return {make_l_section(w, h, t1, t2, d),
          "L-section " + f1(w) + "x" + f1(h) + "x" + f1(d) + " walls " + f1(t1) + "/" + f1(t2)};
}
Made l_part_r(Rng& r, double lo, double hi) {
  Made m = l_section_r(r, lo, hi);
  m.d = "L-part" + m.d.substr(9);
  m.m.name = "L-part";
  return m;
}
Made u_channel_r(Rng& r, double gap, double depth_over_floor) {
  double tw = r.U(0.1, 0.6) * gap, tb = r.U(0.1, 0.6) * gap, d = r.U(20, 60);
  double h = tb + depth_over_floor;
  return {make_u_channel(gap, tw, tb, h, d), "U-channel gap " + f1(gap) + " walls " + f1(tw) +
                                                 " base " + f1(tb) + " height " + f1(h) +
                                                 " length " + f1(d)};
}
Made corner_r(Rng& r) {
  double w = r.U(20, 60), dd = r.U(20, 60), m = std::min(w, dd);
  double tf = r.U(0.1, 0.35) * m, t1 = r.U(0.1, 0.35) * m, t2 = r.U(0.1, 0.35) * m,
         h = tf + r.U(8, 40);
  return {make_corner_block(w, dd, tf, t1, t2, h), "corner block " + f1(w) + "x" + f1(dd) +
                                                       " floor " + f1(tf) + " walls " + f1(t1) +
                                                       "/" + f1(t2) + " height " + f1(h)};
}
Made stairs_r(Rng& r) {
  int n = r.I(2, 3);
  std::vector<double> runs, rises;
  std::string s = "stairs " + std::to_string(n) + " steps (run x rise)";
  for (int i = 0; i < n; ++i) {
    runs.push_back(r.U(4, 20));
    rises.push_back(r.U(3, 15));
    s += " " + f1(runs.back()) + "x" + f1(rises.back());
  }
  double d = r.U(15, 50);
  return {make_stairs(runs, rises, d), s + " width " + f1(d)};
}
Made t_section_r(Rng& r) {
  double w = r.U(20, 60), h = r.U(15, 50), tf = r.U(0.1, 0.4) * h, tw = r.U(0.1, 0.4) * w,
         d = r.U(15, 50);
  return {make_t_section(w, tf, tw, h, d), "T-section " + f1(w) + "x" + f1(h) + " flange " +
                                               f1(tf) + " web " + f1(tw) + " length " + f1(d)};
}
Made ngon_prism_r(Rng& r, int n, double rad, double len) {
  return {make_ngon_prism(n, rad, len, r.U(0, 2 * kPi)),
          std::to_string(n) + "-gon prism r=" + f1(rad) + " L=" + f1(len)};
}
Made wedge_r(Rng& r, double lo, double hi) {
  double a = r.U(lo, hi), b = r.U(lo, hi), c = r.U(0, 1) * a, d = r.U(lo, hi);
  return {make_wedge(a, b, c, d),
          "wedge " + f1(a) + "x" + f1(b) + " apex " + f1(c) + " depth " + f1(d)};
}
Made ramp_step_r(Rng& r) {
  double w1 = r.U(15, 35), run = r.U(3, 15), w2 = r.U(10, 30), h1 = r.U(6, 15),
         h2 = h1 + r.U(3, 15), gw = r.U(0.3, 0.6) * w1, g0 = r.U(0.1, 0.9) * (w1 - gw),
         gd = std::min(r.U(0.2, 0.6) * gw, 0.7 * h1), d = r.U(20, 50);
  return {make_ramp_step(w1, run, w2, h1, h2, g0, gw, gd, d),
          "ramp step " + f1(w1) + "/" + f1(run) + "/" + f1(w2) + " heights " + f1(h1) + "/" +
              f1(h2) + " groove " + f1(gw) + "x" + f1(gd) + " at " + f1(g0) + " length " + f1(d)};
}
}  // namespace

ShapePair make_pair(std::uint64_t seed) {
  Rng r(seed);
  ShapePair P;
  P.pairing = static_cast<int>(seed % kPairings);
  Made a, b;
  switch (P.pairing) {
    case 0: {  // peg in hole
      int n = r.I(3, 8);
      double rp = r.U(4, 10), lp = r.U(8, 30), k = r.U(1.02, 1.2), rh = k * rp;
      double w = 2 * rh * r.U(1.15, 2.0), h = r.U(5, 30), ph = r.U(0, 2 * kPi);
      a = ngon_prism_r(r, n, rp, lp);
      b = {make_ngon_hole_block(w, h, n, rh, ph),
           "block " + f1(w) + "x" + f1(w) + "x" + f1(h) + " with " + std::to_string(n) +
               "-gon hole r=" + f1(rh) + " (+" + f1(100 * (k - 1)) + "%)"};
      break;
    }
    case 1:
      a = box_r(r, 5, 25);
      b = corner_r(r);
      break;
    case 2: {  // prism in U channel
      double gap;
      if (r.I(0, 1) == 0) {
        double x = r.U(5, 20), y = r.U(5, 20), z = r.U(10, 40);
        a = {make_box(x, y, z), "box " + f1(x) + "x" + f1(y) + "x" + f1(z)};
        gap = x * r.U(1.02, 1.2);
      } else {
        int n = r.I(3, 6);
        double rad = r.U(3, 10);
        a = ngon_prism_r(r, n, rad, r.U(10, 40));
        gap = 2 * rad * r.U(1.02, 1.2);
      }
      b = u_channel_r(r, gap, r.U(3, 25));
      break;
    }
    case 3:
      a = box_r(r, 5, 25);
      b = stairs_r(r);
      break;
    case 4: {
      double s = r.U(5, 20), k = r.U(1.02, 1.2), hole = s * k, wall = r.U(0.1, 0.6) * hole,
             h = r.U(5, 30);
      double w = hole + 2 * wall;
      a = {make_box(s, s, s), "cube " + f1(s)};
      double ox = r.U(-0.5, 0.5) * wall * 0.8, oy = r.U(-0.5, 0.5) * wall * 0.8;
      b = {make_square_hole_block(w, h, hole, ox, oy), "block " + f1(w) + "x" + f1(w) + "x" +
                                                           f1(h) + " square hole " + f1(hole) +
                                                           " (+" + f1(100 * (k - 1)) + "%)"};
      break;
    }
    case 5: {
      a = l_part_r(r, 6, 20);
      b = u_channel_r(r, r.U(5, 30), r.U(3, 25));
      break;
    }
    case 6: {
      double x = r.U(5, 20), y = r.U(5, 20), z = r.U(5, 20);
      a = {make_box(x, y, z), "box " + f1(x) + "x" + f1(y) + "x" + f1(z)};
      if (r.I(0, 1) == 0) {
        b = t_section_r(r);
      } else {
        double nw = x * r.U(1.02, 1.3), nd = r.U(2, 10), hw = nw + r.U(4, 20), hd = r.U(3, 15);
        double w = hw + 2 * r.U(3, 15), h = nd + hd + r.U(3, 15), d = r.U(20, 50);
        b = {make_t_slot(w, h, d, nw, nd, hw, hd), "T-slot block " + f1(w) + "x" + f1(h) + "x" +
                                                       f1(d) + " neck " + f1(nw) + "x" + f1(nd) +
                                                       " head " + f1(hw) + "x" + f1(hd)};
      }
      break;
    }
    case 7:
      a = wedge_r(r, 5, 25);
      b = l_section_r(r, 20, 60);
      break;
    case 8: {  // tiny A against big B
      int kind = r.I(0, 4);
      Made big = kind == 0   ? l_section_r(r, 30, 60)
                 : kind == 1 ? u_channel_r(r, r.U(10, 30), r.U(5, 25))
                 : kind == 2 ? corner_r(r)
                 : kind == 3 ? stairs_r(r)
                             : t_section_r(r);
      Box3 bb;
      for (const auto& v : big.m.V) bb.add(v);
      double s = bb.diag() * r.U(0.02, 0.1);
      int ak = r.I(0, 2);
      a = ak == 0   ? box_r(r, 0.5 * s, s)
          : ak == 1 ? wedge_r(r, 0.5 * s, s)
                    : ngon_prism_r(r, r.I(3, 6), 0.5 * s, s);
      a.d = "tiny " + a.d;
      b = big;
      break;
    }
    case 9: {  // A larger than the pocket
      double gap = r.U(5, 20);
      double x = gap * r.U(1.1, 2.0), y = r.U(5, 25), z = r.U(5, 25);
      a = {make_box(x, y, z),
           "box " + f1(x) + "x" + f1(y) + "x" + f1(z) + " (wider than the pocket)"};
      b = u_channel_r(r, gap, r.U(3, 25));
      break;
    }
    case 10:
      a = l_part_r(r, 6, 20);
      b = r.I(0, 1) == 0 ? corner_r(r) : stairs_r(r);
      break;
    case 11:
    default:
      a = box_r(r, 5, 25);
      b = l_section_r(r, 20, 60);
      break;
  }
  a.m.name = "A: " + a.d;
  b.m.name = "B: " + b.d;
  P.A = transform(a.m, random_rigid(r.g));
  P.B = transform(b.m, random_rigid(r.g));
  P.A.name = a.m.name;
  P.B.name = b.m.name;
  P.desc = std::string(pairing_name(P.pairing)) + ": " + a.d + " | " + b.d;
  return P;
}

const char* extra_pairing_name(int which) {
  static const char* names[kExtraPairings] = {
      "pyramid against ramp step", "wedge against ramp step", "n-gon prism against ramp step"};
  return names[((which % kExtraPairings) + kExtraPairings) % kExtraPairings];
}

ShapePair make_extra_pair(int which, std::uint64_t seed) {
  Rng r(seed);
  ShapePair P;
  which = ((which % kExtraPairings) + kExtraPairings) % kExtraPairings;
  P.pairing = -1 - which;
  Made a, b;
  switch (which) {
    case 0: {
      double x = r.U(6, 20), y = r.U(6, 20), h = r.U(5, 20), ox = r.U(-0.3, 0.3) * x,
             oy = r.U(-0.3, 0.3) * y;
      a = {make_pyramid(x, y, h, ox, oy), "pyramid " + f1(x) + "x" + f1(y) + " height " + f1(h) +
                                              " apex offset " + f1(ox) + "," + f1(oy)};
      break;
    }
    case 1:
      a = wedge_r(r, 5, 20);
      break;
    default:
      a = ngon_prism_r(r, r.I(3, 6), r.U(3, 8), r.U(8, 25));
      break;
  }
  b = ramp_step_r(r);
  a.m.name = "A: " + a.d;
  b.m.name = "B: " + b.d;
  P.A = transform(a.m, random_rigid(r.g));
  P.B = transform(b.m, random_rigid(r.g));
  P.A.name = a.m.name;
  P.B.name = b.m.name;
  P.desc = std::string(extra_pairing_name(which)) + ": " + a.d + " | " + b.d;
  return P;
}

bool PairArgs::take(const std::string& option, const std::function<std::string()>& value) {
  if (option == "--seed") {
    seed = std::stoull(value());
    have_seed = true;
    return true;
  }
  if (option != "--extra") return false;
  extra = std::stoi(value());
  if (extra < 0 || extra >= kExtraPairings) throw std::runtime_error("--extra out of range");
  return true;
}

void PairArgs::check() const {
  if (extra >= 0 && !have_seed) throw std::runtime_error("--extra needs --seed N");
}

}  // namespace oracle

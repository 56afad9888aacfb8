#include "cfgen/verify/analysis.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace cf::gen {

Mat3 align(const Vec3& x, const Vec3& y) {
  return Eigen::Quaterniond::FromTwoVectors(x, y).toRotationMatrix();
}

Mat3 axis_angle(const Vec3& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

namespace {

// Unit m maximising min_i m . r_i, by a small LP over m in the box [-1, 1]^3.
std::pair<Vec3, double> cone_center(const std::vector<Vec3>& rays) {
  LinearProgram lp(4);  // m (3), s
  for (int j = 0; j < 3; ++j) {
    lp.lower[j] = {true, -1.0};
    lp.upper[j] = {true, 1.0};
  }
  lp.upper[3] = {true, 2.0};
  lp.c[3] = -1.0;
  for (const Vec3& r : rays)
    lp.add({{0, r.x()}, {1, r.y()}, {2, r.z()}, {3, -1.0}}, LinearProgram::Rel::kGreaterEq, 0.0);
  const LpResult res = solve(lp);
  if (res.status != LpResult::Status::kOptimal || res.x.head<3>().norm() == 0)
    return {Vec3::Zero(), -1.0};
  const Vec3 m = res.x.head<3>().normalized();
  double margin = 2.0;
  for (const Vec3& r : rays) margin = std::min(margin, m.dot(r));
  return {m, margin};
}

double piece_area(const ConvexPiece& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    const auto& u = p.points[i];
    const auto& v = p.points[(i + 1) % p.points.size()];
    a += u.x() * v.y() - v.x() * u.y();
  }
  return 0.5 * a;
}

}  // namespace

bool point_inside(const Polyhedron& m, const Vec3& p, double boundary_tol) {
  // Fixed, irrational-looking directions keep the result deterministic.
  static const Vec3 kDirs[] = {Vec3(0.5773, 0.5812, 0.5735), Vec3(-0.3217, 0.8823, 0.3437),
                               Vec3(0.7071, -0.1237, 0.6962), Vec3(-0.2643, -0.5127, 0.8171),
                               Vec3(0.9123, 0.2957, -0.2831)};
  for (const Vec3& d0 : kDirs) {
    const Vec3 d = d0.normalized();
    int crossings = 0;
    bool ambiguous = false;
    for (std::size_t f = 0; f < m.num_faces() && !ambiguous; ++f) {
      const Face& F = m.faces()[f];
      const double dist = F.normal.dot(p) - F.offset;
      const double dn = F.normal.dot(d);
      if (std::abs(dist) <= boundary_tol) {
        // p on this face's plane: on the boundary if inside the face.
        if (m.face_inset(FaceId(static_cast<int>(f)), p) > -boundary_tol) return false;
        if (std::abs(dn) < 1e-9) continue;
        continue;  // leaving the plane immediately; no crossing
      }
      if (std::abs(dn) < 1e-12) continue;
      const double s = -dist / dn;
      if (s <= 0) continue;
      const double inset = m.face_inset(FaceId(static_cast<int>(f)), p + s * d);
      if (std::abs(inset) <= boundary_tol)
        ambiguous = true;
      else if (inset > 0)
        ++crossings;
    }
    if (!ambiguous) return crossings % 2 == 1;
  }
  return false;  // every direction grazed the boundary: p is on it for all practical purposes
}

void BoxIndex::SortedEnds::build(std::vector<double> sorted) {
  x = std::move(sorted);
  // About two buckets an end: most hold one end or none.
  buckets = std::max<int>(1, 2 * static_cast<int>(x.size()));
  origin = x.empty() ? 0.0 : x.front();
  const double span = x.empty() ? 0.0 : x.back() - x.front();
  per_mm = span > 0 && std::isfinite(span) ? buckets / span : 0.0;
  // Ends in ascending order fall in ascending buckets: bucket b holds the ends
  // [first[b], first[b + 1]), first[b] being the number of ends in the buckets before it.
  first.assign(static_cast<std::size_t>(buckets) + 1, 0);
  for (double e : x) ++first[static_cast<std::size_t>(bucket(e)) + 1];
  for (std::size_t b = 1; b < first.size(); ++b) first[b] += first[b - 1];
}

BoxIndex::BoxIndex(const std::vector<Vec3>& lo, const std::vector<Vec3>& hi)
    : n_(static_cast<int>(lo.size())), words_((n_ + 63) / 64) {
  const auto n = static_cast<std::size_t>(n_), w = static_cast<std::size_t>(words_);
  std::vector<int> order(n);
  for (int ax = 0; ax < 3; ++ax) {
    auto build = [&](const std::vector<Vec3>& end, SortedEnds& ends,
                     std::vector<std::uint64_t>& sets, bool prefix) {
      for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
      std::stable_sort(order.begin(), order.end(),
                       [&](int a, int b) { return end[a][ax] < end[b][ax]; });
      std::vector<double> sorted(n);
      for (std::size_t r = 0; r < n; ++r) sorted[r] = end[static_cast<std::size_t>(order[r])][ax];
      ends.build(std::move(sorted));
      sets.assign((n + 1) * w, 0);
      // prefix: set r holds order[0, r); suffix: set r holds order[r, n). Each set is the
      // one before it (prefix) or after it (suffix) and one element more.
      auto bit = [&](std::size_t r, int e) {
        sets[r * w + static_cast<std::size_t>(e / 64)] |= std::uint64_t{1} << (e % 64);
      };
      if (prefix) {
        for (std::size_t r = 1; r <= n; ++r) {
          std::copy_n(sets.begin() + static_cast<std::ptrdiff_t>((r - 1) * w), w,
                      sets.begin() + static_cast<std::ptrdiff_t>(r * w));
          bit(r, order[r - 1]);
        }
      } else {
        for (std::size_t r = n; r-- > 0;) {
          std::copy_n(sets.begin() + static_cast<std::ptrdiff_t>((r + 1) * w), w,
                      sets.begin() + static_cast<std::ptrdiff_t>(r * w));
          bit(r, order[r]);
        }
      }
    };
    build(lo, lo_sorted_[ax], lo_prefix_[ax], true);
    build(hi, hi_sorted_[ax], hi_suffix_[ax], false);
  }
}

void BoxIndex::query(const Vec3& q_lo, const Vec3& q_hi, std::uint64_t* out) const {
  const auto w = static_cast<std::size_t>(words_);
  for (std::size_t i = 0; i < w; ++i) out[i] = ~std::uint64_t{0};
  for (int ax = 0; ax < 3; ++ax) {
    // lower end <= q_hi: the first r of the lower ends; upper end >= q_lo: from r on.
    const std::size_t rl = lo_sorted_[ax].upper_bound(q_hi[ax]);
    const std::size_t rh = hi_sorted_[ax].lower_bound(q_lo[ax]);
    const std::uint64_t* pl = lo_prefix_[ax].data() + rl * w;
    const std::uint64_t* ph = hi_suffix_[ax].data() + rh * w;
    for (std::size_t i = 0; i < w; ++i) out[i] &= pl[i] & ph[i];
  }
}

namespace {

// A face's width: the extent of its outer loop across the direction of least spread (the
// least eigenvector of the loop's 2D scatter), which for a rectangle is its shorter side.
double face_width(const Face& f) {
  const auto& loop = f.loops_2d.front();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : loop) mean += p;
  mean /= static_cast<double>(loop.size());
  Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
  for (const auto& p : loop) S += (p - mean) * (p - mean).transpose();
  const Eigen::Vector2d d = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(S).eigenvectors().col(0);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : loop) lo = std::min(lo, p.dot(d)), hi = std::max(hi, p.dot(d));
  return hi - lo;
}

// ModelInfo::extent: each edge's length and each face's width.
void add_extents(const Polyhedron& m, ModelInfo& info) {
  for (const Edge& E : m.edges()) info.extent[1].push_back(E.length);
  for (const Face& F : m.faces()) info.extent[2].push_back(face_width(F));
}

// Each vertex's tangent cone: its edges' rays, their centre, whether it is pointed.
void add_cones(const Polyhedron& m, ModelInfo& info) {
  const double tol = 1e-9 * m.size();
  info.cones.resize(m.num_vertices());
  for (std::size_t v = 0; v < m.num_vertices(); ++v) {
    VertexCone& c = info.cones[v];
    const Vertex& V = m.vertices()[v];
    for (EdgeId e : V.edges) {
      const Edge& E = m.edge(e);
      c.rays.push_back(E.v0.index() == v ? E.dir : Vec3(-E.dir));
    }
    auto [center, margin] = cone_center(c.rays);
    c.center = center;
    c.center_margin = margin;
    bool pointed = margin > 1e-9;
    // A face with a reflex corner here puts opposite directions into the cone.
    for (FaceId f : V.faces) {
      const Face& F = m.face(f);
      for (std::size_t l = 0; l < F.loops.size() && pointed; ++l) {
        const auto& loop = F.loops[l];
        for (std::size_t k = 0; k < loop.size(); ++k) {
          if (loop[k].index() != v) continue;
          const auto& a = F.loops_2d[l][(k + loop.size() - 1) % loop.size()];
          const auto& b = F.loops_2d[l][k];
          const auto& c2 = F.loops_2d[l][(k + 1) % loop.size()];
          const double cr = (b - a).x() * (c2 - b).y() - (b - a).y() * (c2 - b).x();
          if (cr <= 0) pointed = false;
        }
      }
    }
    if (pointed) {
      // The rays fit in a half-space, but the solid may be the complement (an inner corner).
      double h = m.size();
      for (EdgeId e : V.edges) h = std::min(h, m.edge(e).length);
      pointed = !point_inside(m, V.p - 1e-3 * h * center, tol);
    }
    c.pointed = pointed;
  }
}

// Each edge's wedge: the directions into its two faces and their bisector.
void add_wedges(const Polyhedron& m, ModelInfo& info) {
  info.wedges.resize(m.num_edges());
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const Edge& E = m.edges()[e];
    const Vec3& nl = m.face(E.left).normal;
    const Vec3& nr = m.face(E.right).normal;
    EdgeWedge& w = info.wedges[e];
    w.into_left = nl.cross(E.dir).normalized();
    w.into_right = E.dir.cross(nr).normalized();
    const Vec3 bis = nl + nr;
    w.bisector = bis.norm() > 1e-12 ? bis.normalized() : Vec3::Zero();
  }
}

// Each face's convex pieces, largest first.
void add_pieces(const Polyhedron& m, ModelInfo& info) {
  info.pieces.resize(m.num_faces());
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    auto pieces = convex_partition(m.faces()[f].loops_2d);
    if (pieces.empty())
      throw Error("model '" + m.name() + "': face " + std::to_string(f) +
                  " could not be partitioned into convex pieces");
    std::stable_sort(pieces.begin(), pieces.end(), [](const ConvexPiece& a, const ConvexPiece& b) {
      return piece_area(a) > piece_area(b);
    });
    info.pieces[f] = std::move(pieces);
  }
}

// Bounding spheres and boxes of the elements (with their index) and the whole model's sphere.
void add_bounds(const Polyhedron& m, ModelInfo& info) {
  for (const Vertex& V : m.vertices()) info.spheres[0].push_back({V.p, 0.0});
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const Vec3 a = m.edge_point(EdgeId(static_cast<int>(e)), 0);
    const Vec3 b = m.edge_point(EdgeId(static_cast<int>(e)), 1);
    info.spheres[1].push_back({0.5 * (a + b), 0.5 * (b - a).norm()});
  }
  {
    std::vector<Vec3> lo, hi;
    auto add_box = [&](const std::vector<VertexId>& vs) {
      Vec3 l = m.vertex(vs[0]).p, h = l;
      for (VertexId v : vs) l = l.cwiseMin(m.vertex(v).p), h = h.cwiseMax(m.vertex(v).p);
      lo.push_back(l);
      hi.push_back(h);
    };
    for (std::size_t v = 0; v < m.num_vertices(); ++v) add_box({VertexId(static_cast<int>(v))});
    info.box_offset[1] = static_cast<int>(lo.size());
    for (const Edge& E : m.edges()) add_box({E.v0, E.v1});
    info.box_offset[2] = static_cast<int>(lo.size());
    for (const Face& F : m.faces()) add_box(F.vertices);
    info.boxes = BoxIndex(lo, hi);
    // A face's sphere is centred on its box.
    for (std::size_t f = 0; f < m.num_faces(); ++f) {
      const std::size_t i = static_cast<std::size_t>(info.box_offset[2]) + f;
      const Vec3 c = 0.5 * (lo[i] + hi[i]);
      double r = 0;
      for (VertexId v : m.faces()[f].vertices) r = std::max(r, (m.vertex(v).p - c).norm());
      info.spheres[2].push_back({c, r});
    }
  }
  {
    Vec3 lo = m.vertices()[0].p, hi = lo;
    for (const Vertex& V : m.vertices()) lo = lo.cwiseMin(V.p), hi = hi.cwiseMax(V.p);
    info.bound.first = 0.5 * (lo + hi);
    for (const Vertex& V : m.vertices())
      info.bound.second = std::max(info.bound.second, (V.p - info.bound.first).norm());
  }
}

// Each face's plane, shared by coplanar faces.
void add_face_planes(const Polyhedron& m, ModelInfo& info) {
  info.face_plane.assign(m.num_faces(), -1);
  int next = 0;
  const double ptol = 1e-7 * m.size();
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    if (info.face_plane[f] >= 0) continue;
    info.face_plane[f] = next;
    for (std::size_t g = f + 1; g < m.num_faces(); ++g) {
      const Face& F = m.faces()[f];
      const Face& G = m.faces()[g];
      if (F.normal.dot(G.normal) > 1 - 1e-12 && std::abs(F.offset - G.offset) < ptol)
        info.face_plane[g] = next;
    }
    ++next;
  }
}

}  // namespace

ModelInfo analyse_model(const Polyhedron& m, double precision_mm) {
  ModelInfo info;
  info.model = &m;
  info.precision_mm = precision_mm;
  add_extents(m, info);
  add_cones(m, info);
  add_wedges(m, info);
  add_pieces(m, info);
  add_bounds(m, info);
  add_face_planes(m, info);
  return info;
}

std::vector<Vec3> closure_points(const Polyhedron& m, ElementKind k, int i) {
  std::vector<Vec3> out;
  if (k == ElementKind::kVertex)
    out.push_back(m.vertices()[i].p);
  else if (k == ElementKind::kEdge) {
    out.push_back(m.edge_point(EdgeId(i), 0));
    out.push_back(m.edge_point(EdgeId(i), 1));
  } else
    for (VertexId v : m.faces()[i].vertices) out.push_back(m.vertex(v).p);
  return out;
}

std::vector<Vec3> inset_closure_points(const Polyhedron& m, ElementKind k, int i, double margin) {
  std::vector<Vec3> whole = closure_points(m, k, i);
  if (margin <= 0 || k == ElementKind::kVertex) return whole;
  if (k == ElementKind::kEdge) {
    const Edge& e = m.edges()[i];
    if (e.length <= 2 * margin) return whole;
    return {whole[0] + margin * e.dir, whole[1] - margin * e.dir};
  }
  const Face& f = m.faces()[i];
  if (f.loops.size() != 1) return whole;
  const std::vector<VertexId>& loop = f.loops[0];
  const std::size_t n = loop.size();
  std::vector<Vec3> p(n),
      into(n);  // corners; unit in-plane normals of side k (p[k] to p[k+1]), inwards
  for (std::size_t c = 0; c < n; ++c) p[c] = m.vertex(loop[c]).p;
  for (std::size_t c = 0; c < n; ++c) {
    const Vec3 d = p[(c + 1) % n] - p[c];
    if (d.norm() < 1e-12) return whole;
    into[c] = f.normal.cross(d).normalized();  // the loop turns counter-clockwise about the normal
  }
  std::vector<Vec3> out;
  for (std::size_t c = 0; c < n; ++c) {
    const Vec3 &w_in = into[(c + n - 1) % n], &w_out = into[c];
    const double turn = w_in.cross(w_out).dot(f.normal);
    if (turn < -1e-12) return whole;  // a reflex corner
    // The corner moved so that it is `margin` from both sides' lines: p + a w_in + b w_out
    // with (a w_in + b w_out) . w_in == (a w_in + b w_out) . w_out == margin.
    const double g = w_in.dot(w_out);
    if (1 - g < 1e-12) {
      out.push_back(p[c] + margin * w_in);  // a straight corner
      continue;
    }
    const double ab = margin / (1 + g);
    out.push_back(p[c] + ab * (w_in + w_out));
  }
  // Too small a face: the moved corners leave some side's strip.
  for (const Vec3& q : out)
    for (std::size_t c = 0; c < n; ++c)
      if ((q - p[c]).dot(into[c]) < margin * (1 - 1e-9)) return whole;
  return out;
}

std::vector<Vec3> closure_directions(const Polyhedron& m, ElementKind k, int i) {
  std::vector<Vec3> out;
  if (k == ElementKind::kEdge)
    out.push_back(m.edges()[i].dir);
  else if (k == ElementKind::kFace)
    for (EdgeId e : m.faces()[i].edges) out.push_back(m.edge(e).dir);
  return out;
}

}  // namespace cf::gen

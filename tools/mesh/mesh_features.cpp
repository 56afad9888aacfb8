// CGAL-free validation of a polygon soup and extraction of the features of docs/spec.md, section 3.
// The rules implemented here are documented in docs/features.md; keep the two in step.

#include "mesh_detail.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace cf::tools::detail {
namespace {

// A facet is degenerate when its smallest height (twice its area over its longest side) is
// below this fraction of the bounding-box diagonal: zero up to the rounding of coordinates
// that came through single precision (STL), which is about 6e-8 of the largest coordinate.
constexpr double kDegenerateRelTol = 1e-7;
// Feature vertices further than this many units of rounding (the machine epsilon times the
// largest coordinate) from the fitted plane of one of their faces are moved onto the planes'
// intersection: a file written with fewer digits than a double holds (float32 STL, 6-10
// digits) has faces planar only to its own precision, and an f-f contact between such faces
// would hold nowhere within the touch tolerance. Points on their planes to the arithmetic's
// rounding (exact or 17-digit input) are left untouched.
constexpr double kSnapRoundings = 64;

// mm: kSnapRoundings units of rounding of the points' largest coordinate.
double snap_tolerance(const std::vector<Vec3>& P) {
  double largest = 0;
  for (const Vec3& p : P) largest = std::max(largest, p.cwiseAbs().maxCoeff());
  return kSnapRoundings * std::numeric_limits<double>::epsilon() * largest;
}

std::string num(double x) {
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}

std::uint64_t key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

// Newell vector: twice the polygon's area vector (right-handed with the vertex order).
Vec3 newell(const std::vector<Vec3>& P, const std::vector<int>& poly) {
  Vec3 n = Vec3::Zero();
  for (std::size_t k = 0; k < poly.size(); ++k)
    n += P[poly[k]].cross(P[poly[(k + 1) % poly.size()]]);
  return n;
}

Vec3 mean_point(const std::vector<Vec3>& P, const std::vector<int>& poly) {
  Vec3 c = Vec3::Zero();
  for (int i : poly) c += P[i];
  return c / static_cast<double>(poly.size());
}

double diagonal(const PolygonSoup& s) {
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  for (const auto& poly : s.polygons)
    for (int i : poly) {
      lo = lo.cwiseMin(s.points[i]);
      hi = hi.cwiseMax(s.points[i]);
    }
  return (hi - lo).norm();
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Directed half-edges of a validated soup: key(a, b) -> (facet, corner index of a).
using HalfEdges = std::unordered_map<std::uint64_t, std::pair<int, int>>;

HalfEdges half_edges(const PolygonSoup& s) {
  HalfEdges he;
  he.reserve(s.polygons.size() * 4);
  for (int f = 0; f < static_cast<int>(s.polygons.size()); ++f) {
    const auto& poly = s.polygons[f];
    for (int k = 0; k < static_cast<int>(poly.size()); ++k)
      he.emplace(key(poly[k], poly[(k + 1) % poly.size()]), std::make_pair(f, k));
  }
  return he;
}

double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace

void fail(const std::string& source, const std::string& what) {
  throw Error("loading '" + source + "': " + what);
}

void check_soup(const PolygonSoup& s, const std::string& src, const LoadOptions& opt) {
  const auto& P = s.points;
  const auto& F = s.polygons;
  const int np = static_cast<int>(P.size());
  if (F.empty()) fail(src, "the file contains no facets");
  for (std::size_t f = 0; f < F.size(); ++f) {
    const std::string fs = "facet " + std::to_string(f);
    if (F[f].size() < 3)
      fail(src,
           "degenerate facet: " + fs + " has only " + std::to_string(F[f].size()) + " vertices");
    for (int i : F[f])
      if (i < 0 || i >= np)
        fail(src, "parse error: " + fs + " refers to vertex " + std::to_string(i) +
                      " but the file has " + std::to_string(np) + " vertices");
    std::vector<int> sorted = F[f];
    std::sort(sorted.begin(), sorted.end());
    const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
    if (dup != sorted.end())
      fail(src,
           "degenerate facet: " + fs + " uses vertex " + std::to_string(*dup) + " more than once");
    for (int i : F[f])
      if (!P[i].allFinite()) fail(src, "vertex " + std::to_string(i) + " is not finite");
  }

  // Edge manifoldness, open boundary and orientation, reported in that order of severity.
  std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> uses;  // forward: a < b
  for (int f = 0; f < static_cast<int>(F.size()); ++f)
    for (std::size_t k = 0; k < F[f].size(); ++k) {
      const int a = F[f][k], b = F[f][(k + 1) % F[f].size()];
      uses[{std::min(a, b), std::max(a, b)}].emplace_back(f, a < b);
    }
  auto edge_name = [](const std::pair<int, int>& e) {
    return "edge " + std::to_string(e.first) + "-" + std::to_string(e.second);
  };
  for (const auto& [e, u] : uses)
    if (u.size() > 2) {
      std::string fl;
      for (const auto& x : u) fl += (fl.empty() ? "" : ", ") + std::to_string(x.first);
      fail(src, "non-manifold edge: " + edge_name(e) + " is shared by " + std::to_string(u.size()) +
                    " facets (" + fl + ")");
    }
  for (const auto& [e, u] : uses)
    if (u.size() == 1)
      fail(src, "open boundary: " + edge_name(e) + " belongs to facet " +
                    std::to_string(u[0].first) + " only");
  for (const auto& [e, u] : uses)
    if (u[0].second == u[1].second) {
      const int a = u[0].second ? e.first : e.second;
      const int b = u[0].second ? e.second : e.first;
      fail(src, "inconsistent orientation: facets " + std::to_string(u[0].first) + " and " +
                    std::to_string(u[1].first) + " both run edge " + std::to_string(a) + "-" +
                    std::to_string(b) + " from " + std::to_string(a) + " to " + std::to_string(b));
    }

  // Vertex manifoldness: the facets around a vertex must form a single fan. Walk the fan
  // from one corner and compare with the number of corners at the vertex.
  const HalfEdges he = half_edges(s);
  std::vector<std::vector<std::pair<int, int>>> corners(np);
  for (int f = 0; f < static_cast<int>(F.size()); ++f)
    for (int k = 0; k < static_cast<int>(F[f].size()); ++k) corners[F[f][k]].emplace_back(f, k);
  for (int v = 0; v < np; ++v) {
    if (corners[v].empty()) continue;
    std::size_t walked = 0;
    auto [f, k] = corners[v][0];
    do {
      ++walked;
      const int next = F[f][(k + 1) % F[f].size()];  // facet f runs v -> next
      const auto [g, j] = he.at(key(next, v));       // its twin runs next -> v, v at j + 1
      f = g;
      k = static_cast<int>((j + 1) % F[g].size());
    } while (!(f == corners[v][0].first && k == corners[v][0].second) &&
             walked <= corners[v].size());
    if (walked != corners[v].size())
      fail(src, "non-manifold vertex: vertex " + std::to_string(v) +
                    " joins separate fans of facets (" + std::to_string(walked) + " of its " +
                    std::to_string(corners[v].size()) + " facets form one fan)");
  }

  const double diag = diagonal(s);
  if (!(diag > 0)) fail(src, "degenerate model: all vertices coincide");
  const double tol = opt.coplanar_rel_tol * diag;
  for (std::size_t f = 0; f < F.size(); ++f) {
    const Vec3 n2 = newell(P, F[f]);
    double longest = 0;
    for (std::size_t k = 0; k < F[f].size(); ++k)
      longest = std::max(longest, (P[F[f][k]] - P[F[f][(k + 1) % F[f].size()]]).norm());
    const double height = n2.norm() / longest;  // 2 area / longest side
    if (!(height > kDegenerateRelTol * diag))
      fail(src, "degenerate facet: facet " + std::to_string(f) + " is too thin: its height (" +
                    num(height) + " mm, twice its area " + num(0.5 * n2.norm()) +
                    " mm^2 over its longest side " + num(longest) + " mm) is below " +
                    num(kDegenerateRelTol * diag) + " mm (1e-7 of the model's diagonal)");
    if (F[f].size() > 3) {
      const Vec3 n = n2.normalized();
      const Vec3 c = mean_point(P, F[f]);
      for (int i : F[f]) {
        const double d = std::abs(n.dot(P[i] - c));
        if (d > tol)
          fail(src, "non-planar facet: vertex " + std::to_string(i) + " of facet " +
                        std::to_string(f) + " lies " + num(d) +
                        " mm off the facet's plane (tolerance " + num(tol) + " mm)");
      }
    }
  }

  UnionFind uf(F.size());
  for (const auto& [e, u] : uses) uf.unite(u[0].first, u[1].first);
  int solids = 0;
  for (std::size_t f = 0; f < F.size(); ++f)
    solids += uf.find(static_cast<int>(f)) == static_cast<int>(f);
  if (solids > 1)
    fail(src, "the file holds " + std::to_string(solids) +
                  " separate solids (facet groups not connected by edges); one solid is expected");

  double vol6 = 0;
  for (const auto& poly : F)
    for (std::size_t k = 1; k + 1 < poly.size(); ++k)
      vol6 += P[poly[0]].dot(P[poly[k]].cross(P[poly[k + 1]]));
  if (!(vol6 > 0))
    fail(src, "inward orientation: the enclosed volume is " + num(vol6 / 6) +
                  " mm^3; facet normals must point out of the solid (counter-clockwise seen "
                  "from outside)");
}

namespace {

// How closely a neighbouring facet must lie to a face's plane to join it, by tier (a facet's
// tier, extract_features: 0 at first, raised where the faces it forms fail). Tier 0: within
// coarse when its normal is within the crease angle of the face's (cos_crease: its cosine), or
// within fine whatever its normal; tier 1: within fine; tier 2: within exact (rounding).
struct JoinTolerances {
  double coarse = 0, fine = 0, exact = 0;  // mm
  double cos_crease = 1;
};

// The faces: maximal edge-connected regions of coplanar facets (docs/features.md), grown
// breadth first over shared edges. A neighbour facing the same way joins when all its vertices
// lie close enough to the region's current plane (area-weighted normal and centroid of the
// facets so far): JoinTolerances at the higher tier of it and the region's seed. Regions grow
// from the largest facets first: a thin facet's own normal is off by its corners' rounding over
// its height (a triangle of a file written at 6 digits), and a region started from it could
// refuse its coplanar neighbours. They are numbered by their lowest facet afterwards, the order
// of growing them in facet order.
struct FacetRegions {
  std::vector<int> region;  // of each facet
  std::vector<int> seed;    // of each region, its lowest facet
};

FacetRegions grow_faces(const PolygonSoup& s, const HalfEdges& he, const std::vector<Vec3>& area2,
                        const std::vector<Vec3>& centre, const JoinTolerances& tol,
                        const std::vector<char>& tier) {
  const auto& P = s.points;
  const auto& F = s.polygons;
  const int nf = static_cast<int>(F.size());
  std::vector<int> by_area(nf);
  for (int f = 0; f < nf; ++f) by_area[f] = f;
  std::stable_sort(by_area.begin(), by_area.end(),
                   [&](int a, int b) { return area2[a].norm() > area2[b].norm(); });
  FacetRegions out;
  std::vector<int>& region = out.region;
  region.assign(nf, -1);
  int nr = 0;
  for (int s0 : by_area) {
    if (region[s0] >= 0) continue;
    const int r = nr++;
    region[s0] = r;
    Vec3 N = area2[s0];
    Vec3 C = area2[s0].norm() * centre[s0];
    double W = area2[s0].norm();
    std::vector<int> queue{s0};
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
      const int f = queue[qi];
      for (int k = 0; k < static_cast<int>(F[f].size()); ++k) {
        const int g = he.at(key(F[f][(k + 1) % F[f].size()], F[f][k])).first;
        if (region[g] >= 0) continue;
        const Vec3 n = N.normalized();
        const Vec3 c = C / W;
        if (!(n.dot(area2[g]) > 0)) continue;
        double off = 0;  // how far g's corners are from the region's plane
        for (int i : F[g]) off = std::max(off, std::abs(n.dot(P[i] - c)));
        const int level = std::max(tier[s0], tier[g]);
        const bool joins = level == 2        ? off <= tol.exact
                           : off <= tol.fine ? true
                                             : level == 0 && off <= tol.coarse &&
                                                   n.dot(area2[g].normalized()) >= tol.cos_crease;
        if (!joins) continue;
        region[g] = r;
        N += area2[g];
        C += area2[g].norm() * centre[g];
        W += area2[g].norm();
        queue.push_back(g);
      }
    }
  }
  std::vector<int> lowest(nr, nf), order(nr), renumber(nr);
  for (int f = 0; f < nf; ++f) lowest[region[f]] = std::min(lowest[region[f]], f);
  for (int r = 0; r < nr; ++r) order[r] = r;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lowest[a] < lowest[b]; });
  out.seed.resize(nr);
  for (int r = 0; r < nr; ++r) renumber[order[r]] = r, out.seed[r] = lowest[order[r]];
  for (int& r : region) r = renumber[r];
  return out;
}

// The least-squares plane n . x = d through the points P[i], i in `idx` (the smallest
// eigenvector of their covariance), with n turned to the side of `side`.
void fit_plane(const std::vector<Vec3>& P, const std::vector<int>& idx, const Vec3& side, Vec3& n,
               double& d) {
  Vec3 c = Vec3::Zero();
  for (int i : idx) c += P[static_cast<std::size_t>(i)];
  c /= static_cast<double>(idx.size());
  Mat3 cov = Mat3::Zero();
  for (int i : idx) {
    const Vec3 q = P[static_cast<std::size_t>(i)] - c;
    cov += q * q.transpose();
  }
  n = Eigen::SelfAdjointEigenSolver<Mat3>(cov).eigenvectors().col(0);  // smallest first
  if (n.dot(side) < 0) n = -n;
  d = n.dot(c);
}

// Moves p onto the planes of `faces` when it is further than `tol` from one of them: the
// least move, in least squares where the planes meet in no one point. Returns how far p was.
double snap_onto_planes(Vec3& p, const std::vector<int>& faces, const std::vector<Vec3>& n,
                        const std::vector<double>& d, double tol) {
  double dev = 0;
  Eigen::MatrixXd A(faces.size(), 3);
  Eigen::VectorXd res(faces.size());
  for (std::size_t q = 0; q < faces.size(); ++q) {
    A.row(static_cast<Eigen::Index>(q)) = n[faces[q]].transpose();
    res[static_cast<Eigen::Index>(q)] = d[faces[q]] - n[faces[q]].dot(p);
    dev = std::max(dev, std::abs(res[static_cast<Eigen::Index>(q)]));
  }
  if (dev > tol) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    svd.setThreshold(1e-6);
    p += Vec3(svd.solve(res));
  }
  return dev;
}

// Rounds of planarize: each takes every vertex closer to its faces' planes by a factor (the
// alternating least squares of planar polygon meshes converge linearly).
constexpr int kPlanarizeRounds = 200;
// A round that does not bring the worst vertex this much closer ends them (a model whose
// merged faces no planes fit converges no further, and a large one would pay every round).
constexpr double kPlanarizeStall = 0.9;

// A vertex on four or more faces merged from facets off one plane (a coarse --coplanar-tol)
// is on no one point of their planes: the planes are refitted through their corners and the
// corners moved onto them again, until every corner is within `tol` of its faces' planes or
// kPlanarizeRounds have passed (the polyhedron's own check then says how far one is off).
void planarize(std::vector<Vec3>& coords, const std::vector<std::vector<int>>& faces_of,
               const std::vector<std::vector<std::vector<int>>>& face_loops, std::vector<Vec3>& n,
               std::vector<double>& d, double tol) {
  double last = std::numeric_limits<double>::infinity();
  for (int round = 0; round < kPlanarizeRounds; ++round) {
    for (std::size_t r = 0; r < face_loops.size(); ++r) {
      std::vector<int> corners;
      for (const auto& loop : face_loops[r])
        corners.insert(corners.end(), loop.begin(), loop.end());
      fit_plane(coords, corners, Vec3(n[r]), n[r], d[r]);
    }
    double worst = 0;
    for (std::size_t i = 0; i < coords.size(); ++i)
      worst = std::max(worst, snap_onto_planes(coords[i], faces_of[i], n, d, tol));
    // Done, or stalled (a model no planes fit): the polyhedron's check says how far off.
    if (worst <= tol || worst > kPlanarizeStall * last) return;
    last = worst;
  }
}

// Each face's loops in feature vertex ids (the outer loop first, then the holes in order, each
// from its smallest id), the faces of each feature vertex, and the edges (v0 < v1, sorted).
struct FaceLoops {
  std::vector<std::vector<std::vector<int>>> loops;
  std::vector<std::vector<int>> faces_of;
  std::vector<std::array<int, 2>> edges;
};

// FaceLoops from the loops of mesh vertices found per face (loop_area: each one's signed
// area about its face's normal) and the feature id of each mesh vertex (vid).
FaceLoops face_loops_of(const std::vector<std::vector<std::vector<int>>>& loops,
                        const std::vector<std::vector<double>>& loop_area,
                        const std::vector<int>& vid, std::size_t n_features,
                        const std::vector<int>& seed, const std::string& src) {
  const int nr = static_cast<int>(loops.size());
  FaceLoops f;
  f.loops.resize(loops.size());
  f.faces_of.resize(n_features);
  for (int r = 0; r < nr; ++r) {
    int outer = -1, outers = 0;
    for (std::size_t l = 0; l < loops[r].size(); ++l)
      if (loop_area[r][l] > 0) {
        ++outers;
        outer = static_cast<int>(l);
      }
    if (outers != 1)
      fail(src, "the face containing facet " + std::to_string(seed[r]) + " has " +
                    std::to_string(outers) +
                    " outer boundaries (counter-clockwise loops); expected 1");
    std::vector<std::vector<int>> out;
    auto convert = [&](const std::vector<int>& loop) {
      std::vector<int> ids;
      for (int v : loop) ids.push_back(vid[v]);
      std::rotate(ids.begin(), std::min_element(ids.begin(), ids.end()), ids.end());
      return ids;
    };
    out.push_back(convert(loops[r][outer]));
    std::vector<std::vector<int>> holes;
    for (std::size_t l = 0; l < loops[r].size(); ++l)
      if (static_cast<int>(l) != outer) holes.push_back(convert(loops[r][l]));
    std::sort(holes.begin(), holes.end());
    for (auto& h : holes) out.push_back(std::move(h));
    for (const auto& loop : out)
      for (std::size_t q = 0; q < loop.size(); ++q) {
        const int a = loop[q], b = loop[(q + 1) % loop.size()];
        f.faces_of[a].push_back(r);
        if (a < b) f.edges.push_back({a, b});  // each edge is run a -> b by exactly one face
      }
    f.loops[r] = std::move(out);
  }
  std::sort(f.edges.begin(), f.edges.end());
  return f;
}

// The feature vertices' coordinates: the input points, moved onto the intersection of their
// faces' planes only when they are off by more than rounding (input written with fewer
// digits, or facets merged across a coarse --coplanar-tol), then made consistent with the
// planes refitted through them (planarize). off_plane: the largest distance before.
std::vector<Vec3> feature_coordinates(const std::vector<Vec3>& P,
                                      const std::vector<int>& feature_points,
                                      std::vector<std::vector<int>>& faces_of,
                                      const std::vector<std::vector<std::vector<int>>>& face_loops,
                                      std::vector<Vec3>& plane_n, std::vector<double>& plane_d,
                                      double* off_plane) {
  const double snap_tol = snap_tolerance(P);
  std::vector<Vec3> coords;
  coords.reserve(feature_points.size());
  bool snapped = false;
  for (std::size_t i = 0; i < feature_points.size(); ++i) {
    auto& fs = faces_of[i];
    std::sort(fs.begin(), fs.end());
    fs.erase(std::unique(fs.begin(), fs.end()), fs.end());
    Vec3 p = P[static_cast<std::size_t>(feature_points[i])];
    const double dev = snap_onto_planes(p, fs, plane_n, plane_d, snap_tol);
    if (off_plane) *off_plane = std::max(*off_plane, dev);
    snapped = snapped || dev > snap_tol;
    coords.push_back(p);
  }
  if (snapped) planarize(coords, faces_of, face_loops, plane_n, plane_d, snap_tol);
  return coords;
}

// The faces' planes, corners and boundary loops for one assignment of facets to faces.
struct Boundaries {
  std::vector<Vec3> plane_n;  // of each face: least squares through its mesh vertices
  std::vector<double> plane_d;
  std::vector<char> is_feature;                      // of each mesh vertex: a corner
  std::vector<std::vector<std::vector<int>>> loops;  // of each face: corners, in mesh ids
  std::vector<std::vector<double>> loop_area;        // each loop's signed area
  // Faces that cannot be planar as grown, each with why: a loop of fewer than 3 corners, a
  // boundary with another face bending by more than tol where those two faces alone meet.
  std::vector<std::pair<int, std::string>> troubles;
};

// Planes of the faces: least squares through all their mesh vertices, oriented like the
// facets.
void fit_face_planes(const PolygonSoup& s, const FacetRegions& faces, Boundaries& b) {
  const std::size_t nr = faces.seed.size();
  std::vector<std::vector<int>> region_vertices(nr);
  std::vector<Vec3> region_area(nr, Vec3::Zero());
  for (std::size_t f = 0; f < s.polygons.size(); ++f) {
    const int r = faces.region[f];
    region_area[r] += newell(s.points, s.polygons[f]);
    for (int i : s.polygons[f]) region_vertices[r].push_back(i);
  }
  b.plane_n.resize(nr);
  b.plane_d.resize(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    auto& vs = region_vertices[r];
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    fit_plane(s.points, vs, region_area[r], b.plane_n[r], b.plane_d[r]);
  }
}

// Corners: a boundary edge a-b is run a -> b by one face and b -> a by the other, so the heads
// of the outgoing boundary half-edges are all the rays of a vertex. A corner has three rays
// or more (three faces meet there). A vertex with two lies between two faces only, on the
// line their planes meet in, so it is no corner: the run of boundary through it must be
// straight within tol, however its facets were rounded or merged (trace_boundaries).
std::vector<char> corners_of(const PolygonSoup& s, const HalfEdges& he,
                             const std::vector<int>& region) {
  const auto& F = s.polygons;
  std::vector<std::vector<int>> rays(s.points.size());
  for (std::size_t f = 0; f < F.size(); ++f)
    for (std::size_t k = 0; k < F[f].size(); ++k) {
      const int a = F[f][k], b = F[f][(k + 1) % F[f].size()];
      if (region[he.at(key(b, a)).first] != region[f]) rays[a].push_back(b);
    }
  std::vector<char> is_feature(s.points.size(), 0);
  for (std::size_t v = 0; v < rays.size(); ++v) {
    auto& r = rays[v];
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    is_feature[v] = r.size() >= 3;
  }
  return is_feature;
}

// Empty when every run of one loop's mesh vertices between consecutive corners (at: their
// positions in mesh_loop) lies within tol of the straight segment between the two corners,
// else why not.
std::string bend_in(const std::vector<Vec3>& P, const std::vector<int>& mesh_loop,
                    const std::vector<std::size_t>& at, double tol) {
  const std::size_t m = mesh_loop.size(), nc = at.size();
  for (std::size_t c = 0; c < nc; ++c) {
    const Vec3& a = P[mesh_loop[at[c]]];
    const Vec3& b = P[mesh_loop[at[(c + 1) % nc]]];
    for (std::size_t q = (at[c] + 1) % m; q != at[(c + 1) % nc]; q = (q + 1) % m)
      if (const double d = point_segment_distance(P[mesh_loop[q]], a, b); d > tol)
        return "bends gradually near vertex " + std::to_string(mesh_loop[q]) + " (" + num(d) +
               " mm off a straight edge); not a polyhedral edge";
  }
  return {};
}

// Loops: follow boundary half-edges; from the end of one, turn around its end vertex
// through facets of the same face until the next boundary half-edge. Only corners are kept.
Boundaries trace_boundaries(const PolygonSoup& s, const HalfEdges& he, const FacetRegions& faces,
                            double tol, const std::string& src) {
  const auto& P = s.points;
  const auto& F = s.polygons;
  const std::vector<int>& region = faces.region;
  const int nf = static_cast<int>(F.size());
  Boundaries b;
  fit_face_planes(s, faces, b);
  b.is_feature = corners_of(s, he, region);
  b.loops.resize(faces.seed.size());
  b.loop_area.resize(faces.seed.size());
  auto twin = [&](int f, int k) { return he.at(key(F[f][(k + 1) % F[f].size()], F[f][k])); };
  auto on_boundary = [&](int f, int k) { return region[twin(f, k).first] != region[f]; };
  auto next_boundary = [&](int f, int k) {
    int g = f;
    int j = static_cast<int>((k + 1) % F[f].size());
    for (int guard = 0; !on_boundary(g, j); ++guard) {
      if (guard > nf) fail(src, "internal error: cannot close a face boundary loop");
      const auto [g2, j2] = twin(g, j);
      g = g2;
      j = static_cast<int>((j2 + 1) % F[g2].size());
    }
    return std::make_pair(g, j);
  };
  auto face_desc = [&](int r) {
    return "the face containing facet " + std::to_string(faces.seed[r]);
  };
  std::unordered_map<std::uint64_t, char> visited;
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < static_cast<int>(F[f].size()); ++k) {
      if (!on_boundary(f, k) || visited.count(key(f, k))) continue;
      const int r = region[f];
      std::vector<int> mesh_loop;
      int g = f, j = k;
      do {
        visited[key(g, j)] = 1;
        mesh_loop.push_back(F[g][j]);
        std::tie(g, j) = next_boundary(g, j);
        if (mesh_loop.size() > P.size() * 2)
          fail(src, "internal error: a boundary loop of " + face_desc(r) + " does not close");
      } while (!(g == f && j == k));
      std::vector<int> corners;
      std::vector<std::size_t> at;
      for (std::size_t q = 0; q < mesh_loop.size(); ++q)
        if (b.is_feature[mesh_loop[q]]) {
          corners.push_back(mesh_loop[q]);
          at.push_back(q);
        }
      if (corners.size() < 3)
        b.troubles.emplace_back(r, "a boundary loop of " + face_desc(r) + " has " +
                                       std::to_string(corners.size()) +
                                       " corners; a curved boundary tessellated finer than the "
                                       "collinearity tolerance (" +
                                       num(tol) + " mm) is not a polyhedron");
      else if (std::string why = bend_in(P, mesh_loop, at, tol); !why.empty())
        b.troubles.emplace_back(r, "the boundary of " + face_desc(r) + " " + why);
      const std::size_t m = mesh_loop.size();
      Vec3 n2 = Vec3::Zero();
      for (std::size_t q = 0; q < m; ++q) n2 += P[mesh_loop[q]].cross(P[mesh_loop[(q + 1) % m]]);
      b.loops[r].push_back(std::move(corners));
      b.loop_area[r].push_back(0.5 * n2.dot(b.plane_n[r]));
    }
  return b;
}

// Faces next to each other whose planes are parallel once their corners are placed: the
// polyhedron would have an edge between two coplanar faces (faces merged at a coarse
// tolerance around a facet that is not, or two faces sharing two edges that meet at a
// corner). Sines below 1e-9 (far above the arithmetic's rounding) count.
std::vector<std::pair<int, std::string>> coplanar_neighbours(const FaceLoops& fl,
                                                             const std::vector<Vec3>& n,
                                                             const std::vector<int>& seed) {
  std::map<std::array<int, 2>, int> first_face;
  std::vector<std::pair<int, std::string>> out;
  for (std::size_t r = 0; r < fl.loops.size(); ++r)
    for (const auto& loop : fl.loops[r])
      for (std::size_t q = 0; q < loop.size(); ++q) {
        std::array<int, 2> e{loop[q], loop[(q + 1) % loop.size()]};
        if (e[0] > e[1]) std::swap(e[0], e[1]);
        const auto [it, fresh] = first_face.emplace(e, static_cast<int>(r));
        if (fresh || n[static_cast<std::size_t>(it->second)].cross(n[r]).norm() >= 1e-9) continue;
        const std::string why = "the faces containing facets " + std::to_string(seed[r]) + " and " +
                                std::to_string(seed[it->second]) +
                                " meet at an edge but lie in one plane";
        out.emplace_back(static_cast<int>(r), why);
        out.emplace_back(it->second, why);
      }
  return out;
}

// Faces whose corners, once placed, are further than kPlanarCheck x diag from the plane
// through them: planarize could not make them planar (faces merged at a coarse tolerance from
// facets no planes fit), and libcf would refuse them (1e-6 of its size, twice this; the
// diagonal of the used points is at least the polyhedron's size).
constexpr double kPlanarCheck = 5e-7;

std::vector<std::pair<int, std::string>> unplanar_faces(const std::vector<Vec3>& coords,
                                                        const FaceLoops& fl, double diag,
                                                        const std::vector<int>& seed) {
  std::vector<std::pair<int, std::string>> out;
  for (std::size_t r = 0; r < fl.loops.size(); ++r) {
    std::vector<int> corners;
    for (const auto& loop : fl.loops[r]) corners.insert(corners.end(), loop.begin(), loop.end());
    Vec3 n;
    double d = 0, off = 0;
    fit_plane(coords, corners, Vec3::UnitZ(), n, d);
    for (int v : corners)
      off = std::max(off, std::abs(n.dot(coords[static_cast<std::size_t>(v)]) - d));
    if (off > kPlanarCheck * diag)
      out.emplace_back(static_cast<int>(r), "the face containing facet " + std::to_string(seed[r]) +
                                                " is not planar (a corner " + num(off) +
                                                " mm off its plane)");
  }
  return out;
}

// mm, of each face of the polyhedron m extracted with these regions (face r of m is region r):
// the largest distance of a vertex of one of its facets from its polygon
// (FeatureMeasures::deviation is the largest of them).
std::vector<double> face_deviations(const PolygonSoup& s, const std::vector<int>& region,
                                    const Polyhedron& m) {
  std::vector<double> worst(m.num_faces(), 0.0);
  for (std::size_t f = 0; f < s.polygons.size(); ++f) {
    const FaceId face(region[f]);
    const Face& F = m.face(face);
    for (int i : s.polygons[f]) {
      const Vec3& p = s.points[static_cast<std::size_t>(i)];
      const double h = F.normal.dot(p) - F.offset;
      const double out = std::max(0.0, -m.face_inset(face, p));  // beyond the face's boundary
      double& w = worst[static_cast<std::size_t>(face.index())];
      w = std::max(w, std::sqrt(h * h + out * out));
    }
  }
  return worst;
}

// A face may lie at most this many times the coplanarity tolerance from the file's facets it
// was merged from (FeatureMeasures::deviation): a facet joins within the tolerance of the face's
// plane so far, the plane fitted at the end moves by up to as much again.
constexpr double kMaxDeviation = 2;

// Raises the tier (JoinTolerances) of every facet of the faces in `troubles`; where they are
// all at the last tier already, of the faces next to them, and so on outward (the corners of a
// face are placed with its neighbours' planes, and planarize refits them all). False when
// every facet is at the last tier: nothing is left to change.
bool raise_tiers(const PolygonSoup& s, const HalfEdges& he, const FacetRegions& faces,
                 const std::vector<std::pair<int, std::string>>& troubles,
                 std::vector<char>& tier) {
  const std::size_t nr = faces.seed.size(), nf = s.polygons.size();
  std::vector<char> mark(nr, 0);
  for (const auto& t : troubles) mark[static_cast<std::size_t>(t.first)] = 1;
  for (;;) {
    bool changed = false, grew = false;
    for (std::size_t f = 0; f < nf; ++f)
      if (mark[static_cast<std::size_t>(faces.region[f])] && tier[f] < 2) ++tier[f], changed = true;
    if (changed) return true;
    std::vector<char> next = mark;
    for (std::size_t f = 0; f < nf; ++f) {
      if (!mark[static_cast<std::size_t>(faces.region[f])]) continue;
      const auto& poly = s.polygons[f];
      for (std::size_t k = 0; k < poly.size(); ++k) {
        const auto r = static_cast<std::size_t>(
            faces.region[he.at(key(poly[(k + 1) % poly.size()], poly[k])).first]);
        grew = grew || !next[r];
        next[r] = 1;
      }
    }
    if (!grew) return false;
    mark = std::move(next);
  }
}

}  // namespace

cf::Polyhedron extract_features(const PolygonSoup& s, const std::string& src,
                                const std::string& name, const LoadOptions& opt,
                                FeatureMeasures* measures) {
  const auto& P = s.points;
  const int nf = static_cast<int>(s.polygons.size());
  const double diag = diagonal(s);
  const double tol = opt.coplanar_rel_tol * diag;
  const HalfEdges he = half_edges(s);
  std::vector<Vec3> area2(nf), centre(nf);
  for (int f = 0; f < nf; ++f) {
    area2[f] = newell(P, s.polygons[f]);
    centre[f] = mean_point(P, s.polygons[f]);
  }
  // A coarse tolerance can merge facets into faces no planar polyhedron has: a boundary
  // between two faces bending where they alone meet, a loop of fewer than 3 corners, two
  // neighbouring faces in one plane, a face planarize cannot make planar. The facets of such
  // faces are grown again a tier stricter (JoinTolerances: the default tolerance, then
  // rounding), until no face fails or every facet is at the last tier; that failure is
  // reported.
  JoinTolerances join;
  join.coarse = tol;
  join.fine = std::min(tol, LoadOptions{}.coplanar_rel_tol * diag);
  join.exact = std::min(join.fine, snap_tolerance(P));
  join.cos_crease = std::cos(opt.crease_angle_deg * M_PI / 180);
  std::vector<char> tier(nf, tol <= join.fine ? 1 : 0);
  for (;;) {
    const FacetRegions faces = grow_faces(s, he, area2, centre, join, tier);
    Boundaries b = trace_boundaries(s, he, faces, tol, src);
    std::vector<int> vid(P.size(), -1), feature_points;
    for (std::size_t v = 0; v < P.size(); ++v)
      if (b.is_feature[v]) {
        vid[v] = static_cast<int>(feature_points.size());
        feature_points.push_back(static_cast<int>(v));
      }
    FaceLoops fl;
    std::vector<Vec3> coords;
    double off = 0;
    if (b.troubles.empty()) {
      fl = face_loops_of(b.loops, b.loop_area, vid, feature_points.size(), faces.seed, src);
      coords =
          feature_coordinates(P, feature_points, fl.faces_of, fl.loops, b.plane_n, b.plane_d, &off);
      b.troubles = coplanar_neighbours(fl, b.plane_n, faces.seed);
      for (auto& t : unplanar_faces(coords, fl, diag, faces.seed))
        b.troubles.push_back(std::move(t));
    }
    if (!b.troubles.empty()) {
      if (!raise_tiers(s, he, faces, b.troubles, tier)) fail(src, b.troubles.front().second);
      continue;
    }
    Polyhedron m;
    try {
      m = Polyhedron::from_features(name, std::move(coords), fl.edges, fl.loops);
    } catch (const Error& e) {
      fail(src, std::string("the extracted features do not form a valid polyhedron: ") + e.what());
    }
    // A face placed further than twice the tolerance from its facets (corners moved onto
    // planes meeting at shallow angles) is grown again finer too.
    const std::vector<double> dev = face_deviations(s, faces.region, m);
    for (std::size_t r = 0; r < dev.size(); ++r)
      if (dev[r] > kMaxDeviation * tol)
        b.troubles.emplace_back(static_cast<int>(r), "the face containing facet " +
                                                         std::to_string(faces.seed[r]) + " lies " +
                                                         num(dev[r]) + " mm from its facets");
    if (!b.troubles.empty() && raise_tiers(s, he, faces, b.troubles, tier)) continue;
    if (measures) *measures = {off, dev.empty() ? 0.0 : *std::max_element(dev.begin(), dev.end())};
    return m;
  }
}

}  // namespace cf::tools::detail

namespace cf::tools {

namespace {

// The fewest significant digits (1 to 17) that print x so that it reads back exactly.
int digits_of(double x) {
  int lo = 1, hi = 17;  // 17 always reads back (a double's round trip)
  char buf[40];
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    std::snprintf(buf, sizeof buf, "%.*g", mid, x);
    if (std::strtod(buf, nullptr) == x)
      hi = mid;
    else
      lo = mid + 1;
  }
  return lo;
}

// Half a unit of the last of `digits` significant digits of x.
double half_unit(double x, int digits) {
  const double exponent = std::floor(std::log10(std::abs(x)));
  return 0.5 * std::pow(10.0, exponent - digits + 1);
}

// Whether x is a float32 value. Through a volatile float: GCC 12.2 at -O2/-O3 was seen to drop
// the rounding of (double)(float)x when vectorizing such round trips (symmetry_test).
bool is_float32(double x) {
  volatile float f = static_cast<float>(x);
  return static_cast<double>(f) == x;
}

}  // namespace

double coordinate_rounding(const std::vector<Vec3>& points) {
  double largest = 0;
  bool float32 = true;
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      largest = std::max(largest, std::abs(p[k]));
      float32 = float32 && is_float32(p[k]);
    }
  if (largest == 0) return 0;
  // Half a unit in the last place of float32 at the largest coordinate: 2^-24 of it.
  if (float32) return std::ldexp(largest, -24);
  // The writer's digits: the most any coordinate needs ("0.1" in a file written at 6 digits
  // is 0.100000 with its zeros dropped).
  const std::size_t n = 3 * points.size();
  const std::size_t stride = std::max<std::size_t>(1, n / kRoundingSample);
  int digits = 1;
  auto read = [&](double x) {
    if (x != 0 && std::isfinite(x)) digits = std::max(digits, digits_of(x));
  };
  for (std::size_t i = 0; i < n; i += stride) read(points[i / 3][static_cast<int>(i % 3)]);
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k)
      if (std::abs(p[k]) == largest) read(p[k]);
  // Never below a double's own rounding (17 digits say more than a double holds).
  return std::max(half_unit(largest, digits), std::ldexp(largest, -53));
}

double model_precision(const cf::Polyhedron& m) {
  double largest = 0, off = 0;
  for (const auto& v : m.vertices()) largest = std::max(largest, v.p.cwiseAbs().maxCoeff());
  for (const auto& f : m.faces())
    for (VertexId i : f.vertices)
      off = std::max(off, std::abs(f.normal.dot(m.vertex(i).p) - f.offset));
  return std::max(off, kPrecisionRoundings * std::numeric_limits<double>::epsilon() * largest);
}

}  // namespace cf::tools

// Feature extraction (docs/spec.md, section 3; docs/features.md) on the default models and on
// constructed meshes; the JSON schema of the model object; the cfgen --features command.

#include "mesh/model_loader.hpp"

#include "scratch.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using cf::Vec3;
using cf::tools::load_model;

namespace {

// Values computed from small exact integers: a few ulps of the model's size.
constexpr double kExact = 1e-12;
// Coordinates that went through single precision (STL) at about 120 mm: float rounding is
// 120 * 6e-8 = 7e-6 mm per coordinate; the feature vertices are plane intersections of
// least-squares planes, so allow a little more.
constexpr double kFloat = 1e-4;

const std::string kData = std::string(CF_SOURCE_DIR) + "/data/models/";
const std::string kFixtures = std::string(CF_TEST_DATA_DIR) + "/models/";

using cf::test::scratch;
using cf::test::write_file;

std::string binary_stl(const std::vector<Vec3>& v, const std::vector<std::vector<int>>& tris) {
  std::string s(80, ' ');
  auto put = [&s](const void* p, std::size_t n) { s.append(static_cast<const char*>(p), n); };
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  put(&n, 4);
  for (const auto& t : tris) {
    const float zero[3] = {0, 0, 0};  // readers recompute normals
    put(zero, 12);
    for (int i : t)
      for (int k = 0; k < 3; ++k) {
        const float x = static_cast<float>(v[i][k]);
        put(&x, 4);
      }
    const std::uint16_t attr = 0;
    put(&attr, 2);
  }
  return s;
}

// Fan triangulation from each polygon's first vertex (valid for the convex polygons used).
std::vector<std::vector<int>> fan(const std::vector<std::vector<int>>& polys) {
  std::vector<std::vector<int>> t;
  for (const auto& p : polys)
    for (std::size_t k = 1; k + 1 < p.size(); ++k) t.push_back({p[0], p[k], p[k + 1]});
  return t;
}

int count_reflex(const cf::Polyhedron& m) {
  int n = 0;
  for (const cf::Edge& e : m.edges()) n += !e.convex;
  return n;
}

int count_holes(const cf::Polyhedron& m) {
  int n = 0;
  for (const cf::Face& f : m.faces()) n += static_cast<int>(f.loops.size()) - 1;
  return n;
}

int find_vertex(const cf::Polyhedron& m, const Vec3& p, double tol = kExact) {
  for (std::size_t i = 0; i < m.num_vertices(); ++i)
    if ((m.vertices()[i].p - p).norm() < tol) return static_cast<int>(i);
  return -1;
}

// The edge between the vertices at p and q, or nullptr.
const cf::Edge* find_edge(const cf::Polyhedron& m, const Vec3& p, const Vec3& q) {
  const int a = find_vertex(m, p), b = find_vertex(m, q);
  for (const cf::Edge& e : m.edges())
    if ((e.v0.value() == a && e.v1.value() == b) || (e.v0.value() == b && e.v1.value() == a))
      return &e;
  return nullptr;
}

// Every generic invariant: Euler-Poincare for a genus-g solid whose faces may have holes,
// V - E + F - H = 2 (1 - g); loops start at their smallest index; edges sorted with v0 < v1.
void check_invariants(const cf::Polyhedron& m, int genus) {
  const long V = static_cast<long>(m.num_vertices()), E = static_cast<long>(m.num_edges()),
             F = static_cast<long>(m.num_faces()), H = count_holes(m);
  CHECK(V - E + F - H == 2 * (1 - genus));
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    CHECK(m.edges()[e].v0 < m.edges()[e].v1);
    if (e > 0) {
      const auto& a = m.edges()[e - 1];
      const auto& b = m.edges()[e];
      CHECK((a.v0 < b.v0 || (a.v0 == b.v0 && a.v1 < b.v1)));
    }
  }
  for (const cf::Face& f : m.faces()) {
    for (const auto& loop : f.loops) CHECK(*std::min_element(loop.begin(), loop.end()) == loop[0]);
    for (std::size_t l = 2; l < f.loops.size(); ++l) CHECK(f.loops[l - 1][0] < f.loops[l][0]);
  }
}

// An n-gon prism of circumradius r and height h along z, its sides one quad each.
cf::tools::PolygonSoup ngon_prism(int n, double r, double h) {
  cf::tools::PolygonSoup s;
  for (double z : {0.0, h})
    for (int i = 0; i < n; ++i)
      s.points.push_back({r * std::cos(2 * M_PI * i / n), r * std::sin(2 * M_PI * i / n), z});
  std::vector<int> bottom, top;
  for (int i = 0; i < n; ++i) bottom.push_back(n - 1 - i), top.push_back(n + i);
  s.polygons = {bottom, top};
  for (int i = 0; i < n; ++i) s.polygons.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  return s;
}

// A UV sphere of radius r: nu meridians, nv rings of latitude; triangles, two per quad.
cf::tools::PolygonSoup uv_sphere(int nu, int nv, double r) {
  cf::tools::PolygonSoup s;
  s.points.push_back({0, 0, -r});
  for (int j = 1; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double lat = M_PI * j / nv - M_PI / 2, lon = 2 * M_PI * i / nu;
      s.points.push_back({r * std::cos(lat) * std::cos(lon), r * std::cos(lat) * std::sin(lon),
                          r * std::sin(lat)});
    }
  const int top = static_cast<int>(s.points.size());
  s.points.push_back({0, 0, r});
  auto id = [&](int j, int i) { return 1 + (j - 1) * nu + i % nu; };
  for (int i = 0; i < nu; ++i) s.polygons.push_back({0, id(1, i + 1), id(1, i)});
  for (int j = 1; j + 1 < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      s.polygons.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
      s.polygons.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
    }
  for (int i = 0; i < nu; ++i) s.polygons.push_back({top, id(nv - 1, i), id(nv - 1, i + 1)});
  return s;
}

// A torus of radii R (to the tube's centre) and r (the tube's): triangles, two per quad.
cf::tools::PolygonSoup torus(int nu, int nv, double R, double r) {
  cf::tools::PolygonSoup s;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double a = 2 * M_PI * i / nu, b = 2 * M_PI * j / nv;
      s.points.push_back({(R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a),
                          r * std::sin(b)});
    }
  auto id = [&](int j, int i) { return j % nv * nu + i % nu; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      s.polygons.push_back({id(j, i), id(j, i + 1), id(j + 1, i + 1)});
      s.polygons.push_back({id(j, i), id(j + 1, i + 1), id(j + 1, i)});
    }
  return s;
}

// mm: the diagonal of the bounding box of the soup's points.
double soup_diagonal(const cf::tools::PolygonSoup& s) {
  Vec3 lo = s.points[0], hi = s.points[0];
  for (const Vec3& p : s.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return (hi - lo).norm();
}

// mm: the distance from p to the model's surface, the nearest of its face polygons.
double surface_distance(const cf::Polyhedron& m, const Vec3& p) {
  double best = HUGE_VAL;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    const cf::Face& F = m.faces()[f];
    const double h = F.normal.dot(p) - F.offset;
    const double out = std::max(0.0, -m.face_inset(cf::FaceId(static_cast<int>(f)), p));
    best = std::min(best, std::hypot(h, out));
  }
  return best;
}

// mm: the largest distance between two corners of face f seen along z.
double widest_span(const cf::Polyhedron& m, const cf::Face& f) {
  double w = 0;
  for (cf::VertexId a : f.vertices)
    for (cf::VertexId b : f.vertices)
      w = std::max(w, (m.vertex(a).p - m.vertex(b).p).head<2>().norm());
  return w;
}

}  // namespace

TEST_CASE("a 12-triangle cube has 8 vertices, 12 edges and 6 faces", "[features]") {
  const cf::Polyhedron m = load_model(kFixtures + "cube_tri.off");
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  check_invariants(m, 0);
  for (const cf::Edge& e : m.edges()) {
    CHECK(e.convex);
    CHECK(e.dihedral == Approx(M_PI / 2).epsilon(kExact));
    CHECK(e.length == Approx(10).epsilon(kExact));
  }
  for (const cf::Face& f : m.faces()) {
    CHECK(f.area == Approx(100).epsilon(kExact));
    CHECK(std::abs(f.normal.cwiseAbs().maxCoeff() - 1) < kExact);  // axis aligned
  }
  // Faces are ordered by their lowest input facet: facets 0,1 are the bottom (z = 0).
  CHECK((m.face(cf::FaceId(0)).normal - Vec3(0, 0, -1)).norm() < kExact);
  CHECK(m.face(cf::FaceId(0)).loops[0] ==
        std::vector<cf::VertexId>{cf::VertexId(0), cf::VertexId(3), cf::VertexId(2),
                                  cf::VertexId(1)});
}

TEST_CASE("the cube A of the default data", "[features][models]") {
  const cf::Polyhedron m = load_model(kData + "cube.off");
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  CHECK(m.volume() == Approx(27000).epsilon(kExact));
  CHECK(m.volume_centroid().norm() < kExact);  // centred on its origin
  check_invariants(m, 0);
}

TEST_CASE("the L-shaped block", "[features][models]") {
  // The L profile in the xy plane has 6 corners, extruded along z (0..80 mm):
  //   V = 6 front + 6 back = 12; E = 6 front + 6 back + 6 along z = 18;
  //   F = 2 caps + 6 sides = 8; the only reflex edge is the inner corner of the L,
  //   (20,20,0)-(20,20,80), with an interior dihedral of 270 degrees.
  const cf::Polyhedron m = load_model(kData + "l_block.off");
  CHECK(m.num_vertices() == 12);
  CHECK(m.num_edges() == 18);
  CHECK(m.num_faces() == 8);
  CHECK(count_holes(m) == 0);
  CHECK(count_reflex(m) == 1);
  const cf::Edge* inner = find_edge(m, {20, 20, 0}, {20, 20, 80});
  REQUIRE(inner != nullptr);
  CHECK_FALSE(inner->convex);
  CHECK(inner->dihedral == Approx(1.5 * M_PI).epsilon(kExact));
  CHECK(m.volume() == Approx(120 * 20 * 80 + 20 * 60 * 80).epsilon(kExact));
  check_invariants(m, 0);
  // The caps are the non-convex L polygon: 6 corners each.
  int l_faces = 0;
  for (const cf::Face& f : m.faces()) l_faces += f.loops[0].size() == 6;
  CHECK(l_faces == 2);
}

TEST_CASE("the corner-shaped block", "[features][models]") {
  // Floor 120 x 20 x 120 with walls 20 thick, 80 high along x = 0 and z = 0 (y up):
  //   V: 4 bottom corners + 6 corners of the L-shaped wall top (y = 80) + 4 corners of the
  //      floor's top square (y = 20) = 14;
  //   F: bottom, wall top, floor top, outer sides x = 0 and z = 0 (rectangles), outer
  //      sides x = 120 and z = 120 (L-shaped), inner walls x = 20 and z = 20 = 9;
  //   E: V + F - 2 = 21 (Euler, genus 0, no holes): 4 bottom + 6 wall top + 4 floor top
  //      + 7 vertical;
  //   reflex: where the floor meets each inner wall and where the two inner walls meet = 3.
  const cf::Polyhedron m = load_model(kData + "corner_block.off");
  CHECK(m.num_vertices() == 14);
  CHECK(m.num_edges() == 21);
  CHECK(m.num_faces() == 9);
  CHECK(count_holes(m) == 0);
  CHECK(count_reflex(m) == 3);
  for (const auto& [p, q] : std::vector<std::pair<Vec3, Vec3>>{{{20, 20, 20}, {120, 20, 20}},
                                                               {{20, 20, 20}, {20, 20, 120}},
                                                               {{20, 20, 20}, {20, 80, 20}}}) {
    const cf::Edge* e = find_edge(m, p, q);
    REQUIRE(e != nullptr);
    CHECK_FALSE(e->convex);
  }
  // The seat for the cube: floor top and the two inner walls, mutually perpendicular.
  int seats = 0;
  for (const cf::Face& f : m.faces())
    seats += (f.normal - Vec3(0, 1, 0)).norm() < kExact && std::abs(f.offset - 20) < kExact;
  CHECK(seats == 1);
  CHECK(m.volume() == Approx(120 * 20 * 120 + 120 * 60 * 20 + 20 * 60 * 100).epsilon(kExact));
  check_invariants(m, 0);
}

TEST_CASE("the peg", "[features][models]") {
  const cf::Polyhedron m = load_model(kData + "peg.off");
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  CHECK(m.volume() == Approx(20 * 60 * 20).epsilon(kExact));
  CHECK(m.bbox_max().isApprox(Vec3(10, 30, 10)));
  check_invariants(m, 0);
}

TEST_CASE("a block with a through-hole has faces with inner loops and reflex edges",
          "[features][models]") {
  // 80 x 40 x 80 with a 24 x 24 square hole along y: V = 8 outer + 8 hole = 16;
  // F = 4 outer sides + 4 hole walls + top + bottom = 10; E = 12 outer box + 4 rim top +
  // 4 rim bottom + 4 along the hole = 24; top and bottom have one hole each (H = 2), genus 1:
  // V - E + F - H = 0. The 4 edges along the hole are reflex; the rims are convex.
  const cf::Polyhedron m = load_model(kData + "hole_block.off");
  CHECK(m.num_vertices() == 16);
  CHECK(m.num_edges() == 24);
  CHECK(m.num_faces() == 10);
  CHECK(count_holes(m) == 2);
  CHECK(count_reflex(m) == 4);
  for (const cf::Edge& e : m.edges())
    if (!e.convex) {
      CHECK(std::abs(e.dir.y()) == Approx(1).epsilon(kExact));  // along the hole
      CHECK(e.dihedral == Approx(1.5 * M_PI).epsilon(kExact));
    }
  check_invariants(m, 1);
  for (const cf::Face& f : m.faces()) {
    if (f.loops.size() != 2) continue;
    CHECK(f.area == Approx(80 * 80 - 24 * 24).epsilon(kExact));
    // The hole loop holds the hole's corners: 28 or 52 in x and z.
    for (cf::VertexId v : f.loops[1]) {
      const Vec3& p = m.vertex(v).p;
      CHECK((p.x() == 28 || p.x() == 52));
      CHECK((p.z() == 28 || p.z() == 52));
    }
    CHECK(f.loops[1].size() == 4);
  }
  CHECK(m.volume() == Approx(80 * 40 * 80 - 24 * 24 * 40).epsilon(kExact));
}

TEST_CASE("a triangulated model and its polygonal original have identical features", "[features]") {
  const cf::tools::LoadOptions same_name{"L"};
  CHECK(cf::to_json(load_model(kData + "l_block_tri.obj", same_name)) ==
        cf::to_json(load_model(kData + "l_block.off", same_name)));
  CHECK(cf::to_json(load_model(kFixtures + "cube_tri.off", same_name)) ==
        cf::to_json(load_model(kFixtures + "cube.off", same_name)));
  // The hole block, fan-triangulated (its trapezoids and rectangles are convex).
  const cf::tools::PolygonSoup poly = cf::tools::read_polygon_soup(kData + "hole_block.off");
  const cf::tools::PolygonSoup tri{poly.points, fan(poly.polygons)};
  CHECK(cf::to_json(cf::tools::model_from_soup(tri, "tri", same_name)) ==
        cf::to_json(cf::tools::model_from_soup(poly, "poly", same_name)));
}

TEST_CASE("a vertex where an edge meets a straight face side stays a vertex of that face",
          "[features]") {
  // A 20 x 10 x 10 block whose right half has a sloped front (z = y / 2 for x in [10, 20]):
  // point 1 = (10,0,0) lies in the middle of the straight front side of the bottom face,
  // where the edges of the front face, the step triangle and the slope meet.
  const std::vector<Vec3> v = {{0, 0, 0},   {10, 0, 0},   {20, 0, 0},  {20, 0, 10},
                               {0, 0, 10},  {0, 10, 0},   {10, 10, 0}, {10, 10, 5},
                               {20, 10, 5}, {20, 10, 10}, {0, 10, 10}};
  // The bottom polygon starts at 3 so that the fan triangulation below has no sliver.
  const std::vector<std::vector<int>> f = {{3, 4, 0, 1, 2}, {10, 9, 8, 7, 6, 5}, {0, 5, 6, 1},
                                           {1, 6, 7},       {1, 7, 8, 2},        {2, 8, 9, 3},
                                           {4, 3, 9, 10},   {0, 4, 10, 5}};
  // V = 11 (every point), F = 8, E = V + F - 2 = 17.
  for (const bool triangulated : {false, true}) {
    const cf::tools::PolygonSoup soup{v, triangulated ? fan(f) : f};
    const cf::Polyhedron m = cf::tools::model_from_soup(soup, "t-junction");
    CHECK(m.num_vertices() == 11);
    CHECK(m.num_edges() == 17);
    CHECK(m.num_faces() == 8);
    check_invariants(m, 0);
    // The bottom face keeps vertex 1 between 0 and 2 and has two edges along its front side.
    CHECK(m.face(cf::FaceId(0)).loops[0] ==
          std::vector<cf::VertexId>{cf::VertexId(0), cf::VertexId(1), cf::VertexId(2),
                                    cf::VertexId(3), cf::VertexId(4)});
    CHECK(find_edge(m, v[0], v[1]) != nullptr);
    CHECK(find_edge(m, v[1], v[2]) != nullptr);
    CHECK(find_edge(m, v[0], v[2]) == nullptr);
  }
}

TEST_CASE("mesh vertices inside faces and inside edges are not features", "[features]") {
  // The surface of a 20 mm cube subdivided 4 x 4 per face: 98 mesh points, 96 quads.
  // Indices are assigned in grid order, so the corners are not the lowest indices; the
  // features are still the 8 corners, ordered by their mesh index.
  const int n = 4;
  const double h = 5;
  std::map<std::array<int, 3>, int> index;
  cf::tools::PolygonSoup soup;
  auto point = [&](std::array<int, 3> g) {
    auto [it, fresh] = index.emplace(g, static_cast<int>(soup.points.size()));
    if (fresh) soup.points.emplace_back(g[0] * h, g[1] * h, g[2] * h);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side <= 1; ++side) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          std::vector<int> q;
          for (auto [di, dj] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            std::array<int, 3> g{};
            g[axis] = side * n;
            g[a] = i + di;
            g[b] = j + dj;
            q.push_back(point(g));
          }
          if (side == 0) std::reverse(q.begin(), q.end());  // a x b = axis: flip the low side
          soup.polygons.push_back(q);
        }
    }
  CHECK(soup.points.size() == 98);
  const cf::Polyhedron m = cf::tools::model_from_soup(soup, "grid cube");
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  CHECK(m.volume() == Approx(8000).epsilon(kExact));
  check_invariants(m, 0);
  // Vertex order follows the mesh index of each corner.
  std::vector<std::pair<int, Vec3>> corners;
  for (const auto& [g, i] : index)
    if ((g[0] % n == 0) && (g[1] % n == 0) && (g[2] % n == 0))
      corners.emplace_back(i, soup.points[i]);
  std::sort(corners.begin(), corners.end(), [](auto& x, auto& y) { return x.first < y.first; });
  for (std::size_t k = 0; k < corners.size(); ++k)
    CHECK((m.vertices()[k].p - corners[k].second).norm() < kExact);
}

TEST_CASE("single-precision STL input of a rotated model gives the exact features", "[features]") {
  // The corner block turned about a skew axis and stored as a float STL: its faces are no
  // longer axis aligned, so every coordinate is rounded; the coplanarity tolerance
  // (1e-5 of the diagonal, 2e-3 mm here) absorbs that rounding.
  const cf::tools::PolygonSoup exact = cf::tools::read_polygon_soup(kData + "corner_block.off");
  const cf::Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(3.25, -7.5, 11.125);
  std::vector<Vec3> moved;
  for (const Vec3& p : exact.points) moved.push_back(R * p + t);
  // Fan triangulation is wrong for the L-shaped facets; triangulate them by their own ears.
  std::vector<std::vector<int>> tris;
  for (const auto& poly : exact.polygons) {
    if (poly.size() == 6) {
      // L hexagon a0..a5 with its reflex corner at a3 (see make_models.py): ears
      // (a3,a4,a5), (a3,a5,a0), (a3,a0,a1), (a3,a1,a2) fan from the reflex corner.
      int r = -1;
      for (int k = 0; k < 6; ++k) {
        const Vec3 e1 = exact.points[poly[k]] - exact.points[poly[(k + 5) % 6]];
        const Vec3 e2 = exact.points[poly[(k + 1) % 6]] - exact.points[poly[k]];
        const Vec3 nn = [&] {
          Vec3 s = Vec3::Zero();
          for (int j = 0; j < 6; ++j)
            s += exact.points[poly[j]].cross(exact.points[poly[(j + 1) % 6]]);
          return s;
        }();
        if (e1.cross(e2).dot(nn) < 0) r = k;
      }
      REQUIRE(r >= 0);
      for (int k = 1; k + 1 < 6; ++k)
        tris.push_back({poly[r], poly[(r + k) % 6], poly[(r + k + 1) % 6]});
    } else {
      for (std::size_t k = 1; k + 1 < poly.size(); ++k)
        tris.push_back({poly[0], poly[k], poly[k + 1]});
    }
  }
  const std::string path = write_file("corner_rotated.stl", binary_stl(moved, tris));
  const cf::Polyhedron m = load_model(path);
  const cf::Polyhedron ref = load_model(kData + "corner_block.off");
  REQUIRE(m.num_vertices() == ref.num_vertices());
  CHECK(m.num_edges() == ref.num_edges());
  CHECK(m.num_faces() == ref.num_faces());
  CHECK(count_reflex(m) == 3);
  for (const cf::Vertex& v : ref.vertices()) CHECK(find_vertex(m, R * v.p + t, kFloat) >= 0);
  CHECK(m.volume() == Approx(ref.volume()).epsilon(1e-6));
  check_invariants(m, 0);
}

namespace {

// A 10 mm cube whose top is two quads meeting at a ridge x = 5 raised by delta; the front
// and back faces run through the ridge points 8 and 9.
cf::tools::PolygonSoup soup_with_ridge(double delta) {
  cf::tools::PolygonSoup s;
  s.points = {{0, 0, 0},   {10, 0, 0},   {10, 10, 0}, {0, 10, 0},         {0, 0, 10},
              {10, 0, 10}, {10, 10, 10}, {0, 10, 10}, {5, 0, 10 + delta}, {5, 10, 10 + delta}};
  s.polygons = {{0, 3, 2, 1},    {4, 8, 9, 7}, {8, 5, 6, 9}, {0, 1, 5, 8, 4},
                {2, 3, 7, 9, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  return s;
}

}  // namespace

TEST_CASE("the coplanarity tolerance decides whether a slightly bent facet joins a face",
          "[features]") {
  // The ridge box (soup_with_ridge). The tolerance is 1e-5 of the diagonal (17.3 mm), i.e.
  // 1.7e-4 mm.
  const double diag = std::sqrt(300.0);
  SECTION("below the tolerance: one top face, the ridge points are not features") {
    const double delta = 1e-7 * diag;
    const cf::Polyhedron m = cf::tools::model_from_soup(soup_with_ridge(delta), "ridge");
    CHECK(m.num_faces() == 6);
    CHECK(m.num_vertices() == 8);
    CHECK(m.num_edges() == 12);
    // The top plane is fitted through all six of its points, so its corners move onto it
    // by about delta / 3: far below the tolerance.
    for (const auto& p : soup_with_ridge(0).points)
      if (p.x() != 5) CHECK(find_vertex(m, p, delta) >= 0);
    check_invariants(m, 0);
  }
  SECTION("above the tolerance: two top faces and a ridge edge") {
    const cf::Polyhedron m = cf::tools::model_from_soup(soup_with_ridge(0.05), "ridge");
    CHECK(m.num_faces() == 7);
    CHECK(m.num_vertices() == 10);
    CHECK(m.num_edges() == 15);
    const cf::Edge* ridge = find_edge(m, {5, 0, 10.05}, {5, 10, 10.05});
    REQUIRE(ridge != nullptr);
    CHECK(ridge->convex);
    CHECK(ridge->dihedral == Approx(M_PI - 2 * std::atan(0.05 / 5)).epsilon(1e-12));
    check_invariants(m, 0);
  }
}

TEST_CASE("a coarse coplanarity tolerance merges bent facets into a planar polyhedron",
          "[features]") {
  // Every vertex of the result lies on its faces' planes to the polyhedron's own check
  // (1e-6 of its size; from_features throws otherwise), and moved by less than the bend.
  cf::tools::LoadOptions coarse;
  coarse.coplanar_rel_tol = 1e-3;  // 0.017 mm on these 17 mm models
  SECTION("a box's ridge of 0.005 mm: its corners, three faces each, move onto the new planes") {
    // The far corners of one roof half are 0.01 mm off the other half's plane: merged.
    const double delta = 0.005;
    const cf::tools::PolygonSoup s = soup_with_ridge(delta);
    const cf::Polyhedron m = cf::tools::model_from_soup(s, "ridge", coarse);
    CHECK(m.num_faces() == 6);
    CHECK(m.num_vertices() == 8);
    CHECK(m.num_edges() == 12);
    for (std::size_t i = 0; i < 8; ++i) CHECK(find_vertex(m, s.points[i], delta) >= 0);
    check_invariants(m, 0);
  }
  SECTION("a pyramid whose sides fold by 0.01 mm: four merged faces meet at the apex") {
    // Base 10 x 10, apex (5, 5, 10); each side split in two triangles at its base edge's
    // midpoint, pushed 0.01 mm outward. Each merged side is planar only to 0.01 mm, and the
    // four planes fitted through them meet in no one point: the apex is placed by refitting
    // the planes through the moved corners and moving them again (mesh_features.cpp,
    // planarize).
    const double delta = 0.01;
    cf::tools::PolygonSoup s;
    s.points = {{0, 0, 0},      {10, 0, 0},         {10, 10, 0},        {0, 10, 0},    {5, 5, 10},
                {5, -delta, 0}, {10 + delta, 5, 0}, {5, 10 + delta, 0}, {-delta, 5, 0}};
    s.polygons = {{0, 8, 3, 7, 2, 6, 1, 5},  // base, seen from below
                  {0, 5, 4},
                  {5, 1, 4},
                  {1, 6, 4},
                  {6, 2, 4},
                  {2, 7, 4},
                  {7, 3, 4},
                  {3, 8, 4},
                  {8, 0, 4}};
    cf::tools::LoadOptions coarser;
    coarser.coplanar_rel_tol = 3e-3;  // 0.05 mm: a side's corners are 0.02 mm off one half's plane
    const cf::Polyhedron m = cf::tools::model_from_soup(s, "pyramid", coarser);
    CHECK(m.num_faces() == 5);
    CHECK(m.num_vertices() == 5);
    CHECK(m.num_edges() == 8);
    for (std::size_t i = 0; i < 5; ++i) CHECK(find_vertex(m, s.points[i], delta) >= 0);
    check_invariants(m, 0);
    // With the default tolerance the folds stay: four sides of two faces each.
    CHECK(cf::tools::model_from_soup(s, "pyramid").num_faces() == 9);
  }
  SECTION("a 64-gon prism: coarser polygons, each side face turning at most the crease angle") {
    // Radius 10 mm, height 5 mm (diagonal 22.9 mm); neighbouring sides turn by 5.6 degrees.
    const cf::tools::PolygonSoup s = ngon_prism(64, 10, 5);
    CHECK(cf::tools::model_from_soup(s, "prism").num_faces() == 66);
    cf::tools::LoadOptions o;
    o.coplanar_rel_tol = 2e-2;  // 0.46 mm: runs of sides merge
    o.crease_angle_deg = 180;   // no bound by angle: runs as long as the distance allows
    const cf::Polyhedron wide = cf::tools::model_from_soup(s, "prism", o);
    CHECK(wide.num_faces() == 15);  // a 13-gon prism
    check_invariants(wide, 0);
    // The default crease angle, 10 degrees: a side joins a face only within 10 degrees of its
    // normal, so a face holds at most 4 sides (the outer ones 3 x 5.6 / 2 = 8.4 degrees off
    // the middle), no wider than the chord of 4 sides.
    o.crease_angle_deg = cf::tools::LoadOptions{}.crease_angle_deg;
    const cf::Polyhedron m = cf::tools::model_from_soup(s, "prism", o);
    CHECK(m.num_faces() > 15);
    CHECK(m.num_faces() <= 66);
    check_invariants(m, 0);
    const double chord4 = 2 * 10 * std::sin(4 * M_PI / 64);
    for (const cf::Face& f : m.faces())
      if (std::abs(f.normal.z()) < 0.5) CHECK(widest_span(m, f) <= chord4 + 1e-9);
    // Below the angle between two sides nothing merges.
    o.crease_angle_deg = 5;
    CHECK(cf::tools::model_from_soup(s, "prism", o).num_faces() == 66);
    // At the coarsest tolerance a merged side's edge with the top would bend: those sides are
    // grown again at the default tolerance, and the result is still a polyhedron.
    o.coplanar_rel_tol = 0.1;
    o.crease_angle_deg = 180;
    const cf::Polyhedron coarsest = cf::tools::model_from_soup(s, "prism", o);
    check_invariants(coarsest, 0);
    CHECK(coarsest.num_faces() <= 66);
  }
}

TEST_CASE("any coplanarity tolerance and crease angle give a polyhedron near the file's facets",
          "[features]") {
  // Curved surfaces are where merging facets into planar faces fails: a boundary between two
  // merged faces that bends, a face no plane fits. Whatever the options, the loader returns a
  // valid polyhedron (from_features checks it) whose faces lie within the reported deviation of
  // every vertex of the file.
  struct Case {
    std::string name;
    cf::tools::PolygonSoup soup;
    int genus;
  };
  const std::vector<Case> cases = {{"sphere", uv_sphere(24, 12, 10), 0},
                                   {"torus", torus(32, 16, 10, 3), 1},
                                   {"prism", ngon_prism(64, 10, 5), 0}};
  for (const Case& c : cases)
    for (double tol : {1e-5, 1e-3, 1e-2, 0.1})
      for (double crease : {0.0, 10.0, 180.0}) {
        CAPTURE(c.name, tol, crease);
        cf::tools::LoadOptions o;
        o.coplanar_rel_tol = tol;
        o.crease_angle_deg = crease;
        const cf::tools::MeasuredModel mm = cf::tools::measured_model_from_soup(c.soup, c.name, o);
        check_invariants(mm.model, c.genus);
        // 1e-9 mm: rounding of the distances (models of 20-30 mm).
        for (const Vec3& p : c.soup.points)
          CHECK(surface_distance(mm.model, p) <= mm.deviation_mm + 1e-9);
        // A face is grown again finer when it lies further than twice the tolerance from its
        // facets (docs/features.md, "Creases").
        CHECK(mm.deviation_mm <= 2 * tol * soup_diagonal(c.soup) + 1e-9);
        if (tol == 1e-5) CHECK(mm.deviation_mm < 1e-9);  // exact facets, nothing merged off-plane
      }
}

#ifdef CF_PUBLIC_MODELS
TEST_CASE("the public curved models: faces at three crease angles", "[features][public]") {
  // docs/features.md, "Creases": faces/edges/vertices and reflex edges of the three.js emerald
  // and CGAL's U at the default tolerance and at 1e-2 with crease angles of 2, 10 and 30
  // degrees. The counts are the loader's exact output (a change to the merging rules changes
  // them, and the table with them).
  struct Row {
    const char* file;
    double tol, crease;
    std::size_t faces, edges, vertices;
    int reflex;
  };
  const Row rows[] = {{"threejs_emerald.obj", 1e-5, 10, 94, 164, 72, 18},
                      {"threejs_emerald.obj", 1e-2, 2, 84, 152, 70, 14},
                      {"threejs_emerald.obj", 1e-2, 10, 63, 125, 64, 6},
                      {"threejs_emerald.obj", 1e-2, 30, 39, 89, 52, 0},
                      {"cgal_u.off", 1e-5, 10, 78, 160, 84, 63},
                      {"cgal_u.off", 1e-2, 2, 64, 142, 80, 52},
                      {"cgal_u.off", 1e-2, 10, 26, 72, 48, 17},
                      {"cgal_u.off", 1e-2, 30, 19, 51, 34, 10}};
  for (const Row& r : rows) {
    CAPTURE(r.file, r.tol, r.crease);
    cf::tools::LoadOptions o;
    o.coplanar_rel_tol = r.tol;
    o.crease_angle_deg = r.crease;
    const std::string path = std::string(CF_PUBLIC_MODELS) + "/" + r.file;
    const cf::tools::MeasuredModel mm = cf::tools::load_measured_model(path, o);
    CHECK(mm.model.num_faces() == r.faces);
    CHECK(mm.model.num_edges() == r.edges);
    CHECK(mm.model.num_vertices() == r.vertices);
    CHECK(count_reflex(mm.model) == r.reflex);
    check_invariants(mm.model, 0);
    // Within twice the tolerance of the file's facets (docs/features.md, "Creases").
    const double diag = soup_diagonal(cf::tools::read_polygon_soup(path));
    CHECK(mm.deviation_mm <= 2 * r.tol * diag);
  }
}
#endif

TEST_CASE("a finely tessellated sphere loads: faces that would bend a boundary keep their facets",
          "[features]") {
  // 20,000 facets; near the poles neighbouring triangles are within the default tolerance of
  // one plane, but a face merged from them would bend where it meets the next ring.
  const cf::tools::PolygonSoup s = uv_sphere(100, 100, 10);
  cf::tools::LoadOptions o;
  o.check_self_intersection = false;  // a convex sphere; the check takes seconds at this size
  const cf::Polyhedron m = cf::tools::model_from_soup(s, "sphere", o);
  check_invariants(m, 0);
  // The quads of two coplanar triangles merge (9,800 faces); of the 200 triangles of the two
  // polar fans, pairs merge where that bends no boundary.
  CHECK(m.num_faces() > 98 * 100);
  CHECK(m.num_faces() <= 98 * 100 + 2 * 100);
}

// --- schema and command line ----------------------------------------------------------------

namespace {

struct Run {
  int status = -1;
  std::string out;
};

// Runs a command through the shell, capturing stdout (stderr too when asked).
Run run(const std::string& cmd) {
  Run r;
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = ::pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

std::shared_ptr<valijson::Schema> load_schema() {
  std::ifstream in(std::string(CF_SOURCE_DIR) + "/schemas/model.schema.json");
  REQUIRE(in.good());
  const nlohmann::json doc = nlohmann::json::parse(in);
  auto schema = std::make_shared<valijson::Schema>();
  valijson::SchemaParser parser;
  valijson::adapters::NlohmannJsonAdapter adapter(doc);
  parser.populateSchema(adapter, *schema);
  return schema;
}

std::string validate(const valijson::Schema& schema, const nlohmann::json& j) {
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter adapter(j);
  if (validator.validate(schema, adapter, &results)) return "";
  std::string why;
  valijson::ValidationResults::Error e;
  while (results.popError(e)) {
    std::string ctx;
    for (const auto& c : e.context) ctx += c;
    why += ctx + ": " + e.description + "; ";
  }
  return why;
}

}  // namespace

TEST_CASE("cfgen --features output of every default model validates against the schema",
          "[cli][schema]") {
  const auto schema = load_schema();
  for (const char* name : {"cube.off", "l_block.off", "l_block_tri.obj", "corner_block.off",
                           "peg.off", "hole_block.off"}) {
    INFO(name);
    const Run r = run(quoted(CF_CFGEN) + " --features " + quoted(kData + name));
    REQUIRE(r.status == 0);
    nlohmann::json j = nlohmann::json::parse(r.out);
    CHECK(validate(*schema, j) == "");
    // How the model was read: the default options; exact files whose faces lie on their
    // fitted planes (a deviation of rounding, 1e-12 mm on these 10-120 mm models).
    const nlohmann::json& measures = j.at("measures");
    CHECK(measures.at("coplanar_rel_tol") == cf::tools::LoadOptions{}.coplanar_rel_tol);
    CHECK(measures.at("crease_angle_deg") == cf::tools::LoadOptions{}.crease_angle_deg);
    CHECK(measures.at("deviation_mm").get<double>() < 1e-12);
    // The printed model is the loaded model.
    j.erase("measures");
    CHECK(j.dump(2) == cf::to_json(load_model(kData + name)));
  }
}

TEST_CASE("the schema rejects malformed model objects", "[schema]") {
  const auto schema = load_schema();
  nlohmann::json good = nlohmann::json::parse(cf::to_json(load_model(kData + "cube.off")));
  CHECK(validate(*schema, good) == "");
  nlohmann::json j = good;
  j.erase("faces");
  CHECK(validate(*schema, j) != "");
  j = good;
  j["edges"][0] = {1, 2, 3};
  CHECK(validate(*schema, j) != "");
  j = good;
  j["vertices"][0] = {1, 2};
  CHECK(validate(*schema, j) != "");
  j = good;
  j["faces"][0]["loops"][0] = {0, 1};
  CHECK(validate(*schema, j) != "");
  j = good;
  j["edges"][0][0] = -1;
  CHECK(validate(*schema, j) != "");
}

TEST_CASE("cfgen reports bad input in one line with a non-zero status", "[cli]") {
  const std::string cfgen = quoted(CF_CFGEN);
  SECTION("missing model") {
    const Run r = run(cfgen + " --features /nonexistent/model.off 2>&1");
    CHECK(r.status == 1);
    CHECK(r.out == "cfgen: loading '/nonexistent/model.off': cannot open file: no such file\n");
  }
  SECTION("broken model") {
    const std::string bad = write_file("open.off",
                                       "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                       "3 0 2 1\n3 0 1 3\n3 0 3 2\n");
    const Run r = run(cfgen + " --features " + quoted(bad) + " 2>&1");
    CHECK(r.status == 1);
    CHECK_THAT(r.out, Catch::StartsWith("cfgen: loading '" + bad + "': open boundary: edge"));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  SECTION("bad option") {
    const Run r = run(cfgen + " --no-such-option 2>&1");
    CHECK(r.status == 2);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  SECTION("generation without -o") {
    const Run r = run(cfgen + " a.off b.off 2>&1");
    CHECK(r.status == 2);
    CHECK(r.out == "cfgen: missing -o GRAPH.json\n");
  }
  SECTION("--help") {
    const Run r = run(cfgen + " --help");
    CHECK(r.status == 0);
    CHECK_THAT(r.out, Catch::Contains("--features"));
  }
}

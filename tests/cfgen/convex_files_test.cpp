// Property test of cfgen's graphs (run_generate, tools/cfgen/generate.hpp) on convex pairs read
// from files written the way real tools write them. For two convex polytopes the CF graph is
// known in closed form: every CF has exactly one PC, and every face-face, edge-face,
// face-edge, vertex-face, face-vertex and edge-edge pair of elements is exactly one CF. So
// with F, E, V the faces, edges and vertices of each solid (a face being a maximal planar
// polygon, however the file triangulates it):
//   f-f = FA*FB, e-f = EA*FB, f-e = FA*EB, v-f = VA*FB, f-v = FA*VB, e-e = EA*EB.
// The polytopes are built here from scratch (half-space intersection), moved by a random
// rigid motion and written as binary STL (float32), ASCII STL, OBJ, PLY or OFF at 6, 10 or 17
// significant digits; nothing of the generator's or the loader's is used to count them.

#include "cfgen/generate.hpp"
#include "scratch.hpp"

#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <locale>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace {

using Vec = Eigen::Vector3d;

// ---- Convex polytopes as intersections of half-spaces --------------------------------------

struct Plane {
  Vec n;     // outward unit normal
  double d;  // the half-space n.x <= d
};

// A convex polytope: vertices, faces as loops counter-clockwise seen from outside (one face a
// plane: a maximal planar polygon), each face's outward unit normal, and the edges.
struct Polytope {
  std::vector<Vec> v;
  std::vector<std::vector<int>> faces;
  std::vector<Vec> normals;
  std::vector<std::array<int, 2>> edges;
  double diameter = 0;
  int num_faces() const { return static_cast<int>(faces.size()); }
  int num_edges() const { return static_cast<int>(edges.size()); }
  int num_vertices() const { return static_cast<int>(v.size()); }
};

// What a polytope must satisfy to be drawn: no feature the generator could take for another.
constexpr double kMinFromFlatDeg = 5;      // every dihedral angle at least this far from 180 deg
constexpr double kMinEdgeFraction = 0.05;  // every edge at least this times the diameter
constexpr double kDegenerateRel = 1e-6;    // no 4th plane this close (x diameter) to a vertex
// Every face has 4 or more vertices (the "faces of 4 or more vertices"), on every
// face: about 1 draw in 10 passes all the limits, so none needs to be let off.
constexpr std::size_t kMinFaceCorners = 4;

// The intersection of the half-spaces, or nothing (`why` says what) when it is unbounded,
// degenerate or breaks one of the limits above.
std::optional<Polytope> intersect(const std::vector<Plane>& planes, std::string& why) {
  const int n = static_cast<int>(planes.size());
  double scale = 0;
  for (const Plane& p : planes) scale = std::max(scale, std::abs(p.d));
  // Every point where three planes meet inside all the half-spaces is a vertex.
  std::vector<Vec> pts;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) {
        Eigen::Matrix3d M;
        M.row(0) = planes[i].n.transpose();
        M.row(1) = planes[j].n.transpose();
        M.row(2) = planes[k].n.transpose();
        if (std::abs(M.determinant()) < 1e-6) continue;  // (nearly) parallel: no corner
        const Vec x = M.fullPivLu().solve(Vec(planes[i].d, planes[j].d, planes[k].d));
        bool inside = true;
        for (const Plane& p : planes) inside = inside && p.n.dot(x) <= p.d + 1e-9 * scale;
        if (inside) pts.push_back(x);
      }
  if (pts.size() < 4) return why = "too few vertices", std::nullopt;
  Polytope P;
  for (const Vec& a : pts)
    for (const Vec& b : pts) P.diameter = std::max(P.diameter, (a - b).norm());
  // The planes through each vertex: exactly 3, so each vertex came from one triple only.
  std::vector<std::vector<int>> on(pts.size());
  for (std::size_t c = 0; c < pts.size(); ++c) {
    for (int i = 0; i < n; ++i)
      if (std::abs(planes[i].n.dot(pts[c]) - planes[i].d) <= kDegenerateRel * P.diameter)
        on[c].push_back(i);
    if (on[c].size() != 3) return why = "more than 3 planes at a vertex", std::nullopt;
  }
  P.v = pts;
  // Edges: two vertices on two common planes.
  std::vector<int> degree(pts.size(), 0);
  std::vector<std::array<int, 2>> edge_planes;
  for (std::size_t a = 0; a < pts.size(); ++a)
    for (std::size_t b = a + 1; b < pts.size(); ++b) {
      std::vector<int> common;
      std::set_intersection(on[a].begin(), on[a].end(), on[b].begin(), on[b].end(),
                            std::back_inserter(common));
      if (common.size() < 2) continue;
      if (common.size() > 2) return why = "coincident vertices", std::nullopt;
      P.edges.push_back({static_cast<int>(a), static_cast<int>(b)});
      edge_planes.push_back({common[0], common[1]});
      ++degree[a];
      ++degree[b];
    }
  // Bounded: every vertex has its three edges (an unbounded region has rays instead).
  for (int d : degree)
    if (d != 3) return why = "unbounded", std::nullopt;
  // Faces: the planes through 3 or more vertices, ordered counter-clockwise about the normal.
  for (int i = 0; i < n; ++i) {
    std::vector<int> f;
    for (std::size_t c = 0; c < pts.size(); ++c)
      if (std::find(on[c].begin(), on[c].end(), i) != on[c].end()) f.push_back(static_cast<int>(c));
    if (f.empty()) continue;  // a redundant half-space
    if (f.size() < 3) return why = "a plane touching only an edge", std::nullopt;
    if (f.size() < kMinFaceCorners) return why = "a face of fewer than 4 vertices", std::nullopt;
    Vec centre = Vec::Zero();
    for (int c : f) centre += pts[c];
    centre /= static_cast<double>(f.size());
    const Vec& nrm = planes[i].n;
    const Vec u = nrm.unitOrthogonal(), w = nrm.cross(u);  // (u, w, nrm) right-handed
    auto angle = [&](int c) {
      return std::atan2((pts[c] - centre).dot(w), (pts[c] - centre).dot(u));
    };
    std::sort(f.begin(), f.end(), [&](int a, int b) { return angle(a) < angle(b); });
    P.faces.push_back(f);
    P.normals.push_back(nrm);
  }
  // Every side of every face is an edge, and Euler's formula holds (a sphere).
  for (const auto& f : P.faces)
    for (std::size_t k = 0; k < f.size(); ++k) {
      const int a = f[k], b = f[(k + 1) % f.size()];
      const std::array<int, 2> e{std::min(a, b), std::max(a, b)};
      if (std::find(P.edges.begin(), P.edges.end(), e) == P.edges.end())
        return why = "a face side that is no edge", std::nullopt;
    }
  if (P.num_vertices() - P.num_edges() + P.num_faces() != 2) return why = "Euler", std::nullopt;
  for (std::size_t e = 0; e < P.edges.size(); ++e) {
    if ((pts[P.edges[e][0]] - pts[P.edges[e][1]]).norm() < kMinEdgeFraction * P.diameter)
      return why = "a short edge", std::nullopt;
    // The angle between the two faces' normals is 180 deg minus the dihedral angle.
    const double c = planes[edge_planes[e][0]].n.dot(planes[edge_planes[e][1]].n);
    if (std::acos(std::min(1.0, c)) < kMinFromFlatDeg * M_PI / 180)
      return why = "a nearly flat edge", std::nullopt;
  }
  return P;
}

// A random convex polytope: 8 to 11 planes tangent to a sphere of radius 15 to 40 mm about
// the origin, with random normals at least 35 deg apart, each plane pushed out by up to 15% of
// the radius; drawn again until it passes every limit of intersect() and has every vertex
// within 2.2 radii of the origin (no long spikes: a diameter of about 3.3 radii, so that the
// rounding of the files is not small against the solid).
Polytope random_polytope(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> gauss;
  for (int attempt = 0; attempt < 100000; ++attempt) {
    const int n = std::uniform_int_distribution<int>(8, 11)(rng);
    const double radius = 15 + 25 * uniform(rng);
    std::vector<Plane> planes;
    for (int draws = 0; static_cast<int>(planes.size()) < n && draws < 10000; ++draws) {
      const Vec m = Vec(gauss(rng), gauss(rng), gauss(rng)).normalized();
      bool apart = true;
      for (const Plane& p : planes) apart = apart && p.n.dot(m) <= std::cos(35 * M_PI / 180);
      if (apart) planes.push_back({m, radius * (1 + 0.15 * uniform(rng))});
    }
    std::string why;
    std::optional<Polytope> P = intersect(planes, why);
    if (!P) continue;
    double reach = 0;
    for (const Vec& x : P->v) reach = std::max(reach, x.norm());
    if (reach <= 2.2 * radius) return *P;
  }
  FAIL("no polytope drawn in 100000 attempts");
  return {};
}

// P moved by a random rotation (uniform) and a translation of length up to 100 mm.
Polytope random_motion(Polytope P, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform(0, 1);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(gauss(rng), gauss(rng), gauss(rng), gauss(rng)).normalized().matrix();
  const Vec t = Vec(gauss(rng), gauss(rng), gauss(rng)).normalized() * (100 * uniform(rng));
  for (Vec& x : P.v) x = R * x + t;
  for (Vec& m : P.normals) m = R * m;
  return P;
}

// True when every face loop of P turns counter-clockwise about its outward normal (Newell's
// normal of the loop along it): a check of this file's construction, not of the generator.
bool outward(const Polytope& P) {
  for (int f = 0; f < P.num_faces(); ++f) {
    Vec newell = Vec::Zero();
    const auto& loop = P.faces[f];
    for (std::size_t k = 0; k < loop.size(); ++k)
      newell += P.v[loop[k]].cross(P.v[loop[(k + 1) % loop.size()]]);
    if (newell.normalized().dot(P.normals[f]) < 1 - 1e-9) return false;
  }
  return true;
}

// ---- Files written the way real tools write them -------------------------------------------

enum class Format { kStlBinary, kStlAscii, kObj, kPly, kOff };

const char* format_name(Format f) {
  switch (f) {
    case Format::kStlBinary:
      return "binary STL";
    case Format::kStlAscii:
      return "ASCII STL";
    case Format::kObj:
      return "OBJ";
    case Format::kPly:
      return "PLY";
    case Format::kOff:
      return "OFF";
  }
  return "?";
}

const char* extension(Format f) {
  switch (f) {
    case Format::kStlBinary:
    case Format::kStlAscii:
      return ".stl";
    case Format::kObj:
      return ".obj";
    case Format::kPly:
      return ".ply";
    case Format::kOff:
      return ".off";
  }
  return "";
}

// A stream writing numbers with `digits` significant digits (%g style), in the C locale.
std::ostringstream number_stream(int digits) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << std::setprecision(digits);
  return os;
}

void put_point(std::ostream& os, const Vec& x) { os << x.x() << ' ' << x.y() << ' ' << x.z(); }

// The triangles of P's faces (fans: the faces are convex), counter-clockwise from outside,
// each with its face's index.
std::vector<std::pair<int, std::array<int, 3>>> triangles(const Polytope& P) {
  std::vector<std::pair<int, std::array<int, 3>>> t;
  for (int f = 0; f < P.num_faces(); ++f)
    for (std::size_t k = 1; k + 1 < P.faces[f].size(); ++k)
      t.push_back({f, {P.faces[f][0], P.faces[f][k], P.faces[f][k + 1]}});
  return t;
}

void put_le32(std::string& out, std::uint32_t x) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((x >> (8 * i)) & 0xff));
}

void put_float(std::string& out, double x) {
  const float f = static_cast<float>(x);
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  put_le32(out, bits);
}

// The bytes of P in `format`, numbers at `digits` significant digits (binary STL: float32).
std::string mesh_text(const Polytope& P, Format format, int digits, const std::string& name) {
  if (format == Format::kStlBinary) {
    std::string out = "binary STL written by convex_files_test " + name;
    out.resize(80, ' ');
    const auto tris = triangles(P);
    put_le32(out, static_cast<std::uint32_t>(tris.size()));
    for (const auto& [f, t] : tris) {
      for (int i = 0; i < 3; ++i) put_float(out, P.normals[f][i]);
      for (int c : t)
        for (int i = 0; i < 3; ++i) put_float(out, P.v[c][i]);
      out.append(2, '\0');  // attribute byte count
    }
    return out;
  }
  std::ostringstream os = number_stream(digits);
  // PLY's ascii body and OFF's after their headers: a point a line, then each face as its
  // vertex count and indices.
  auto points_then_counted_faces = [&] {
    for (const Vec& x : P.v) {
      put_point(os, x);
      os << '\n';
    }
    for (const auto& f : P.faces) {
      os << f.size();
      for (int c : f) os << ' ' << c;
      os << '\n';
    }
  };
  switch (format) {
    case Format::kStlAscii:  // as most exporters: %e with digits - 1 decimals
      os << std::scientific << std::setprecision(digits - 1) << "solid " << name << '\n';
      for (const auto& [f, t] : triangles(P)) {
        os << "  facet normal ";
        put_point(os, P.normals[f]);
        os << "\n    outer loop\n";
        for (int c : t) {
          os << "      vertex ";
          put_point(os, P.v[c]);
          os << '\n';
        }
        os << "    endloop\n  endfacet\n";
      }
      os << "endsolid " << name << '\n';
      break;
    case Format::kObj:
      os << "# written by convex_files_test\no " << name << '\n';
      for (const Vec& x : P.v) {
        os << "v ";
        put_point(os, x);
        os << '\n';
      }
      for (const auto& f : P.faces) {
        os << 'f';
        for (int c : f) os << ' ' << c + 1;
        os << '\n';
      }
      break;
    case Format::kPly: {
      // 6 digits: single precision, as most exporters; more: double.
      const char* type = digits <= 7 ? "float" : "double";
      os << "ply\nformat ascii 1.0\ncomment written by convex_files_test\nelement vertex "
         << P.num_vertices() << "\nproperty " << type << " x\nproperty " << type << " y\nproperty "
         << type << " z\nelement face " << P.num_faces()
         << "\nproperty list uchar int vertex_indices\nend_header\n";
      points_then_counted_faces();
      break;
    }
    case Format::kOff:
      os << "OFF\n" << P.num_vertices() << ' ' << P.num_faces() << " 0\n";
      points_then_counted_faces();
      break;
    case Format::kStlBinary:
      break;
  }
  return os.str();
}

// ---- The cases -----------------------------------------------------------------------------

struct Case {
  Format a, b;
  int digits;  // significant digits of the text formats (binary STL: float32 whatever this is)
  std::uint64_t seed;
};

// Every format at least once, every digit count at least once, binary STL three times, and
// two cases at 17 digits without binary STL (faces planar to double rounding): those pass
// whenever the generator is right on exact input.
const Case kCases[] = {
    {Format::kOff, Format::kOff, 17, 101},      {Format::kStlAscii, Format::kPly, 17, 102},
    {Format::kStlBinary, Format::kObj, 6, 103}, {Format::kObj, Format::kStlBinary, 17, 104},
    {Format::kStlAscii, Format::kPly, 10, 105}, {Format::kPly, Format::kOff, 10, 106},
    {Format::kObj, Format::kOff, 10, 107},      {Format::kStlAscii, Format::kStlBinary, 6, 108},
};

// The PC types, A's element kind then B's.
const char* const kTypes[] = {"f-f", "e-f", "f-e", "v-f", "f-v", "e-e"};

int element_count(const Polytope& P, char kind) {
  return kind == 'f' ? P.num_faces() : kind == 'e' ? P.num_edges() : P.num_vertices();
}

nlohmann::json generate(const std::string& a, const std::string& b, const std::string& out) {
  cf::tools::GenerateArgs args;
  args.a_path = a;
  args.b_path = b;
  args.out_path = out;
  args.threads = 2;
  args.quiet = true;
  REQUIRE(cf::tools::run_generate(args) == 0);
  std::ifstream in(out);
  return nlohmann::json::parse(in);
}

std::int64_t count_or_zero(const nlohmann::json& object, const std::string& key) {
  return object.contains(key) ? object.at(key).get<std::int64_t>() : 0;
}

}  // namespace

TEST_CASE("a convex pair read from any format has the closed-form CF graph", "[convex_files]") {
  for (const Case& c : kCases) {
    DYNAMIC_SECTION(format_name(c.a) << " / " << format_name(c.b) << ", " << c.digits
                                     << " digits, seed " << c.seed) {
      std::mt19937_64 rng(c.seed);
      const Polytope A = random_motion(random_polytope(rng), rng);
      const Polytope B = random_motion(random_polytope(rng), rng);
      REQUIRE(outward(A));
      REQUIRE(outward(B));
      const std::string tag = "s" + std::to_string(c.seed);
      const std::string a_path = cf::test::write_file(tag + "_A" + extension(c.a),
                                                      mesh_text(A, c.a, c.digits, tag + "_A"));
      const std::string b_path = cf::test::write_file(tag + "_B" + extension(c.b),
                                                      mesh_text(B, c.b, c.digits, tag + "_B"));
      INFO("A: " << A.num_faces() << " faces, " << A.num_edges() << " edges, " << A.num_vertices()
                 << " vertices; B: " << B.num_faces() << " faces, " << B.num_edges() << " edges, "
                 << B.num_vertices() << " vertices");
      const nlohmann::json g =
          generate(a_path, b_path, (cf::test::scratch() / (tag + ".json")).string());

      // The loader saw the solids built here (coplanar triangles merged into one face).
      for (const auto& [key, P] : {std::pair<const char*, const Polytope*>{"A", &A}, {"B", &B}}) {
        const nlohmann::json& m = g.at("models").at(key);
        INFO("model " << key);
        CHECK(m.at("faces").size() == P->faces.size());
        CHECK(m.at("edges").size() == P->edges.size());
        CHECK(m.at("vertices").size() == P->v.size());
      }

      // The closed form.
      std::map<std::string, std::int64_t> expected;
      for (const char* type : kTypes)
        expected[type] = std::int64_t{element_count(A, type[0])} * element_count(B, type[2]);
      std::int64_t total = 0;
      for (const auto& [type, n] : expected) total += n;

      const nlohmann::json& stats = g.at("stats");
      // Only single-PC CFs.
      CHECK(count_or_zero(stats.at("cfs_by_pc_count"), "1") == total);
      for (const auto& [k, n] : stats.at("cfs_by_pc_count").items()) {
        INFO("CFs of " << k << " PCs");
        if (k != "1") CHECK(n.get<std::int64_t>() == 0);
      }
      // Each type's count exactly.
      const nlohmann::json& by_type = stats.at("pcs_by_type");
      for (const char* type : kTypes) {
        INFO(type << " PCs: expected " << expected[type] << ", got "
                  << count_or_zero(by_type, type));
        CHECK(count_or_zero(by_type, type) == expected[type]);
      }
      for (const auto& [k, n] : by_type.items()) {
        INFO("PC type " << k);
        if (!expected.count(k)) CHECK(n.get<std::int64_t>() == 0);
      }
      // And the CFs themselves: every pair of elements exactly once, each its own CF.
      std::size_t multi = 0, out_of_range = 0, repeated = 0;
      std::set<std::tuple<std::string, int, int>> seen;
      for (const nlohmann::json& cf : g.at("cfs")) {
        if (cf.at("pcs").size() != 1) {
          ++multi;
          continue;
        }
        const nlohmann::json& pc = cf.at("pcs")[0];
        const std::string type = pc.at("type").get<std::string>();
        const int a = pc.at("a").get<int>(), b = pc.at("b").get<int>();
        if (!expected.count(type) || a < 0 || a >= element_count(A, type[0]) || b < 0 ||
            b >= element_count(B, type[2])) {
          ++out_of_range;
          continue;
        }
        if (!seen.insert({type, a, b}).second) ++repeated;
      }
      CHECK(multi == 0);
      CHECK(out_of_range == 0);
      CHECK(repeated == 0);
      for (const char* type : kTypes) {
        std::ostringstream missing;  // the first few pairs without a CF, for the message
        int listed = 0;
        for (int a = 0; a < element_count(A, type[0]) && listed < 8; ++a)
          for (int b = 0; b < element_count(B, type[2]) && listed < 8; ++b)
            if (!seen.count({type, a, b})) {
              missing << ' ' << a << ':' << b;
              ++listed;
            }
        INFO(type << " pairs without a CF (A:B, first 8):" << missing.str());
        CHECK(std::count_if(seen.begin(), seen.end(), [&](const auto& s) {
                return std::get<0>(s) == type;
              }) == expected[type]);
      }
    }
  }
}

TEST_CASE("coplanar triangles written at 6 digits merge into their face", "[convex_files]") {
  // ASCII STL at 6 significant digits puts a triangle's corners up to about 5e-7 of the
  // diagonal off their face's plane; a thin triangle's own normal is off by far more. Loading
  // only: the faces, edges and vertices of 150 solids, each moved and written so.
  int split = 0;
  for (std::uint64_t seed = 1000; seed < 1150; ++seed) {
    std::mt19937_64 rng(seed);
    const Polytope P = random_motion(random_polytope(rng), rng);
    const std::string tag = "m" + std::to_string(seed);
    const cf::Polyhedron m = cf::tools::load_model(
        cf::test::write_file(tag + ".stl", mesh_text(P, Format::kStlAscii, 6, tag)));
    INFO("seed " << seed);
    CHECK(m.num_faces() == P.faces.size());
    CHECK(m.num_edges() == P.edges.size());
    CHECK(m.num_vertices() == P.v.size());
    split += m.num_faces() != P.faces.size();
  }
  CHECK(split == 0);
}

// Model input: every reader (OFF, OBJ, STL ascii and binary, PLY) and every rejection path of
// tools/mesh/model_loader, with the messages checked.

#include "mesh/model_loader.hpp"

#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;
using cf::tools::load_model;

namespace {

// Values computed from small exact integers: a few ulps of 1000.
constexpr double kExact = 1e-12;

const std::string kModels = std::string(CF_TEST_DATA_DIR) + "/models/";

using cf::test::scratch;
using cf::test::write_file;

// The 10 mm cube of tests/data/models/cube.off as points and quads.
const std::vector<cf::Vec3> kCubeV = {{0, 0, 0},  {10, 0, 0},  {10, 10, 0},  {0, 10, 0},
                                      {0, 0, 10}, {10, 0, 10}, {10, 10, 10}, {0, 10, 10}};
const std::vector<std::vector<int>> kCubeF = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                              {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};

std::string off_text(const std::vector<cf::Vec3>& v, const std::vector<std::vector<int>>& f) {
  std::ostringstream os;
  os << "OFF\n" << v.size() << ' ' << f.size() << " 0\n";
  for (const auto& p : v) os << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& poly : f) {
    os << poly.size();
    for (int i : poly) os << ' ' << i;
    os << '\n';
  }
  return os.str();
}

std::vector<std::vector<int>> triangulate(const std::vector<std::vector<int>>& quads) {
  std::vector<std::vector<int>> t;
  for (const auto& q : quads) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  return t;
}

// Binary STL: 80-byte header, count, then per triangle normal, 3 corners, attribute.
std::string binary_stl(const std::vector<cf::Vec3>& v, const std::vector<std::vector<int>>& tris,
                       const std::string& header) {
  std::string s(80, ' ');
  std::memcpy(&s[0], header.data(), std::min<std::size_t>(header.size(), 80));
  auto put = [&s](const void* p, std::size_t n) { s.append(static_cast<const char*>(p), n); };
  const std::uint32_t n = static_cast<std::uint32_t>(tris.size());
  put(&n, 4);
  for (const auto& t : tris) {
    const cf::Vec3 nrm = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).normalized();
    for (int k = 0; k < 3; ++k) {
      const float x = static_cast<float>(nrm[k]);
      put(&x, 4);
    }
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

// Checks a loaded 10 mm cube: counts, volume, and that its vertices are the cube's corners.
void check_cube(const cf::Polyhedron& m) {
  CHECK(m.num_vertices() == 8);
  CHECK(m.num_edges() == 12);
  CHECK(m.num_faces() == 6);
  CHECK(m.volume() == Approx(1000).epsilon(kExact));
  for (const cf::Vertex& v : m.vertices()) {
    bool corner = false;
    for (const auto& c : kCubeV) corner = corner || (v.p - c).norm() < kExact;
    CHECK(corner);
  }
  for (const cf::Face& f : m.faces()) {
    CHECK(f.loops.size() == 1);
    CHECK(f.loops[0].size() == 4);
    CHECK(f.area == Approx(100).epsilon(kExact));
  }
}

}  // namespace

TEST_CASE("every reader loads the cube", "[mesh_io]") {
  SECTION("OFF, polygonal") { check_cube(load_model(kModels + "cube.off")); }
  SECTION("OFF, triangulated") { check_cube(load_model(kModels + "cube_tri.off")); }
  SECTION("OBJ with texture and normal references") {
    check_cube(load_model(kModels + "cube.obj"));
  }
  SECTION("STL ascii") { check_cube(load_model(kModels + "cube_ascii.stl")); }
  SECTION("STL binary") {
    check_cube(load_model(
        write_file("cube_binary.stl", binary_stl(kCubeV, triangulate(kCubeF), "binary cube"))));
  }
  SECTION("STL binary whose header starts with 'solid'") {
    // Some exporters do this; the reader falls back from ascii to binary.
    check_cube(load_model(write_file("cube_solid_header.stl",
                                     binary_stl(kCubeV, triangulate(kCubeF), "solid cube"))));
  }
  SECTION("PLY ascii, polygonal") { check_cube(load_model(kModels + "cube.ply")); }
  SECTION("PLY binary little-endian, polygonal") {
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\n"
        "property float y\nproperty float z\nelement face 6\n"
        "property list uchar int vertex_indices\nend_header\n";
    for (const auto& p : kCubeV)
      for (int k = 0; k < 3; ++k) {
        const float x = static_cast<float>(p[k]);
        ply.append(reinterpret_cast<const char*>(&x), 4);
      }
    for (const auto& q : kCubeF) {
      ply.push_back(static_cast<char>(q.size()));
      for (const int i : q) {
        const std::int32_t i32 = i;  // little-endian host assumed (x86-64, aarch64)
        ply.append(reinterpret_cast<const char*>(&i32), 4);
      }
    }
    check_cube(load_model(write_file("cube_binary.ply", ply)));
  }
  SECTION("extension in upper case") {
    fs::copy_file(kModels + "cube.off", scratch() / "CUBE.OFF",
                  fs::copy_options::overwrite_existing);
    check_cube(load_model((scratch() / "CUBE.OFF").string()));
  }
}

TEST_CASE("formats that keep the vertex order give identical features", "[mesh_io]") {
  const std::string ref = cf::to_json(load_model(kModels + "cube.off", {"cube"}));
  CHECK(cf::to_json(load_model(kModels + "cube_tri.off", {"cube"})) == ref);
  CHECK(cf::to_json(load_model(kModels + "cube.obj", {"cube"})) == ref);
  CHECK(cf::to_json(load_model(kModels + "cube.ply", {"cube"})) == ref);
}

TEST_CASE("the model's name is the file stem unless given", "[mesh_io]") {
  CHECK(load_model(kModels + "cube.off").name() == "cube");
  cf::tools::LoadOptions opt;
  opt.name = "A";
  CHECK(load_model(kModels + "cube.off", opt).name() == "A");
}

TEST_CASE("identical points are merged, keeping input indices", "[mesh_io]") {
  // Facet 1 uses point 8, a copy of point 4: after merging the cube is closed.
  std::vector<cf::Vec3> v = kCubeV;
  v.push_back(v[4]);
  auto f = kCubeF;
  f[1] = {8, 5, 6, 7};
  const cf::Polyhedron m = load_model(write_file("dup_point.off", off_text(v, f)));
  check_cube(m);
}

TEST_CASE("files that cannot be read are rejected, naming the file", "[mesh_io]") {
  const std::string missing = (scratch() / "missing.off").string();
  CHECK_THROWS_WITH(load_model(missing),
                    Catch::Contains("loading '" + missing + "': cannot open file: no such file"));
  fs::create_directories(scratch() / "dir.off");
  CHECK_THROWS_WITH(
      load_model((scratch() / "dir.off").string()),
      Catch::Contains("dir.off': cannot open file: is a directory, not a regular file"));
  const std::string empty = write_file("empty.off", "");
  CHECK_THROWS_WITH(load_model(empty),
                    Catch::Contains("loading '" + empty + "': the file is empty"));
  const std::string xyz = write_file("cube.xyz", off_text(kCubeV, kCubeF));
  CHECK_THROWS_WITH(
      load_model(xyz),
      Catch::Contains(
          "cube.xyz': unknown file extension '.xyz' (expected .off, .obj, .stl or .ply)"));
  const std::string noext = write_file("cube", off_text(kCubeV, kCubeF));
  CHECK_THROWS_WITH(load_model(noext), Catch::Contains("unknown file extension ''"));
}

TEST_CASE("malformed files are parse errors", "[mesh_io]") {
  CHECK_THROWS_WITH(
      load_model(write_file("bad.off", "OFF\n3 1 0\n0 0 zero\n1 0 0\n0 1 0\n3 0 1 2\n")),
      Catch::Contains("bad.off': parse error: line 3: vertex 0: 'zero' is not a finite number"));
  CHECK_THROWS_WITH(load_model(write_file("bad.obj", "v 0 0 0\nbogus line\n")),
                    Catch::Contains("bad.obj': parse error: line 2: unknown OBJ record 'bogus'"));
  CHECK_THROWS_WITH(
      load_model(write_file("bad.stl",
                            "solid x\n  facet normal 0 0 1\n    outer loop\n"
                            "      vertex 0 0 nope\n")),
      Catch::Contains(
          "bad.stl': parse error: line 4: expected a finite number in a vertex, found 'nope'"));
  CHECK_THROWS_WITH(load_model(write_file("bad.ply",
                                          "ply\nformat ascii 1.0\nelement vertex 3\n"
                                          "property float x\nend_header\n1\n")),
                    Catch::Contains("bad.ply': parse error: the header's element counts need at "
                                    "least 6 bytes of data, but the file has 2 after the header"));
  // A facet index beyond the vertex list, in OFF and in OBJ (where it may point forward).
  auto f = kCubeF;
  f[0] = {0, 3, 2, 9};
  CHECK_THROWS_WITH(load_model(write_file("index.off", off_text(kCubeV, f))),
                    Catch::Contains("index.off': parse error: line 11: facet 0 refers to vertex 9 "
                                    "but the file has 8 vertices (0 to 7)"));
  CHECK_THROWS_WITH(
      load_model(write_file("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")),
      Catch::Contains(
          "index.obj': parse error: facet 0 refers to vertex 3 but the file has 3 vertices"));
}

TEST_CASE("data after what the header declares is refused, with its byte offset", "[mesh_io]") {
  // Two models in one OFF file: the second would be dropped without a word.
  const std::string one = off_text(kCubeV, kCubeF);
  CHECK_THROWS_WITH(
      load_model(write_file("two.off", one + one)),
      Catch::Contains("two.off': parse error: line 17: byte offset " + std::to_string(one.size()) +
                      ": data after the 6 facets the header declares (a second model"));
  // White space and comments after the last facet are fine.
  check_cube(load_model(write_file("tail.off", one + "\n# the end\n\n")));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  CHECK_THROWS_WITH(
      load_model(write_file("extra.ply", ply + "3 0 2 1\n")),
      Catch::Contains("extra.ply': parse error: line 14, byte offset " +
                      std::to_string(ply.size()) +
                      ": 8 bytes of data after the last element the header declares"));
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  bin += std::string(12, '\0');
  CHECK_THROWS_WITH(
      load_model(write_file("extra_bin.ply", bin + "abc")),
      Catch::Contains("extra_bin.ply': parse error: byte offset " + std::to_string(bin.size()) +
                      ": 3 bytes of data after the last element"));
}

TEST_CASE("header counts are checked against the file's size before anything is allocated",
          "[mesh_io][hostile]") {
  // Each of these used to allocate gigabytes (CGAL reserves what the header says).
  CHECK_THROWS_WITH(
      load_model(write_file("count.off", "OFF\n3 999999999 0\n0 0 0\n1 0 0\n0 1 0\n")),
      Catch::Contains(
          "count.off': parse error: the header says 3 vertices and 999999999 facets, more than the "
          "remaining 18 bytes of the file can hold"));
  CHECK_THROWS_WITH(
      load_model(write_file("facet.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n")),
      Catch::Contains(
          "facet.off': parse error: line 6: facet 0 says it has 1000000000 vertices but its line "
          "lists 3 numbers"));
  CHECK_THROWS_WITH(
      load_model(write_file("count.ply",
                            "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                            "property float x\nproperty float y\nproperty float z\nend_header\n")),
      Catch::Contains(
          "count.ply': parse error: the header's element counts need at least 48000000000 bytes"));
  CHECK_THROWS_WITH(
      load_model(write_file("list.ply",
                            "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
                            "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                            "property list uint int vertex_indices\nend_header\n\xff\xff\xff\x7f")),
      Catch::Contains("list.ply': parse error: item 0 of element 'face' has a list of 2147483647 "
                      "values, more than "
                      "the rest of the file holds"));
  std::string stl(80, ' ');
  stl += std::string("\xff\xff\xff\x7f", 4);
  CHECK_THROWS_WITH(load_model(write_file("count.stl", stl)),
                    Catch::Contains("count.stl': parse error: not an ascii STL (no 'solid'), and "
                                    "as binary STL its header says "
                                    "2147483647 triangles"));
}

TEST_CASE("indices and coordinates out of range get precise messages", "[mesh_io][hostile]") {
  auto f = kCubeF;
  std::string text = off_text(kCubeV, f);
  text.replace(text.find("\n4 0 3 2 1\n"), 11, "\n4 99999999999999999999 3 2 1\n");
  CHECK_THROWS_WITH(load_model(write_file("index20.off", text)),
                    Catch::Contains("index20.off': parse error: line 11: facet 0 refers to vertex "
                                    "99999999999999999999 but the "
                                    "file has 8 vertices (0 to 7)"));
  CHECK_THROWS_WITH(
      load_model(
          write_file("index20.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n")),
      Catch::Contains(
          "index20.obj': parse error: line 4: facet 0 refers to vertex 99999999999999999999, which "
          "does not exist"));
  std::vector<cf::Vec3> v = kCubeV;
  for (auto& p : v) p *= 1e300;
  CHECK_THROWS_WITH(load_model(write_file("huge.off", off_text(v, kCubeF))),
                    Catch::Contains("huge.off': vertex 1 has the coordinate 1e+301 mm, beyond the "
                                    "largest accepted (|x| <= 1e+09 mm)"));
  CHECK_THROWS_WITH(
      load_model(write_file("inf.off", "OFF\n3 1 0\n0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n")),
      Catch::Contains("inf.off': parse error: line 4: vertex 1: '1e999' is not a finite number"));
  // Found by fuzz_ply: an index beyond the range of long long (the message's cast was
  // undefined behaviour), and a NaN in binary PLY (it broke the ordering of the point index).
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  CHECK_THROWS_WITH(
      load_model(write_file("index_huge.ply", ply_head + "3 0 1 1" + std::string(40, '1') + "\n")),
      Catch::Contains("index_huge.ply': parse error: facet 0 refers to vertex "
                      "1.111111111111111e+40, which does "
                      "not exist"));
  std::string nan_ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  const float nan_xyz[3] = {std::nanf(""), 0, 0};
  nan_ply.append(reinterpret_cast<const char*>(nan_xyz), sizeof nan_xyz);
  CHECK_THROWS_WITH(
      load_model(write_file("nan.ply", nan_ply)),
      Catch::Contains(
          "nan.ply': parse error: a property value in the binary data is not a finite number"));
  // Binary garbage is quoted printable.
  CHECK_THROWS_WITH(
      load_model(write_file("garbage.obj", "v 0 0 0\n\x01\x1b[2J\xff x\n")),
      Catch::Contains(
          "garbage.obj': parse error: line 2: unknown OBJ record '\\x01\\x1B[2J\\xFF'"));
}

TEST_CASE("a FIFO is refused without blocking", "[mesh_io][hostile]") {
  const std::string fifo = (scratch() / "fifo.off").string();
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(
      load_model(fifo),
      Catch::Contains("fifo.off': cannot open file: is a FIFO (named pipe), not a regular file"));
}

TEST_CASE("units: the points are converted to mm", "[mesh_io][units]") {
  std::vector<cf::Vec3> v = kCubeV;
  for (auto& p : v) p /= 1000;  // the 10 mm cube in metres
  const std::string path = write_file("cube_m.off", off_text(v, kCubeF));
  cf::tools::LoadOptions opt;
  opt.units = "m";
  check_cube(load_model(path, opt));
  const cf::Polyhedron raw = load_model(path);
  CHECK(raw.size() == Approx(0.01 * std::sqrt(3.0)));
  CHECK_THAT(cf::tools::size_warning(raw, "A", "--units-a"),
             Catch::StartsWith("model A 'cube_m' is 0.01732 mm across (bounding-box diagonal), "
                               "small against the contact "
                               "threshold epsilon = 1 mm") &&
                 Catch::EndsWith("give its unit with --units-a (mm, cm, m or in)"));
  CHECK(cf::tools::size_warning(load_model(path, opt), "A", "--units-a").empty());
  opt.units = "in";
  CHECK(load_model(path, opt).size() == Approx(0.01 * 25.4 * std::sqrt(3.0)));
  opt.units = "furlong";
  CHECK_THROWS_WITH(load_model(path, opt),
                    Catch::Contains("unknown unit 'furlong' (expected mm, cm, m or in)"));
}

TEST_CASE("a file without facets is rejected", "[mesh_io]") {
  CHECK_THROWS_WITH(load_model(write_file("nofacets.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")),
                    Catch::Contains("nofacets.off': the file contains no facets"));
  CHECK_THROWS_WITH(load_model(write_file("blank.stl", "   \n")),
                    Catch::Contains("blank.stl': the file contains no facets"));
}

TEST_CASE("broken solids are rejected with the reason", "[mesh_io]") {
  SECTION("open boundary") {
    auto f = kCubeF;
    f.pop_back();  // no x = 0 side
    CHECK_THROWS_WITH(
        load_model(write_file("open.off", off_text(kCubeV, f))),
        Catch::Contains("open.off': open boundary: edge 0-3 belongs to facet 0 only"));
  }
  SECTION("non-manifold edge: two cubes sharing an edge") {
    // Second cube [10,20] x [10,20] x [0,10] shares the cube's edge 2-6 (x = y = 10).
    std::vector<cf::Vec3> v = kCubeV;
    for (int i = 0; i < 8; ++i) v.push_back(kCubeV[i] + cf::Vec3(10, 10, 0));
    auto f = kCubeF;
    for (auto q : kCubeF) {
      for (int& i : q) i += 8;
      f.push_back(q);
    }
    // Weld the second cube's corners (10,10,z) = points 8 and 12 onto points 2 and 6.
    for (auto& q : f)
      for (int& i : q) i = i == 8 ? 2 : i == 12 ? 6 : i;
    CHECK_THROWS_WITH(
        load_model(write_file("nm_edge.off", off_text(v, f))),
        Catch::Contains("nm_edge.off': non-manifold edge: edge 2-6 is shared by 4 facets"));
  }
  SECTION("non-manifold vertex: two cubes sharing a corner") {
    std::vector<cf::Vec3> v = kCubeV;
    for (int i = 0; i < 8; ++i) v.push_back(kCubeV[i] + cf::Vec3(10, 10, 10));
    auto f = kCubeF;
    for (auto q : kCubeF) {
      for (int& i : q) i = i == 0 ? 6 : i + 8;  // its corner 0 is the cube's corner 6
      f.push_back(q);
    }
    CHECK_THROWS_WITH(
        load_model(write_file("nm_vertex.off", off_text(v, f))),
        Catch::Contains("nm_vertex.off': non-manifold vertex: vertex 6 joins separate fans"));
  }
  SECTION("inconsistent orientation: one facet flipped") {
    auto f = kCubeF;
    std::reverse(f[1].begin(), f[1].end());
    CHECK_THROWS_WITH(
        load_model(write_file("flipped.off", off_text(kCubeV, f))),
        Catch::Contains("flipped.off': inconsistent orientation: facets 1 and 2 both run edge"));
  }
  SECTION("inward orientation") {
    auto f = kCubeF;
    for (auto& q : f) std::reverse(q.begin(), q.end());
    CHECK_THROWS_WITH(
        load_model(write_file("inward.off", off_text(kCubeV, f))),
        Catch::Contains("inward.off': inward orientation: the enclosed volume is -1000 mm^3"));
  }
  SECTION("self-intersection") {
    // Triangulated cube with its top corner (10,10,10) pulled down through the bottom.
    std::vector<cf::Vec3> v = kCubeV;
    v[6] = {5, 5, -5};
    CHECK_THROWS_WITH(load_model(write_file("selfx.off", off_text(v, triangulate(kCubeF)))),
                      Catch::Contains("selfx.off': self-intersection: facets"));
  }
  SECTION("self-intersection, with a vertex along an edge") {
    // The same, with the midpoint of edge 0-1 a vertex of both triangles along that edge: the
    // test drops such straight vertices first (a 30,000-gon of them took minutes), and must
    // still see the intersection.
    std::vector<cf::Vec3> v = kCubeV;
    v[6] = {5, 5, -5};
    v.push_back({5, 0, 0});  // 8
    auto f = triangulate(kCubeF);
    for (auto& t : f) {
      if (t == std::vector<int>{0, 2, 1}) t = {0, 2, 1, 8};
      if (t == std::vector<int>{0, 1, 5}) t = {0, 8, 1, 5};
    }
    CHECK_THROWS_WITH(load_model(write_file("selfx_straight.off", off_text(v, f))),
                      Catch::Contains("selfx_straight.off': self-intersection: facets"));
    v[6] = kCubeV[6];  // the cube again: valid, the midpoint no corner of it
    CHECK(load_model(write_file("straight.off", off_text(v, f))).num_vertices() == 8);
  }
  SECTION("self-intersection in a face written as strips, with vertices along its edges") {
    // A 10 mm cube whose bottom is one polygon with 100 vertices on each side, whose sides are
    // strips of quads and whose top is a fan of triangles around its centre: the test merges
    // each side's strips and the top's fan and drops the straight vertices first, and must
    // still see the top's centre pulled down through the bottom.
    constexpr int k = 100, n = 4 * k;
    std::vector<cf::Vec3> v;
    for (double z : {0.0, 10.0})
      for (int s = 0; s < 4; ++s)
        for (int i = 0; i < k; ++i) {
          const double f = 10.0 * i / k;
          const cf::Vec3 p[] = {{f, 0, z}, {10, f, z}, {10 - f, 10, z}, {0, 10 - f, z}};
          v.push_back(p[s]);
        }
    v.push_back({5, 5, 10});  // the top's centre: 2n
    std::vector<std::vector<int>> f(1);
    for (int i = n - 1; i >= 0; --i) f[0].push_back(i);  // the bottom, seen from below
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      f.push_back({i, j, n + j, n + i});
      f.push_back({n + i, n + j, 2 * n});
    }
    const cf::Polyhedron cube = load_model(write_file("cube_strips.off", off_text(v, f)));
    CHECK(cube.num_vertices() == 8);
    CHECK(cube.num_faces() == 6);
    v[2 * n] = {5, 5, -5};  // through the bottom (the volume stays positive: 500 mm^3)
    CHECK_THROWS_WITH(load_model(write_file("cube_strips_through.off", off_text(v, f))),
                      Catch::Contains("cube_strips_through.off': self-intersection: facets"));
  }
  SECTION("degenerate facet: repeated vertex") {
    auto f = kCubeF;
    f[0] = {0, 3, 3, 2, 1};
    CHECK_THROWS_WITH(
        load_model(write_file("repeat.off", off_text(kCubeV, f))),
        Catch::Contains("repeat.off': degenerate facet: facet 0 uses vertex 3 more than once"));
  }
  SECTION("degenerate facet: fewer than 3 vertices") {
    auto f = kCubeF;
    f.push_back({0, 1});
    CHECK_THROWS_WITH(load_model(write_file("two.off", off_text(kCubeV, f))),
                      Catch::Contains("two.off': degenerate facet: facet 6 has only 2 vertices"));
  }
  SECTION("degenerate facet: zero area") {
    // Point 8 is the midpoint of edge 4-5; the side face runs 5 -> 8 -> 4, and the sliver
    // triangle 4-8-5 closes the gap against the top face's edge 4-5.
    std::vector<cf::Vec3> v = kCubeV;
    v.push_back({5, 0, 10});
    auto f = kCubeF;
    f[2] = {0, 1, 5, 8, 4};
    f.push_back({4, 8, 5});
    CHECK_THROWS_WITH(load_model(write_file("sliver.off", off_text(v, f))),
                      Catch::Contains("sliver.off': degenerate facet: facet 6 is too thin: its "
                                      "height ("));
  }
  SECTION("a needle is refused for its height, with its area") {
    // Facet 6 is a triangle 10 mm long whose apex lies 1e-9 mm off its base: its area is
    // not zero, its height is below 1e-7 of the diagonal (1.7e-6 mm).
    std::vector<cf::Vec3> v = kCubeV;
    v.push_back({5, 1e-9, 10});
    auto f = kCubeF;
    f[2] = {0, 1, 5, 8, 4};
    f.push_back({4, 8, 5});
    CHECK_THROWS_WITH(load_model(write_file("needle.off", off_text(v, f))),
                      Catch::Contains("needle.off': degenerate facet: facet 6 is too thin: its "
                                      "height (1e-09 mm, twice its area 5e-09 mm^2 over its "
                                      "longest side 10 mm) is below 1.73205e-06 mm"));
  }
  SECTION("non-planar facet") {
    std::vector<cf::Vec3> v = kCubeV;
    v[6].z() = 10.5;
    CHECK_THROWS_WITH(load_model(write_file("warped.off", off_text(v, kCubeF))),
                      Catch::Contains("warped.off': non-planar facet: vertex"));
  }
  SECTION("two separate solids") {
    std::vector<cf::Vec3> v = kCubeV;
    for (int i = 0; i < 8; ++i) v.push_back(kCubeV[i] + cf::Vec3(20, 0, 0));
    auto f = kCubeF;
    for (auto q : kCubeF) {
      for (int& i : q) i += 8;
      f.push_back(q);
    }
    CHECK_THROWS_WITH(load_model(write_file("two_cubes.off", off_text(v, f))),
                      Catch::Contains("two_cubes.off': the file holds 2 separate solids"));
  }
}

TEST_CASE("model_from_soup validates in-memory soups too", "[mesh_io]") {
  cf::tools::PolygonSoup soup{kCubeV, kCubeF};
  check_cube(cf::tools::model_from_soup(soup, "memory"));
  soup.polygons.pop_back();
  CHECK_THROWS_WITH(cf::tools::model_from_soup(soup, "memory"),
                    Catch::Contains("loading 'memory': open boundary"));
}

TEST_CASE("a file's coordinate rounding is read from how its numbers are written",
          "[mesh_io][precision]") {
  using cf::tools::coordinate_rounding;
  using V = cf::Vec3;
  // float32 values (binary STL): half a unit in float32's last place at the largest, 2^-24
  // of it; 20 lies in [16, 32), whose float32 spacing is 2^-19.
  const float third = 1.0f / 3.0f;
  CHECK(coordinate_rounding({V(third, 20, -1.5), V(0, 0, 0)}) == std::ldexp(20.0, -24));
  // Six significant digits (8.66025 for 8.660254...): half a unit of the fifth decimal.
  CHECK(coordinate_rounding({V(8.66025, 5, 1.23457), V(-8.66025, 5, 0.1)}) ==
        Approx(0.5e-5).epsilon(1e-9));
  // Ten digits on a 1e3 scale.
  CHECK(coordinate_rounding({V(1234.567891, 0.1, 0.2)}) == Approx(0.5e-6).epsilon(1e-9));
  // Full doubles: a double's own rounding, 2^-53 of the largest.
  const double x = std::sqrt(2.0) * 10;
  CHECK(coordinate_rounding({V(x, 1 / 3.0, 0.1)}) == std::ldexp(x, -53));
  CHECK(coordinate_rounding({V(0, 0, 0)}) == 0);
}

TEST_CASE("the rounding is measured in the file's unit and recorded in mm",
          "[mesh_io][precision]") {
  // Binary STL stores float32: a 1 m cube in metres is rounded to 2^-24 m = 6e-5 mm.
  const std::string text =
      "OFF\n8 6 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n"
      "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  const std::string path = cf::test::write_file("unit_cube.off", text);
  cf::tools::LoadOptions metres;
  metres.units = "m";
  const cf::tools::MeasuredModel m = cf::tools::load_measured_model(path, metres);
  CHECK(m.rounding_mm == std::ldexp(1.0, -24) * 1000);
}

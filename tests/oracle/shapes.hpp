#pragma once
// Independent test oracle: shape families written as closed, outward-oriented, 2-manifold OFF
// meshes (polygonal facets; faces with holes are split into triangles; no T-junctions), and the
// seeded pairing of two of them (A moving, B fixed). See tests/oracle/README.md for the
// families and their proportion ranges.

#include "classify.hpp"

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace oracle {

struct Mesh {
  std::vector<Vec3> V;
  std::vector<std::vector<int>> F;  // facets, counter-clockwise seen from outside
  std::string name;
};

void write_off(const Mesh& m, const std::string& path);
/// Binary STL as CAD and mesh tools write it: each facet triangulated (ear clipping in its
/// plane), every coordinate rounded to float32, the facet normals left zero.
void write_stl_float32(const Mesh& m, const std::string& path);
Mesh read_off(const std::string& path);  // throws std::runtime_error

double mesh_volume(const Mesh& m);
double mesh_area(const Mesh& m);
/// "" when the mesh is closed, every edge shared by exactly two facets running it opposite
/// ways, no degenerate facet, planar facets, positive volume; otherwise the problem.
std::string check_mesh(const Mesh& m);
/// Maximal edge-connected regions of coplanar facets (what the features call faces).
int count_planar_faces(const Mesh& m);
/// Mesh vertices where at least three different planar faces meet (feature vertices of these
/// families).
int count_corner_vertices(const Mesh& m);

Mesh transform(const Mesh& m, const Pose& X);
/// Uniform random rotation, translation uniform in [-40, 40]^3 mm.
Pose random_rigid(std::mt19937_64& rng);
Mat3 random_rotation(std::mt19937_64& rng);

// ---- families (model frame; sizes in mm) ----
Mesh make_box(double x, double y, double z);
/// L section: foot [0,w]x[0,t1], wall [0,t2]x[0,h], extruded by d.
Mesh make_l_section(double w, double h, double t1, double t2, double d);
/// U channel: gap g between walls of thickness tw, base thickness tb, total height h, length d.
Mesh make_u_channel(double g, double tw, double tb, double h, double d);
/// T section: flange w x tf on top of a web of thickness tw, total height h, length d.
Mesh make_t_section(double w, double tf, double tw, double h, double d);
/// Block w x h x d with a T-shaped slot along d: neck width nw, depth nd; head width hw, depth hd.
Mesh make_t_slot(double w, double h, double d, double nw, double nd, double hw, double hd);
/// Floor w x dd x tf with two walls (thickness t1 along x, t2 along y) of height h.
Mesh make_corner_block(double w, double dd, double tf, double t1, double t2, double h);
/// Stairs of runs[i] x rises[i] (first step tallest), width d.
Mesh make_stairs(const std::vector<double>& runs, const std::vector<double>& rises, double d);
/// Block w x w x h with a square through-hole of side s (offset ox, oy from the centre).
Mesh make_square_hole_block(double w, double h, double s, double ox, double oy);
/// Block w x w x h with a regular n-gon through-hole of circumradius r, turned by phase.
Mesh make_ngon_hole_block(double w, double h, int n, double r, double phase);
/// Regular n-gon prism of circumradius r and length l.
Mesh make_ngon_prism(int n, double r, double l, double phase);
/// Triangular prism: triangle (0,0), (a,0), (c,b), extruded by d.
Mesh make_wedge(double a, double b, double c, double d);
/// Square-based pyramid: base a x b at z = 0, apex at (a/2 + ox, b/2 + oy, h) (four edges at
/// the apex, no face pair at a right angle unless by chance).
Mesh make_pyramid(double a, double b, double h, double ox, double oy);
/// Block whose top is a lower level (height h1, run w1) with a V-groove across it (from x = g0,
/// width gw, depth gd), a ramp rising over `run` to an upper level (height h2, run w2);
/// extruded by d. Obtuse convex edges at the ramp's top and the groove's lips, reflex ones at
/// the ramp's foot and the groove's bottom.
Mesh make_ramp_step(double w1, double run, double w2, double h1, double h2, double g0, double gw,
                    double gd, double d);
/// Extrusion of a polygon (outer CCW, holes CW) along z by d; caps triangulated when needed.
Mesh extrude(const std::vector<Vec2>& outer, const std::vector<std::vector<Vec2>>& holes, double d);
/// Ear clipping of a polygon with holes; triangles index into the concatenation of the loops.
std::vector<std::array<int, 3>> triangulate(const std::vector<Vec2>& outer,
                                            const std::vector<std::vector<Vec2>>& holes);

struct ShapePair {
  Mesh A, B;  // transformed (random rigid motion each)
  std::string desc;
  int pairing = 0;
};
constexpr int kPairings = 12;
/// The pair of seed: pairing = seed % kPairings, proportions from std::mt19937_64(seed).
ShapePair make_pair(std::uint64_t seed);
const char* pairing_name(int pairing);

/// Pairings outside the seeded cycle (the recall test's seeds keep their pairings): 0 pyramid
/// against a ramp step, 1 wedge against a ramp step, 2 n-gon prism against a ramp step;
/// proportions from std::mt19937_64(seed). ShapePair::pairing is -1 - which.
constexpr int kExtraPairings = 3;
ShapePair make_extra_pair(int which, std::uint64_t seed);
const char* extra_pairing_name(int which);

/// The pair a command line names with `--seed N` and `--extra K` (the oracle's tools).
struct PairArgs {
  bool have_seed = false;
  std::uint64_t seed = 0;
  int extra = -1;  // >= 0: make_extra_pair(extra, seed)
  /// True when `option` is --seed or --extra, its value read with `value`; throws
  /// std::runtime_error naming the option when the value is out of range.
  bool take(const std::string& option, const std::function<std::string()>& value);
  /// Throws std::runtime_error when --extra came without --seed.
  void check() const;
};

}  // namespace oracle

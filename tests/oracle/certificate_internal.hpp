#pragma once
// Internals of the certificate checker (certificate_check.hpp), shared by its four sources:
// certificate_check.cpp (file, tolerances, rules, report), certificate_cells.cpp (the tree
// of cells and its leaf claims), certificate_program.cpp (piece tables, programs, Farkas) and
// certificate_images.cpp (sets invalid as the image of another under a symmetry).

#include "certificate_check.hpp"
#include "classify.hpp"
#include "poly.hpp"

#include <nlohmann/json.hpp>

#ifdef CF_ORACLE_CERT_GMP
#include <gmpxx.h>
#else
#include <boost/multiprecision/cpp_int.hpp>
#endif

#include <array>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace oracle::cert {

using json = nlohmann::json;

// Exact rationals: GMP's mpq_class when CMake found gmpxx (CF_ORACLE_CERT_GMP), else
// Boost.Multiprecision's cpp_rational (header-only; Boost is already a test dependency). Both
// construct from a double the rational of exactly its value. GMP is preferred for speed: a
// program leaf sums a few hundred products per choice, and up to 4096 choices per leaf.
#ifdef CF_ORACLE_CERT_GMP
using Rational = mpq_class;
inline double to_double(const Rational& q) { return q.get_d(); }
#else
using Rational = boost::multiprecision::cpp_rational;
inline double to_double(const Rational& q) { return q.convert_to<double>(); }
#endif
/// A rational just above pi (3.14159265358979323847 > pi): exact comparisons with the ball.
Rational pi_upper();

// ---- named tolerances (each justified where it is used) ----

/// The alignment every witness meets: an f-f's |R n_A + n_B|, an e-f's |(R e_A).n_B| and an
/// f-e's |(R n_A).e_B| are at most this (docs/certificates.md, "Rules"; generator.md). The
/// rules keep this constant; trees use `rot_tol_rad` (Tol::rot), 1e-8 in files that predate
/// it, and never below this (a smaller one would refute witnesses the verifier accepts).
constexpr double kAlignTol = 1e-8;
/// Error, per unit length, of the central rotation the checker computes (Rodrigues' formula or
/// R0 Rot(axis, c), each entry a few ulps) applied to a vector, plus the rounding of the turn
/// bound itself: ~5e-16 in practice, taken 20 times larger.
constexpr double kRcErr = 1e-14;
/// Absolute error of a dot or cross product of unit vectors computed in double (a few ulps),
/// taken ~1000 times larger; every strict comparison of such a value keeps this much margin.
constexpr double kUnitEval = 1e-13;
/// pi - double(pi) = 1.2246e-16, rounded up: the root cube [-pi_d, pi_d]^3 and the root arc of
/// half-width pi_d miss rotations this close to the domain's edge, so the root's rotations are
/// grown by this much.
constexpr double kPiGap = 2e-16;
/// Relative rounding of the checker's own rows, bounds and boxes (sums of a few products of
/// doubles: a few ulps of the magnitudes involved, taken ~50 times larger).
constexpr double kRelRound = 1e-14;
/// A frame, a plane offset or a piece that is off by more than this (relative to the models'
/// coordinate scale, or absolute for unit vectors) is not the face's: rounding of the
/// generator's own arithmetic is ~1e-15; what is smaller is measured and carried into rows.
constexpr double kGross = 1e-9;

/// Tolerances the checks use: the certificate's, each made no stronger than the graph's
/// parameters (the weaker of the two); in a tree with its own `tolerances`, those.
struct Tol {
  double touch = 0;        // mm
  double margin = 0;       // mm, min_margin_mm
  double slack = 0;        // local_slack
  double rounding = 0;     // mm, rounding_mm
  double rot = kAlignTol;  // rad, rot_tol_rad
  double off_circle = 0;   // rad
  double deep_extra = 0;   // mm, a tree's deep_extra_mm (0 for the file's)
  double size = 0;         // mm, the larger bounding-box diagonal
  double scale = 0;        // mm: size + the largest |vertex| of either model (rounding scale)
};

/// A tree's tolerances (docs/certificates.md, "Cells", `tolerances`): `file` with the values
/// `cells.tolerances` gives, each required to be at least as loose as the file's. Returns ""
/// and sets *out, else why the tree's tolerances are not acceptable.
std::string tree_tolerances(const Tol& file, const json& cells, Tol* out);

struct SetPc {
  PcType type;
  int a = -1, b = -1;
};
std::string pc_text(const SetPc& p);

// ---- piece tables (certificate_program.cpp) ----

struct PieceSide {
  Vec2 q0, q1;            // corners k, k+1 in the generator's (u, v)
  Vec2 o;                 // unit outward normal in (u, v)
  bool claimed = false;   // the file's boundary[k]
  bool boundary = false;  // the checker's decision: the side lies on the face's boundary
  double mu = 0;          // the margin the checker's rows use on this side (mm, <= margin)
};
struct Piece {
  std::vector<PieceSide> sides;
  Vec2 lo, hi;  // bounding box in (u, v)
  double area = 0;
};
struct FaceTable {
  bool ok = false;
  std::string problem;  // why not ok
  Vec3 n, U, V;
  double offset = 0;
  double e_frame = 0;  // bound on |(offset n + u* U + v* V) - x*| for x* on the face
  double rho = 0;      // allowance of the piece rows: how far a deep point may be from a piece
  std::vector<Piece> pieces;
};
struct PieceTables {
  std::map<int, FaceTable> A, B;
};
/// Checks the file's `pieces` (may be null); problems and warnings are appended.
PieceTables check_piece_tables(const Graph& g, const Tol& tol, const json& pieces,
                               std::vector<std::string>& problems,
                               std::vector<std::string>& warnings);

// ---- rotations of a node ----

/// The rotations of a node: every rotation R of the node moves every vector x of A's frame by
/// |R x - M x| <= beta(x), M the central rotation as the checker computed it.
struct Turn {
  bool arc = false;
  Mat3 M = Mat3::Identity();
  double h = 0;              // half-width, grown by the tree's gaps
  double off = 0;            // arcs: off_circle_rad
  Vec3 axis = Vec3::Zero();  // arcs: unit
  double eta = 0;            // arcs: how far R0 is from a rotation (spectral-norm bound)
  double beta(const Vec3& x) const;
  double unit() const;  // beta per unit length at worst
};
Mat3 rodrigues(const Vec3& r);
Mat3 rot_about(const Vec3& unit_axis, double theta);

struct Ctx {
  const Graph& g;
  Tol tol;
  const PieceTables& pieces;
};

/// Checks a program leaf: every choice of pieces present and its multipliers proving the
/// program infeasible in exact arithmetic. Returns "" when the claim holds, else why not.
std::string check_program(const Ctx& ctx, const std::vector<SetPc>& pcs, const Vec3& pivot,
                          const Turn& turn, const Vec3& lo, const Vec3& hi, const json& farkas);

/// Checks a first-order leaf (docs/certificates.md, "First-order leaves"): a cube node with
/// theta_max = sqrt(3) h below pi/4, one entry per choice of the e-e PCs' signs in order, and
/// each entry's multipliers proving its program infeasible over the box of v. Returns "" when
/// the claim holds, else why not.
std::string check_first_order(const Ctx& ctx, const std::vector<SetPc>& pcs, const Turn& turn,
                              const json& farkas);

/// Checks a set's `cells`; fills out.node_fails and out.leaves.
void check_cells(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& cells,
                 CertSetResult& out);

// ---- images (certificate_images.cpp) ----

/// A set as a sorted list of (type, a, b): the same set whatever the order of its PC list.
using SetKey = std::vector<std::tuple<int, int, int>>;
SetKey set_key(const std::vector<SetPc>& pcs);

/// "f-f:3:5;e-e:0:7" -> PCs, each of a non-degenerate type with indices in range; throws
/// std::runtime_error naming the problem.
std::vector<SetPc> parse_pcs(const Graph& g, const std::string& text);

/// One model's map h(x) = H (x - c) + c matched onto the model (docs/certificates.md,
/// "Images", steps 1 to 3). eps and delta are upper bounds for the orthogonal matrix nearest H.
struct SolidMap {
  std::string problem;       // "" when the map is a symmetry of the model
  int det_sign = 0;          // the sign of det H
  std::vector<int> v, e, f;  // the image of each vertex, edge and face
  double eps = 0;            // mm: the largest distance from a vertex's image to its match
  double delta = 0;          // rad: the largest angle an edge direction or face normal turns by
};
SolidMap match_symmetry(const Poly& P, const std::string& name, const Mat3& H, const Vec3& c,
                        double scale);

/// What the checker concluded about a set another one may be the image of.
struct DecidedSet {
  int index = -1;
  std::string kind;  // "cells", "image", a rule's name, ...
  CertOutcome outcome = CertOutcome::Rejected;
  Tol tree;  // cells: the tree's tolerances
};

/// The maps of the entries seen so far, by (solid, H, c): entries of one orbit share them.
using SymmetryCache = std::map<std::pair<char, std::array<double, 12>>, SolidMap>;

/// Checks an image entry (docs/certificates.md, "Images", steps 1 to 5) given every other
/// set's verdict (by key, first listing). Returns "" when the claim holds, else why not.
std::string check_image(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& image_of,
                        const std::map<SetKey, DecidedSet>& decided, SymmetryCache& cache);

// ---- small helpers ----
Vec3 get_vec3(const json& j, const char* key);
std::string fmt(double x);  // shortest round-trip text
/// The closure vertices of a PC's element of A (side 0) or of B (side 1).
std::vector<int> closure_vertices(const Poly& P, int kind, int index);

}  // namespace oracle::cert

#pragma once
// Independent test oracle: what holds between A and B at one pose (docs/spec.md, section 4).
//
//  - touching pairs of open elements (vertex, open edge, open face), with a length tolerance;
//  - interior disjointness, exactly in the combinatorial sense: A and B have overlapping
//    interiors iff (1) at some point where their boundaries meet the tangent cones of A and B
//    have overlapping interiors, or (2) one boundary lies inside the other solid. (1) is
//    checked at every touching pair (the cones depend only on the two elements), (2) by a
//    ray-cast when nothing touches. A transversal crossing (an open edge through an open
//    face deeper than the tolerance) is reported directly;
//  - the PCs (touching pairs not dominated by another), their types and contact planes;
//  - the clearance: the smallest distance between primitive pairs (vertex-face, face-vertex,
//    edge-edge, closed elements) that are farther apart than the tolerance.

#include "poly.hpp"

#include <string>
#include <vector>

namespace oracle {

struct Pose {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  Vec3 apply(const Vec3& x) const { return R * x + t; }
  Vec3 inv(const Vec3& x) const { return R.transpose() * (x - t); }
};

std::string pose_string(const Pose& X);  // "R=[[..],[..],[..]] t=[..] q=(w,x,y,z)"

struct Tolerances {
  double len = 1e-6;  // mm: closed elements this close touch
  double ang = 1e-6;  // rad: slack of the tangent-cone tests
  double gap = 1e-4;  // mm: the sampler drops poses whose clearance is below this
};
/// len = 1e-7 x the smaller model's bounding-box diagonal, gap = 100 x len.
Tolerances default_tolerances(const Poly& A, const Poly& B);

enum class PcType { FF, EF, FE, VF, FV, EE, VV, VE, EV, EEC };
const char* type_name(PcType t);  // "f-f", ..., "v-v", "v-e", "e-v", "e-e(collinear)"
bool parse_type(const std::string& s, PcType* t);
inline bool nondegenerate(PcType t) { return static_cast<int>(t) <= static_cast<int>(PcType::EE); }
int kind_a(PcType t);  // 0 vertex, 1 edge, 2 face
int kind_b(PcType t);

struct Pc {
  PcType type;
  int a, b;
  bool operator<(const Pc& o) const {
    if (type != o.type) return type < o.type;
    if (a != o.a) return a < o.a;
    return b < o.b;
  }
  bool operator==(const Pc& o) const { return type == o.type && a == o.a && b == o.b; }
};
using CfKey = std::vector<Pc>;           // sorted
std::string key_string(const CfKey& k);  // "f-f:1:2 v-f:3:0"

struct Touch {
  PcType type;
  int a = -1, b = -1;
  bool transversal = false;  // an open edge through an open face (penetration)
  double extent = 0;         // line contacts: length; f-f: overlap area
  double sin_angle = 1;      // e-e: sine of the angle between the edges
  bool near_end = false;     // e-e: crossing close to an edge end or at a small angle
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();  // world: contact point (p0) or segment (p0, p1)
  // Contact plane normal (world, non-degenerate types) as found: B's face's outward normal for
  // f-f, e-f, v-f, A's for f-e, f-v, either side for e-e; normal_into_a orients it.
  Vec3 normal = Vec3::Zero();
};

/// The normal of a non-degenerate touch's contact plane (docs/spec.md, section 4), oriented
/// from B into A (the direction in which A leaves B): B's face normal for f-f, e-f and v-f;
/// minus A's face normal for f-e and f-v (Touch::normal is A's, outward); for e-e the normal of
/// the plane of both edges, on the side of B's edge's outward bisector (the sum of its two
/// faces' normals). World frame, unit.
Vec3 normal_into_a(const Poly& B, const Touch& t);

struct Verdict {
  bool penetrating = false;
  std::string why;  // what penetrates
  std::vector<Touch> touches;
  std::vector<int> pcs;                // indices into touches: the non-dominated ones
  bool degenerate = false;             // a PC is v-v, v-e, e-v or collinear e-e
  bool too_many = false;               // more than 3 PCs
  bool same_plane = false;             // two PCs share a contact plane
  std::vector<std::string> uncertain;  // near-degenerate situations (the sampler drops these)
  double clearance = kInf;
  std::string clearance_what;

  bool free() const { return !penetrating && touches.empty(); }
  bool valid_cf() const {
    return !penetrating && !pcs.empty() && !degenerate && !too_many && !same_plane;
  }
  CfKey key() const;
  std::string describe() const;  // one line: status, PCs, flags
};

class Classifier {
 public:
  Classifier(const Poly& A, const Poly& B, Tolerances tol);
  Verdict classify(const Pose& X, bool with_clearance = true) const;
  /// The clearance counting only pairs that no PC of `pcs` dominates: how far the nearest
  /// contact that would not be another reading of these PCs is (kInf when none).
  double clearance_outside(const Pose& X, const CfKey& pcs) const;
  /// Only the interior test (touches + cones + containment); cheaper, no PCs.
  bool interiors_disjoint(const Pose& X, std::string* why = nullptr) const;
  const Tolerances& tol() const { return tol_; }
  const Poly& A() const { return A_; }
  const Poly& B() const { return B_; }

 private:
  struct Scene;
  void touches(const Scene& S, Verdict& V) const;
  void cone_checks(const Scene& S, Verdict& V) const;
  void containment(const Scene& S, Verdict& V) const;
  void pcs_and_planes(const Scene& S, Verdict& V) const;
  void clearance(const Scene& S, Verdict& V, const CfKey* outside = nullptr) const;
  Scene scene(const Pose& X) const;
  const Poly& A_;
  const Poly& B_;
  Tolerances tol_;
  std::vector<Box3> bv_, be_, bf_;  // B element boxes (world)
};

/// Point strictly inside the solid (x in P's frame). Ray casting with random directions.
bool point_in_solid(const Poly& P, const Vec3& x);

// ---- tangent cones (apex at the origin, world frame), exposed for unit tests ----
struct Wedge {
  Vec3 d, n1, n2, m1, m2;  // edge direction, face normals, in-face directions
  bool convex = true;
};
struct Sector {
  Vec3 n, r1, r2;  // plane normal (outward), ccw from r1 to r2 about n
  double span = 0;
};
struct Cone {
  int kind = 0;  // 0 half-space {n.x <= 0}, 1 wedge, 2 vertex cone
  Vec3 n;
  Wedge w;
  std::vector<Sector> sectors;
  std::vector<std::pair<Vec3, Wedge>> rays;  // vertex cone: edge directions and their wedges
};
Cone face_cone(const Poly& P, int f, const Mat3& R);
Cone edge_cone(const Poly& P, int e, const Mat3& R);
Cone vertex_cone(const Poly& P, int v, const Mat3& R);
/// True when the interiors of the two cones intersect (slack: angular tolerance).
bool cones_overlap(const Cone& X, const Cone& Y, double slack);
bool point_in_cone(const Cone& K, const Vec3& u);

}  // namespace oracle

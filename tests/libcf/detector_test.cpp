#include <cf/detector.hpp>
#include <cf/geometry.hpp>

#include "detect/polygon_clipping.hpp"
#include "fixtures.hpp"
#include "runtime_models.hpp"

#include <boost/geometry.hpp>
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

namespace {

using cf::PcType;
using cf::Vec3;
namespace tmod = cf::testmodels;

// Poses are built from round numbers; results follow through a few rotations: 1e-9 mm.
constexpr double kTol = 1e-9;

Eigen::Matrix3d rot(double angle, const Vec3& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

cf::Pose pose(const Eigen::Matrix3d& R, const Vec3& t) {
  cf::Pose p;
  p.R_BA = R;
  p.t_BA = t;
  return p;
}

int count(const cf::ContactSet& cs, PcType type) {
  int n = 0;
  for (const cf::ContactPc& c : cs) n += c.pc.type == type;
  return n;
}

const cf::ContactPc* find(const cf::ContactSet& cs, PcType type, int a, int b) {
  for (const cf::ContactPc& c : cs)
    if (c.pc == cf::Pc{type, a, b}) return &c;
  return nullptr;
}

using cf::test::edge_between;

void check_frame(const cf::ContactPc& c) {
  CHECK((c.R_WT.transpose() * c.R_WT - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  CHECK(c.R_WT.determinant() == Approx(1.0).margin(1e-12));
}

}  // namespace

TEST_CASE("cube resting flat on the slab: one plane, f-f undominated", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // Cube face 2 (y = -15) 0.3 mm above the slab top (B face 4, y = 20).
  det.detect(pose(Eigen::Matrix3d::Identity(), {70, 35.3, 40}), cs);
  REQUIRE(cs.size() == 9);  // f-f, 4 e-f, 4 v-f
  CHECK(cs.num_planes() == 1);
  CHECK(count(cs, PcType::kFF) == 1);
  CHECK(count(cs, PcType::kEF) == 4);
  CHECK(count(cs, PcType::kVF) == 4);
  const cf::ContactPc* ff = find(cs, PcType::kFF, 2, 4);
  REQUIRE(ff);
  CHECK_FALSE(ff->dominated);
  CHECK(ff->distance == Approx(0.3).margin(kTol));
  CHECK((ff->origin_W - Vec3(70, 20, 40)).norm() < kTol);  // centroid of the overlap
  CHECK((ff->p_W - Vec3(70, 20.3, 40)).norm() < kTol);
  CHECK((ff->R_WT.col(1) - Vec3(0, 1, 0)).norm() < kTol);
  check_frame(*ff);
  for (const cf::ContactPc& c : cs) {
    if (c.pc.type != PcType::kFF) CHECK(c.dominated);
    CHECK(c.misfit >= ff->misfit);
    CHECK(c.distance == Approx(0.3).margin(kTol));
  }
}

TEST_CASE("cube half over the slab's edge: overlap centroid of the shared part", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // Cube x in [110, 140]: overlap with the slab top x in [110, 120], z in [25, 55].
  det.detect(pose(Eigen::Matrix3d::Identity(), {125, 35.5, 40}), cs);
  const cf::ContactPc* ff = find(cs, PcType::kFF, 2, 4);
  REQUIRE(ff);
  CHECK((ff->origin_W - Vec3(115, 20, 40)).norm() < kTol);
  CHECK(ff->distance == Approx(0.5).margin(kTol));
  // The slab's edge at x = 120 under the cube's face: f-e, same plane.
  const int e = edge_between(b, 2, 8);
  const cf::ContactPc* fe = find(cs, PcType::kFE, 2, e);
  REQUIRE(fe);
  CHECK(fe->plane == ff->plane);
  CHECK((fe->origin_W - Vec3(120, 20.5, 40)).norm() < kTol);
  CHECK((fe->R_WT.col(0).cross(Vec3(0, 0, 1))).norm() < kTol);  // x along the edge
  check_frame(*fe);
}

TEST_CASE("cube in the corner of the L: two contact planes", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  det.detect(pose(Eigen::Matrix3d::Identity(), {35.2, 35.4, 40}), cs);
  CHECK(cs.num_planes() == 2);
  const cf::ContactPc* slab = find(cs, PcType::kFF, 2, 4);
  const cf::ContactPc* wall = find(cs, PcType::kFF, 5, 5);  // cube face x = -15 on x = 20
  REQUIRE(slab);
  REQUIRE(wall);
  CHECK(slab->distance == Approx(0.4).margin(kTol));
  CHECK(wall->distance == Approx(0.2).margin(kTol));
  CHECK((wall->R_WT.col(1) - Vec3(1, 0, 0)).norm() < kTol);
  CHECK(slab->plane != wall->plane);
}

TEST_CASE("cube on an edge: e-f with the task frame along the edge", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // Rotated 45 degrees about z: the edge through A's vertices 0 and 4 (x = y = -15, along z)
  // is lowest, at height 15 sqrt(2) below the centre.
  const double h = 15 * std::sqrt(2.0);
  det.detect(pose(rot(M_PI / 4, {0, 0, 1}), {70, 20 + h + 0.25, 40}), cs);
  REQUIRE(count(cs, PcType::kEF) == 1);
  const cf::ContactPc& c = *std::find_if(
      cs.begin(), cs.end(), [](const cf::ContactPc& x) { return x.pc.type == PcType::kEF; });
  CHECK(c.pc.a == edge_between(a, 0, 4));  // x = y = -15 turns to (0, -15 sqrt 2)
  CHECK(c.pc.b == 4);
  CHECK(c.distance == Approx(0.25).margin(kTol));
  CHECK((c.origin_W - Vec3(70, 20, 40)).norm() < kTol);
  CHECK((c.p_W - Vec3(70, 20.25, 40)).norm() < kTol);
  CHECK(std::abs(c.R_WT.col(0).dot(Vec3(0, 0, 1))) == Approx(1).margin(kTol));
  check_frame(c);
  CHECK(count(cs, PcType::kVF) == 2);  // its end vertices, dominated
  CHECK(cs.num_planes() == 1);
}

TEST_CASE("a slightly tilted edge gives e-f and the v-f of its lower end (paper Fig. 3)",
          "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  const double h = 15 * std::sqrt(2.0);
  // The e-f's angular tolerance: atan(epsilon / 30 mm) = 0.0333 rad (the whole edge is over
  // the slab). It dominates its end vertices' v-f up to a quarter of that
  // (DetectionParams::dominance_fit): 0.005 rad does, 0.015 rad does not.
  for (const double tilt : {0.005, 0.015}) {
    INFO("tilt " << tilt << " rad");
    const Eigen::Matrix3d R = rot(tilt, {1, 0, 0}) * rot(M_PI / 4, {0, 0, 1});
    det.detect(pose(R, {70, 20 + h + 0.2, 40}), cs);
    const cf::ContactPc* ef = nullptr;
    for (const cf::ContactPc& c : cs)
      if (c.pc.type == PcType::kEF) ef = &c;
    REQUIRE(ef);
    const double shape = ef->misfit - std::abs(ef->distance);  // angle / tolerance (epsilon = 1)
    CHECK(shape == Approx(tilt / std::atan(1.0 / 30)).epsilon(1e-6));
    CHECK_FALSE(ef->dominated);
    // The lower end vertex is within epsilon (the upper one too at 0.005 rad): dominated by
    // the e-f, and worse by the penalty, only at the small tilt.
    int vfs = 0;
    for (const cf::ContactPc& c : cs)
      if (c.pc.type == PcType::kVF) {
        ++vfs;
        CHECK(c.dominated == (tilt < 0.01));
        CHECK(c.misfit == Approx(std::abs(c.distance) + (tilt < 0.01 ? 1.0 : 0.0)).margin(1e-9));
      }
    CHECK(vfs >= 1);
  }
}

TEST_CASE("the f-f tolerance follows the overlap's extent along the tilt, whatever the yaw",
          "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // The cube's bottom face (2) over the slab's top (4), tilted about one of its edges'
  // directions: the heights spread over its 30 mm side, so the tolerance is atan(1/30),
  // however the cube is turned about the slab's normal (a bounding box of the overlap in
  // the slab's frame would give up to atan(1/60) at 45 degrees).
  const double tol = std::atan(1.0 / 30);
  for (const double yaw : {0.0, 0.5, M_PI / 4}) {
    for (const double fraction : {0.9, 1.1}) {
      INFO("yaw " << yaw << ", tilt " << fraction << " x tolerance");
      const Eigen::Matrix3d R = rot(yaw, {0, 1, 0}) * rot(fraction * tol, {1, 0, 0});
      double low = 1e9;
      for (const Vec3& v :
           {Vec3(-15, -15, -15), Vec3(15, -15, -15), Vec3(15, -15, 15), Vec3(-15, -15, 15)})
        low = std::min(low, (R * v).y());
      det.detect(pose(R, {70, 20 + 0.2 - low, 40}), cs);
      const cf::ContactPc* ff = find(cs, PcType::kFF, 2, 4);
      if (fraction < 1) {
        REQUIRE(ff);
        CHECK(ff->distance == Approx(0.2).margin(kTol));
        // The overlap's extent along the tilt, measured in the slab's plane: 30 cos(tilt).
        const double angle = fraction * tol;
        CHECK(ff->misfit ==
              Approx(angle / std::atan(1.0 / (30 * std::cos(angle))) + 0.2).epsilon(1e-9));
      } else {
        CHECK_FALSE(ff);
      }
    }
  }
}

TEST_CASE("the e-f tolerance follows the part of the edge over the face", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // The cube on its edge x = y = -15 (vertices 0-4, along z), turned 45 degrees about z, the
  // edge tilted by 0.05 rad and over the slab's top (z from 0 to 80) for only its last 10 mm:
  // heights 0.1 to 0.6 mm there. The tolerance is atan(1/10) = 0.0997 rad, not the whole
  // edge's atan(1/30) = 0.0333 rad.
  const double tilt = 0.05;
  const Eigen::Matrix3d R = rot(-tilt, {1, 0, 0}) * rot(M_PI / 4, {0, 0, 1});
  const Vec3 mid_A(-15, -15, 0);  // the edge's midpoint
  const Vec3 dir = R * Vec3(0, 0, 1);
  // Edge point at parameter u (mm along the edge from its midpoint): t + R mid_A + u dir.
  // Its far end (u = 15) at z = 10, its point at z = 0 (the slab's front edge) 0.1 mm above
  // the slab's top.
  Vec3 t(70, 0, 0);
  t.z() = 10 - (R * mid_A).z() - 15 * dir.z();
  const double u0 = (0 - t.z() - (R * mid_A).z()) / dir.z();  // at z = 0
  t.y() = 20.1 - (R * mid_A).y() - u0 * dir.y();
  det.detect(pose(R, t), cs);
  const int e04 = edge_between(a, 0, 4);
  const cf::ContactPc* ef = find(cs, PcType::kEF, e04, 4);
  REQUIRE(ef);
  CHECK(ef->distance == Approx(0.1).margin(1e-6));
  const double region = 10 / dir.z();  // the part of the edge over the face
  CHECK(ef->misfit - ef->distance == Approx(tilt / std::atan(1.0 / region)).epsilon(1e-6));
  CHECK(ef->p_W.z() == Approx(5).margin(1e-6));  // the region's centroid
}

TEST_CASE("cube on a corner: a single v-f", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // Turn the diagonal to vertex 0 (-15,-15,-15) straight down.
  const Eigen::Matrix3d R =
      Eigen::Quaterniond::FromTwoVectors(Vec3(-1, -1, -1).normalized(), Vec3(0, -1, 0))
          .toRotationMatrix();
  const Vec3 v0 = R * Vec3(-15, -15, -15);
  det.detect(pose(R, Vec3(70, 20.4, 40) - v0), cs);
  REQUIRE(cs.size() == 1);
  CHECK(cs[0].pc == cf::Pc{PcType::kVF, 0, 4});
  CHECK(cs[0].distance == Approx(0.4).margin(kTol));
  CHECK((cs[0].p_W - Vec3(70, 20.4, 40)).norm() < kTol);
  CHECK((cs[0].origin_W - Vec3(70, 20, 40)).norm() < kTol);
  CHECK_FALSE(cs[0].dominated);
}

TEST_CASE("a face of A on a vertex of B: f-v", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // A's bottom face (2, normal -y in A) tilted so that it slopes away beyond the wall's
  // corner vertex 11 = (0, 80, 80).
  const Vec3 n = Vec3(0.3, -1, -0.2).normalized();
  const Eigen::Matrix3d R =
      Eigen::Quaterniond::FromTwoVectors(Vec3(0, -1, 0), n).toRotationMatrix();
  const Vec3 q(0, 80, 80);
  const double h = 0.6;
  det.detect(pose(R, q - h * n - R * Vec3(0, -15, 0)), cs);
  REQUIRE(cs.size() == 1);
  CHECK(cs[0].pc == cf::Pc{PcType::kFV, 2, 11});
  CHECK(cs[0].distance == Approx(h).margin(kTol));
  CHECK((cs[0].R_WT.col(1) + n).norm() < kTol);
  CHECK((cs[0].p_W - (q - h * n)).norm() < kTol);
  check_frame(cs[0]);
}

TEST_CASE("an edge of A crossing the slab's edge: e-e", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // After Rx(45) the edge from (-15,-15,15) to (15,-15,15) is lowest; Rz(-30) tilts it down
  // towards +x. Its midpoint is put 0.5 mm above the slab's edge x = 120, y = 20.
  const Eigen::Matrix3d R = rot(-M_PI / 6, {0, 0, 1}) * rot(M_PI / 4, {1, 0, 0});
  const Vec3 mid_A(0, -15, 15);
  det.detect(pose(R, Vec3(120, 20.5, 40) - R * mid_A), cs);
  REQUIRE(cs.size() == 1);
  const cf::ContactPc& c = cs[0];
  CHECK(c.pc.type == PcType::kEE);
  CHECK(c.pc.a == edge_between(a, 4, 5));
  CHECK(c.pc.b == edge_between(b, 2, 8));
  CHECK(c.distance == Approx(0.5 * std::cos(M_PI / 6)).margin(kTol));
  CHECK((c.R_WT.col(1) - Vec3(0.5, std::cos(M_PI / 6), 0)).norm() < kTol);
  check_frame(c);
}

TEST_CASE("a reading beside a face counts only while its two points are within the band",
          "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  // The cube's bottom face (2) on the slab's edge x = 120, y = 20 (f-e), turned by 30 degrees
  // about z so that it drops beyond the edge. Its edge x = 15 (vertices 1 and 5) overhangs the
  // slab's edge by `over` along the face: beside the slab's top (face 4) by over cos 30 and
  // below its plane by over sin 30, outside B. Read on face 4 it is a contact at
  // -over sin 30 whose points are `over` apart: within the band (1 mm) at 0.5, not at 1.1,
  // although its in-plane gap (0.95 mm) is within in_plane_tolerance_mm (1 mm).
  const double alpha = M_PI / 6;
  const Eigen::Matrix3d R = rot(-alpha, {0, 0, 1});
  const int edge = edge_between(a, 1, 5);
  for (const double over : {0.5, 1.1}) {
    CAPTURE(over);
    det.detect(pose(R, Vec3(120, 20, 40) - R * Vec3(15 - over, -15, 0)), cs);
    const cf::ContactPc* fe = find(cs, PcType::kFE, 2, edge_between(b, 2, 8));
    REQUIRE(fe);
    CHECK(fe->distance == Approx(0).margin(kTol));
    const cf::ContactPc* ef = find(cs, PcType::kEF, edge, 4);
    const cf::ContactPc* vf1 = find(cs, PcType::kVF, 1, 4);
    const cf::ContactPc* vf5 = find(cs, PcType::kVF, 5, 4);
    if (over < 1) {
      REQUIRE(ef);
      REQUIRE(vf1);
      REQUIRE(vf5);
      CHECK(ef->distance == Approx(-over * std::sin(alpha)).margin(kTol));
      CHECK(vf1->distance == Approx(-over * std::sin(alpha)).margin(kTol));
      CHECK(ef->fit > 0);
    } else {
      CHECK_FALSE(ef);
      CHECK_FALSE(vf1);
      CHECK_FALSE(vf5);
    }
  }
}

TEST_CASE("no contact far away; a deep penetration is not a contact", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  det.detect(pose(Eigen::Matrix3d::Identity(), {70, 60, 40}), cs);
  CHECK(cs.empty());
  det.detect(pose(Eigen::Matrix3d::Identity(), {70, 36.01, 40}), cs);  // 1.01 mm apart
  CHECK(cs.empty());
  det.detect(pose(Eigen::Matrix3d::Identity(), {70, 34.5, 40}), cs);  // 0.5 mm deep
  CHECK(count(cs, PcType::kFF) == 1);
  CHECK(find(cs, PcType::kFF, 2, 4)->distance == Approx(-0.5).margin(kTol));
}

TEST_CASE("bad parameters are rejected with their name", "[detector]") {
  cf::Params p;
  p.epsilon_mm = -1;
  CHECK_THROWS_WITH(cf::ContactDetector(tmod::cube(), tmod::l_block(), p),
                    Catch::Contains("parameter epsilon_mm = -1 is outside [1e-06, 1000] mm"));
  p = cf::Params();
  p.detection.deepest_contact_mm = std::nan("");
  CHECK_THROWS_WITH(
      cf::ContactDetector(tmod::cube(), tmod::l_block(), p),
      Catch::Contains("parameter detection.deepest_contact_mm = nan is outside [0, 1000000] mm"));
}

TEST_CASE("overlap of polygons with holes matches Boost.Geometry", "[detector]") {
  namespace bg = boost::geometry;
  using BPoint = bg::model::d2::point_xy<double>;
  using BPoly = bg::model::polygon<BPoint, false>;  // counter-clockwise outer rings
  // P: 10 x 10 square with a 4 x 4 hole; Q: an L-shaped hexagon, shifted around.
  std::vector<cf::internal::Vec2> p = {{0, 0}, {10, 0}, {10, 10}, {0, 10},
                                       {3, 3}, {3, 7},  {7, 7},   {7, 3}};
  const int plb[] = {0, 4, 8};
  const cf::internal::Poly2 P{p.data(), plb, 2};
  BPoly bp;
  bg::read_wkt("POLYGON((0 0,10 0,10 10,0 10,0 0),(3 3,3 7,7 7,7 3,3 3))", bp);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-8, 8);
  std::vector<double> scratch(64);
  for (int k = 0; k < 200; ++k) {
    const double dx = U(rng), dy = U(rng);
    std::vector<cf::internal::Vec2> q = {{0, 0}, {8, 0}, {8, 3}, {3, 3}, {3, 8}, {0, 8}};
    for (auto& v : q) v += cf::internal::Vec2(dx, dy);
    if (k % 10 == 0)  // exact edge coincidences
      for (auto& v : q) v -= cf::internal::Vec2(dx, dy);
    const int qlb[] = {0, 6};
    const cf::internal::Poly2 Q{q.data(), qlb, 1};
    const cf::internal::Overlap2 ov =
        cf::internal::overlap(P, Q, 1e-9, scratch.data(), [](const auto&) {});
    BPoly bq;
    for (const auto& v : q) bg::append(bq.outer(), BPoint(v.x(), v.y()));
    bg::append(bq.outer(), BPoint(q[0].x(), q[0].y()));
    std::vector<BPoly> inter;
    bg::intersection(bp, bq, inter);
    double area = 0, cx = 0, cy = 0;
    for (const BPoly& g : inter) {
      const double ag = bg::area(g);
      BPoint c(0, 0);
      bg::centroid(g, c);
      area += ag;
      cx += ag * c.x();
      cy += ag * c.y();
    }
    INFO("shift " << dx << ", " << dy);
    CHECK(ov.area == Approx(area).margin(1e-9));
    if (area > 1e-6) {
      CHECK(ov.centroid.x() == Approx(cx / area).margin(1e-9));
      CHECK(ov.centroid.y() == Approx(cy / area).margin(1e-9));
    }
  }
}

TEST_CASE("overlap of convex polygons by clipping matches the general routine and Boost.Geometry",
          "[detector]") {
  namespace bg = boost::geometry;
  using BPoint = bg::model::d2::point_xy<double>;
  using BPoly = bg::model::polygon<BPoint, false>;
  using cf::internal::Vec2;
  // Random convex polygons of 3 to 8 sides (points on a perturbed circle, in angle order),
  // sometimes sharing vertices and edges exactly, sometimes with collinear corners.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  auto convex_poly = [&](const Vec2& c, double r) {
    const int n = 3 + static_cast<int>(6 * U(rng));
    std::vector<double> ang;
    for (int i = 0; i < n; ++i) ang.push_back(6.283185307179586 * U(rng));
    std::sort(ang.begin(), ang.end());
    std::vector<Vec2> pts;
    for (double a : ang) pts.push_back(c + r * Vec2(std::cos(a), std::sin(a)));
    if (U(rng) < 0.2) pts.insert(pts.begin() + 1, 0.5 * (pts[0] + pts[1]));  // a collinear corner
    return pts;
  };
  std::vector<double> scratch(64);
  std::vector<Vec2> buf(2 * 32);
  int compared = 0, overlapping = 0;
  for (int k = 0; k < 2000; ++k) {
    std::vector<Vec2> p = convex_poly(Vec2::Zero(), 5);
    std::vector<Vec2> q =
        k % 7 == 0 ? p : convex_poly(Vec2(8 * U(rng) - 4, 8 * U(rng) - 4), 1 + 5 * U(rng));
    if (k % 7 == 0) std::rotate(q.begin(), q.begin() + 1, q.end());  // the same polygon
    const int plb[] = {0, static_cast<int>(p.size())}, qlb[] = {0, static_cast<int>(q.size())};
    const cf::internal::Poly2 P{p.data(), plb, 1}, Q{q.data(), qlb, 1};
    REQUIRE(cf::internal::is_convex(P));
    REQUIRE(cf::internal::is_convex(Q));
    // A linear function's minimum and maximum over the visited vertices (what ff takes).
    const Vec2 g(0.3, -0.7);
    double lo_c = 1e300, hi_c = -1e300, lo_g = 1e300, hi_g = -1e300;
    cf::internal::Overlap2 oc;
    REQUIRE(cf::internal::overlap_convex(P, Q, buf.data(), 32, oc, [&](const Vec2& v) {
      lo_c = std::min(lo_c, g.dot(v));
      hi_c = std::max(hi_c, g.dot(v));
    }));
    const cf::internal::Overlap2 og =
        cf::internal::overlap(P, Q, 1e-9, scratch.data(), [&](const Vec2& v) {
          lo_g = std::min(lo_g, g.dot(v));
          hi_g = std::max(hi_g, g.dot(v));
        });
    BPoly bp, bq;
    for (const auto& v : p) bg::append(bp.outer(), BPoint(v.x(), v.y()));
    bg::append(bp.outer(), BPoint(p[0].x(), p[0].y()));
    for (const auto& v : q) bg::append(bq.outer(), BPoint(v.x(), v.y()));
    bg::append(bq.outer(), BPoint(q[0].x(), q[0].y()));
    std::vector<BPoly> inter;
    bg::intersection(bp, bq, inter);
    double area = 0;
    for (const BPoly& r : inter) area += bg::area(r);
    INFO("case " << k);
    // Coordinates of a few mm: rounding of a few clipping steps, far below 1e-9. Boost's
    // default robustness policy snaps to an integer grid (about 1e-7 of the extent): 1e-5
    // of area against it.
    CHECK(oc.area == Approx(og.area).margin(1e-9));
    CHECK(oc.area == Approx(area).margin(1e-5));
    ++compared;
    if (og.area > 1e-6) {
      ++overlapping;
      CHECK(oc.centroid.x() == Approx(og.centroid.x()).margin(1e-9));
      CHECK(oc.centroid.y() == Approx(og.centroid.y()).margin(1e-9));
      CHECK(lo_c == Approx(lo_g).margin(1e-9));
      CHECK(hi_c == Approx(hi_g).margin(1e-9));
    }
  }
  CHECK(overlapping > 1000);
  CHECK(compared - overlapping > 100);
}

TEST_CASE("a segment clipped by a convex polygon matches the general routine", "[detector]") {
  using cf::internal::Vec2;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<double> scratch(64);
  int crossing = 0, missing = 0, along = 0;
  for (int k = 0; k < 5000; ++k) {
    // A random convex polygon of 3 to 8 sides, counter-clockwise, radius 5.
    const int n = 3 + static_cast<int>(6 * U(rng));
    std::vector<double> ang;
    for (int i = 0; i < n; ++i) ang.push_back(6.283185307179586 * U(rng));
    std::sort(ang.begin(), ang.end());
    std::vector<Vec2> p;
    for (double a : ang) p.push_back(5 * Vec2(std::cos(a), std::sin(a)));
    const int lb[] = {0, n};
    const cf::internal::Poly2 P{p.data(), lb, 1};
    // Nearly straight corners are left out: there the two routines' tol bands differ by
    // tol / sin(corner's turn) (below).
    bool sharp = true;
    for (int c = 0; c < n; ++c) {
      const Vec2 u = p[static_cast<std::size_t>((c + 1) % n)] - p[static_cast<std::size_t>(c)];
      const Vec2 v =
          p[static_cast<std::size_t>((c + 2) % n)] - p[static_cast<std::size_t>((c + 1) % n)];
      sharp = sharp && cf::internal::cross2(u, v) > 0.01 * u.norm() * v.norm();
    }
    if (!sharp) continue;
    // Segments: random, through two vertices, along an edge (exactly, and beyond its ends).
    Vec2 a(12 * U(rng) - 6, 12 * U(rng) - 6), b(12 * U(rng) - 6, 12 * U(rng) - 6);
    const int i = static_cast<int>(n * U(rng)) % n, j = (i + 1) % n;
    if (k % 5 == 1)
      a = p[static_cast<std::size_t>(i)], b = p[static_cast<std::size_t>((i + 2) % n)];
    if (k % 5 == 2) {
      const Vec2 e = p[static_cast<std::size_t>(j)] - p[static_cast<std::size_t>(i)];
      a = p[static_cast<std::size_t>(i)] - 0.5 * U(rng) * e;
      b = p[static_cast<std::size_t>(j)] + 0.5 * U(rng) * e;
      ++along;
    }
    double g0 = 2, g1 = -1, len = 0;
    cf::internal::clip_segment(a, b, P, 1e-9, cf::internal::OnBoundary::kInclude, scratch.data(),
                               [&](double t0, double t1) {
                                 g0 = std::min(g0, t0);
                                 g1 = std::max(g1, t1);
                                 len += t1 - t0;
                               });
    double c0 = 0, c1 = 0;
    const bool hit = cf::internal::clip_segment_convex(a, b, P, 1e-9, &c0, &c1);
    INFO("case " << k);
    // A convex polygon cuts a segment in one piece. Both routines take the boundary within
    // tol (1e-9) as inside, the general one by the distance of each piece's midpoint, this
    // one by moving each edge's line out by tol; so where the segment grazes an edge or
    // passes a corner their ends differ by tol / sin(angle), 1e-9 / 0.01 for these corners
    // and more for the rare grazing segment: 1e-6 of the parameter.
    if (len > 1e-6) {
      REQUIRE(hit);
      ++crossing;
      CHECK(len == Approx(g1 - g0).margin(1e-9));
      CHECK(c0 == Approx(g0).margin(1e-6));
      CHECK(c1 == Approx(g1).margin(1e-6));
    } else {
      CHECK((!hit || c1 - c0 < 1e-6));
      ++missing;
    }
  }
  CHECK(crossing > 1000);
  CHECK(missing > 300);
  CHECK(along > 500);
}

TEST_CASE("convexity: one loop, no reflex corner", "[detector]") {
  using cf::internal::Vec2;
  std::vector<Vec2> square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  std::vector<Vec2> l_shape = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<Vec2> holed = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {1, 1}, {1, 3}, {3, 3}, {3, 1}};
  const int lb4[] = {0, 4}, lb6[] = {0, 6}, lb44[] = {0, 4, 8};
  CHECK(cf::internal::is_convex({square.data(), lb4, 1}));
  CHECK_FALSE(cf::internal::is_convex({l_shape.data(), lb6, 1}));
  CHECK_FALSE(cf::internal::is_convex({holed.data(), lb44, 2}));
}

namespace {
cf::Params band(double eps) {
  cf::Params p;
  p.epsilon_mm = p.detection.deepest_contact_mm = eps;
  return p;
}
cf::Params all_pairs(cf::Params p) {
  p.detection.use_bvh = false;
  return p;
}
cf::Params not_kept(cf::Params p) {
  p.detection.reuse_margin_mm = 0;
  return p;
}
// One model pair under a detector and a reference detector (all pairs, or no kept pairs),
// posed alike; x and y hold their last results.
struct Twin {
  cf::ContactDetector det, ref;
  cf::ContactSet x, y;
  Twin(const cf::Polyhedron& a, const cf::Polyhedron& b, const cf::Params& p, const cf::Params& q)
      : det(a, b, p), ref(a, b, q) {}
  void detect(const cf::Pose& pose) {
    det.detect(pose, x);
    ref.detect(pose, y);
  }
};
// Culled detection against all pairs: the same PCs, in the same order, at the same distances.
void check_same_contacts(const cf::ContactSet& x, const cf::ContactSet& y) {
  REQUIRE(x.size() == y.size());
  for (int i = 0; i < x.size(); ++i) {
    CHECK(x[i].pc == y[i].pc);
    CHECK(x[i].distance == y[i].distance);
  }
}
// Kept pairs against none: that, and the same dominance and contact planes.
void check_same_readings(const cf::ContactSet& x, const cf::ContactSet& y) {
  REQUIRE(x.size() == y.size());
  for (int i = 0; i < x.size(); ++i) {
    CHECK(x[i].pc == y[i].pc);
    CHECK(x[i].distance == y[i].distance);
    CHECK(x[i].dominated == y[i].dominated);
    CHECK(x[i].plane == y[i].plane);
  }
}
}  // namespace

TEST_CASE("the BVH finds what all pairs find on faceted spheres", "[detector]") {
  // 600 and 672 faces: enough for the culling to matter (leaves of several elements and
  // oriented boxes), small enough for all pairs. The paper's threshold and one scaled to the
  // facets (2 to 7 mm here): the boxes' inflation changes by ten.
  const double eps = GENERATE(1.0, 0.1);
  // Models centred on their frames' origins, and far from them (single-precision boxes must
  // not lose contacts there).
  const bool far = GENERATE(false, true);
  const Vec3 ca = far ? Vec3(4000, -3000, 2500) : Vec3::Zero(),
             cb = far ? Vec3(-2500, 1500, 3000) : Vec3::Zero();
  const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30, ca);
  const cf::Polyhedron b = tmod::faceted_sphere(50, 21, 32, cb);
  Twin t(a, b, band(eps), all_pairs(band(eps)));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  int contacts = 0;
  // Gaps from 1.1 epsilon apart (nothing) to 1.1 epsilon deep (beyond deepest_contact_mm):
  // the band's edges on both sides.
  for (int k = 0; k < 32; ++k) {
    const Vec3 dir = Vec3(U(rng), U(rng), U(rng)).normalized();
    const Eigen::Matrix3d R = rot(3 * U(rng), Vec3(U(rng), U(rng), U(rng)));
    const cf::Pose p = pose(R, cb + dir * (80 + 1.1 * eps * U(rng)) - R * ca);
    t.detect(p);
    INFO("epsilon " << eps << ", far " << far << ", pose " << k);
    check_same_contacts(t.x, t.y);
    contacts += t.x.size();
    CHECK(t.det.last_pairs_tested() * 100 < t.ref.last_pairs_tested());
  }
  CHECK(contacts > 0);
}

TEST_CASE("the BVH finds what all pairs find for a big model against a small one, either way",
          "[detector]") {
  // A 600-face sphere (face-group leaves, wide nodes) against the paper's L-block and cube
  // (one element per leaf): the culling mixes both kinds of tree.
  const double eps = GENERATE(1.0, 0.1);
  const int which = GENERATE(0, 1, 2);
  const cf::Polyhedron sphere = tmod::faceted_sphere(30, 20, 30, Vec3(5, -3, 2));
  const cf::Polyhedron a = which == 0 ? sphere : which == 1 ? tmod::cube() : tmod::l_block();
  const cf::Polyhedron b = which == 0 ? tmod::l_block() : sphere;
  Twin t(a, b, band(eps), all_pairs(band(eps)));
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> U(-1, 1);
  int contacts = 0;
  for (int k = 0; k < 24; ++k) {
    // A's lowest point along -dir on B's highest along dir, with a gap across the band: A
    // lies beyond B's supporting plane, so it touches B there and nowhere deeper.
    const Vec3 dir = Vec3(U(rng), U(rng), U(rng)).normalized();
    const Eigen::Matrix3d R = rot(3 * U(rng), Vec3(U(rng), U(rng), U(rng)));
    Vec3 top = b.vertex(cf::VertexId(0)).p, low = R * a.vertex(cf::VertexId(0)).p;
    for (const cf::Vertex& v : b.vertices())
      if (dir.dot(v.p) > dir.dot(top)) top = v.p;
    for (const cf::Vertex& v : a.vertices())
      if (dir.dot(R * v.p) < dir.dot(low)) low = R * v.p;
    const cf::Pose p = pose(R, top + 1.1 * eps * U(rng) * dir - low);
    t.detect(p);
    INFO("epsilon " << eps << ", pair " << which << ", pose " << k);
    check_same_contacts(t.x, t.y);
    contacts += t.x.size();
    CHECK(t.det.last_pairs_tested() * 10 < t.ref.last_pairs_tested());
  }
  CHECK(contacts > 24);
}

namespace {
// A faceted torus about the z axis (major radius R, minor r): planar trapezoids, outward;
// its inner half is saddle-shaped, with reflex edges.
cf::Polyhedron faceted_torus(double R, double r, int around, int across) {
  std::vector<Vec3> v;
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j) {
      const double th = 2 * M_PI * i / around, ph = 2 * M_PI * j / across;
      v.emplace_back((R + r * std::cos(ph)) * std::cos(th), (R + r * std::cos(ph)) * std::sin(th),
                     r * std::sin(ph));
    }
  const auto at = [&](int i, int j) { return (i % around) * across + (j % across); };
  std::vector<std::vector<int>> f;
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < across; ++j)
      f.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  return tmod::from_loops("torus", v, f);
}

}  // namespace

TEST_CASE("the BVH finds what all pairs find in a torus's hole", "[detector]") {
  // A 384-face sphere in the hole of a 384-face torus, touching its inner, saddle-shaped
  // side (reflex edges, non-convex surroundings) on one side and then another.
  const double eps = GENERATE(1.0, 0.1);
  const cf::Polyhedron a = tmod::faceted_sphere(18, 16, 24), b = faceted_torus(30, 10, 24, 16);
  Twin t(a, b, band(eps), all_pairs(band(eps)));
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> U(-1, 1);
  int contacts = 0, reflex = 0;
  for (int k = 0; k < 8; ++k) {
    // The hole's radius is 20 (less the facets' sagitta, ~0.2 mm): A's centre moved 1.6 to
    // 2 mm towards the ring brings that side into the band.
    const double az = M_PI * U(rng);
    const Vec3 off =
        (1.8 + 0.2 * U(rng)) * Vec3(std::cos(az), std::sin(az), 0) + Vec3(0, 0, 2 * U(rng));
    const cf::Pose p = pose(rot(3 * U(rng), Vec3(U(rng), U(rng), U(rng))), off);
    t.detect(p);
    INFO("epsilon " << eps << ", pose " << k);
    // Within ContactSet's capacity: past it, which contacts are kept depends on the order
    // they are found in.
    REQUIRE(!t.y.overflow());
    check_same_contacts(t.x, t.y);
    for (const cf::ContactPc& c : t.x)
      if (c.pc.type == PcType::kFE && !b.edges()[static_cast<std::size_t>(c.pc.b)].convex) ++reflex;
    contacts += t.x.size();
  }
  CHECK(contacts > 8);
  CHECK(reflex == 0);  // a face never touches a reflex edge as f-e
}

TEST_CASE("pairs kept between nearby poses give what the hierarchy gives", "[detector]") {
  // A 600-face sphere rolling and sliding over a 672-face one in small steps (about 0.06 mm
  // and 0.5 mrad per tick, a hand's speed at a servo rate, plus the gap's change), with
  // jumps of 5 mm now and then: every result must equal the one without kept pairs, and most
  // ticks must reuse.
  const double eps = GENERATE(1.0, 0.1);
  const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30);
  const cf::Polyhedron b = tmod::faceted_sphere(50, 21, 32);
  REQUIRE(band(eps).detection.reuse_margin_mm > 0);
  Twin t(a, b, band(eps), not_kept(band(eps)));
  int reused = 0, contacts = 0;
  const int n = 400;
  for (int k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / n;
    const Vec3 dir =
        Vec3(std::cos(0.3 * s), 0.03 * std::sin(1.7 * s), std::sin(0.3 * s)).normalized();
    const Eigen::Matrix3d R = rot(0.2 * s, Vec3(1, 2, 3));
    // The facets lie up to 0.4 mm (sagittas 0.15 and 0.25) inside the spheres: centre gaps
    // swinging by an epsilon around 0.15 mm deep keep the meshes in or near the band.
    const double gap = (k % 100 == 50) ? 5.0 : eps * 0.5 * std::sin(20 * s) - 0.15;
    const cf::Pose p = pose(R, dir * (80 + gap));
    t.detect(p);
    INFO("epsilon " << eps << ", tick " << k);
    check_same_readings(t.x, t.y);
    CHECK_FALSE(t.ref.last_reused_pairs());
    reused += t.det.last_reused_pairs() ? 1 : 0;
    contacts += t.x.size();
  }
  CAPTURE(contacts, reused);
  CHECK(contacts > 50);  // contacts on a good share of the ticks (over 100 at either epsilon)
  CHECK(reused > n / 2);
  // Poses far apart are never served from kept pairs.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int k = 0; k < 20; ++k) {
    const cf::Pose p = pose(rot(3 * U(rng), Vec3(U(rng), U(rng), U(rng))),
                            Vec3(U(rng), U(rng), U(rng)).normalized() * 80);
    t.detect(p);
    CHECK_FALSE(t.det.last_reused_pairs());
    REQUIRE(t.x.size() == t.y.size());
    for (int i = 0; i < t.x.size(); ++i) CHECK(t.x[i].pc == t.y[i].pc);
  }
}

namespace {
// Detects along `poses` with kept pairs (warm) and without (cold): every result must be the
// same. Returns the ticks served from kept pairs and, over those ticks, the pairs each
// detector took past the boxes to the cheap rejections.
struct WarmCold {
  int reused = 0, contacts = 0;
  std::size_t warm_pairs = 0, cold_pairs = 0;
};
WarmCold compare_warm_cold(const cf::Polyhedron& a, const cf::Polyhedron& b, double eps,
                           const std::vector<cf::Pose>& poses,
                           double reuse_margin_mm = cf::DetectionParams{}.reuse_margin_mm) {
  cf::Params prm = band(eps);
  prm.detection.reuse_margin_mm = reuse_margin_mm;
  Twin t(a, b, prm, not_kept(prm));
  WarmCold r;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    t.detect(poses[k]);
    INFO("epsilon " << eps << ", tick " << k);
    REQUIRE(!t.y.overflow());
    check_same_readings(t.x, t.y);
    if (t.det.last_reused_pairs()) {
      ++r.reused;
      r.warm_pairs += t.det.last_pairs_tested();
      r.cold_pairs += t.ref.last_pairs_tested();
    }
    r.contacts += t.x.size();
  }
  return r;
}
}  // namespace

TEST_CASE("kept pairs' certificates never hide a contact", "[detector]") {
  // Kept pairs turned away skip their tests while A has moved (or turned) less than their
  // certificates allow; these trajectories turn A fast relative to its motion, so that the
  // rotational certificates (edges and wedges dipping into the other solid) expire and
  // renew all the time, and one puts reflex edges on A (turned away for good).
  const double eps = GENERATE(1.0, 0.1);
  const int n = 300;
  SECTION("a sphere spinning on a sphere") {
    // 1.5 mrad per tick about a slowly turning axis (0.045 mm of its facets' travel per tick,
    // about the most for which pairs are still kept), the centre drifting 0.02 mm per tick,
    // the gap swinging through the band (the facets lie up to 0.4 mm inside the spheres).
    const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30), b = tmod::faceted_sphere(50, 21, 32);
    std::vector<cf::Pose> poses;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    for (int k = 0; k < n; ++k) {
      const double s = static_cast<double>(k) / n;
      R = rot(0.0015, Vec3(std::cos(3 * s), std::sin(3 * s), 0.5)) * R;
      const Vec3 dir = Vec3(std::sin(0.02 * k / 80), 0.03 * std::sin(2 * s), 1).normalized();
      const double gap = eps * 0.6 * std::sin(9 * s) - 0.2;
      poses.push_back(pose(R, dir * (80 + gap)));
    }
    const WarmCold r = compare_warm_cold(a, b, eps, poses);
    CAPTURE(r.contacts, r.reused, r.warm_pairs, r.cold_pairs);
    CHECK(r.contacts > n / 4);  // at either epsilon (over 100)
    CHECK(r.reused > n / 2);
    // The certificates skip most pairs: the test exercises them.
    CHECK(2 * r.warm_pairs < r.cold_pairs);
  }
  SECTION("a torus rocking and spinning on a sphere") {
    // The torus (ring radius 30, tube 10) over a sphere of radius 50, its axis 8 mm off
    // the sphere's centre: the nearest point of its tube's centre circle is 60 from the
    // sphere's centre at a height of sqrt(60^2 - 22^2 - ...) = sqrt(2700 + 60 * 8 - 8^2)
    // = 55.82, less 0.7 mm for the facets. The contact is on the inner,
    // saddle-shaped side of the tube (reflex edges) over about a quarter of the ring. The
    // torus spins 1 mrad per tick about its axis and rocks by up to 0.03 rad.
    const cf::Polyhedron a = faceted_torus(30, 10, 24, 16), b = tmod::faceted_sphere(50, 21, 32);
    std::vector<cf::Pose> poses;
    for (int k = 0; k < n; ++k) {
      const double s = static_cast<double>(k) / n;
      const Eigen::Matrix3d R =
          rot(0.03 * std::sin(7 * s), Vec3(std::cos(2 * s), std::sin(2 * s), 0)) *
          rot(0.001 * k, Vec3::UnitZ());
      const double h = std::sqrt(2700.0 + 60 * 8 - 8 * 8) - 0.7 + eps * 0.6 * std::sin(11 * s);
      poses.push_back(pose(R, Vec3(8, 0, h)));
    }
    const WarmCold r = compare_warm_cold(a, b, eps, poses);
    CAPTURE(r.contacts, r.reused, r.warm_pairs, r.cold_pairs);
    CHECK(r.contacts > n / 4);  // at either epsilon (over 200)
    CHECK(r.reused > n / 2);
    CHECK(2 * r.warm_pairs < r.cold_pairs);
  }
  SECTION("a sphere toggling between two nearby poses") {
    // A device's noise at its worst: back and forth between a pose and one 0.1 mm and
    // 3 mrad from it. The pairs are kept at the first; a certificate earned at the second
    // (a pair moved or turned away there) must not be read as if from the first when A is
    // back at the first. 30 poses in contact at random, 6 ticks each: first, first (pairs
    // kept), second, first, second, first.
    const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30), b = tmod::faceted_sphere(50, 21, 32);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> U(-1, 1);
    std::vector<cf::Pose> poses;
    for (int k = 0; k < 30; ++k) {
      const Vec3 dir = Vec3(U(rng), U(rng), U(rng)).normalized();
      const Eigen::Matrix3d R = rot(3 * U(rng), Vec3(U(rng), U(rng), U(rng)));
      const cf::Pose first = pose(R, dir * (80 - 0.2 + 0.4 * eps * U(rng)));
      const cf::Pose second = pose(rot(0.003, Vec3(U(rng), U(rng), U(rng))) * R,
                                   first.t_BA + 0.1 * Vec3(U(rng), U(rng), U(rng)).normalized());
      for (const cf::Pose* p : {&first, &first, &second, &first, &second, &first})
        poses.push_back(*p);
    }
    const WarmCold r = compare_warm_cold(a, b, eps, poses);
    CAPTURE(r.contacts, r.reused, r.warm_pairs, r.cold_pairs);
    CHECK(r.contacts > static_cast<int>(poses.size()) / 4);
    CHECK(r.reused == 4 * 30);  // all but the first two ticks at each pose
    CHECK(2 * r.warm_pairs < r.cold_pairs);
  }
  SECTION("a sphere pressed in and drawn out, kept pairs serving for 1 mm") {
    // Straight along the line of the centres, 0.04 mm per tick, from 1.5 epsilon apart to
    // 0.8 epsilon deep (plus the facets' 0.4 mm) and back, with a slow turn: the heights
    // change as fast as the motion bound allows, and a margin of 1 mm (beyond B's boxes'
    // growth past the band, 0.41 epsilon) lets pairs kept apart by the boxes come into
    // the band while their certificates are in use.
    const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30), b = tmod::faceted_sphere(50, 21, 32);
    const Vec3 dir = Vec3(0.2, -0.3, 1).normalized();
    std::vector<cf::Pose> poses;
    double gap = 1.5 * eps;
    double step = -0.04;
    for (int k = 0; k < n; ++k) {
      gap += step;
      if (gap < -0.8 * eps - 0.4 || gap > 1.5 * eps) step = -step;
      poses.push_back(pose(rot(0.0002 * k, Vec3(1, 1, 0)), dir * (80 + gap)));
    }
    const WarmCold r = compare_warm_cold(a, b, eps, poses, 1.0);
    CAPTURE(r.contacts, r.reused, r.warm_pairs, r.cold_pairs);
    CHECK(r.contacts > n / 4);
    CHECK(r.reused > n / 2);
    // Kept within 1 mm, at epsilon 0.1 mm ten times as many pairs as the boxes pass: fewer
    // tested than the boxes pass still shows the certificates at work.
    CHECK(r.warm_pairs < r.cold_pairs);
  }
}

TEST_CASE("kept pairs serve rotations, and rotations rounded to float", "[detector]") {
  // A's sphere centred 500 mm from its frame's origin, so that R^T R - I, times that
  // centre, shifts B's points as A sees them (the f-v and f-e certificates assume a
  // rotation). Rotations rounded to float (1e-7 off) are served from kept pairs, results
  // unchanged; rotations 1e-4 off orthonormal are detected from scratch, results unchanged.
  const double eps = GENERATE(1.0, 0.1);
  const Vec3 centre(300, -400, 0);
  const cf::Polyhedron a = tmod::faceted_sphere(30, 20, 30, centre),
                       b = tmod::faceted_sphere(50, 21, 32);
  const int n = 200;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const bool far_off : {false, true}) {
    std::vector<cf::Pose> poses;
    for (int k = 0; k < n; ++k) {
      const double s = static_cast<double>(k) / n;
      Eigen::Matrix3d R = rot(0.0005 * k, Vec3(1, 2, 3));
      if (far_off) {
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) R(i, j) += 1e-4 * U(rng);
      } else {
        R = R.cast<float>().cast<double>();
      }
      // A's centre (R centre + t) 80 mm from B's along a slowly turning direction (0.04
      // mm per tick, and 0.5 mrad).
      const Vec3 dir =
          Vec3(std::cos(0.1 * s), 0.02 * std::sin(3 * s), std::sin(0.1 * s)).normalized();
      const double gap = eps * 0.6 * std::sin(9 * s) - 0.2;
      poses.push_back(pose(R, dir * (80 + gap) - R * centre));
    }
    INFO((far_off ? "rotations 1e-4 off orthonormal" : "rotations rounded to float"));
    const WarmCold r = compare_warm_cold(a, b, eps, poses);
    CAPTURE(r.contacts, r.reused);
    CHECK(r.contacts > n / 4);
    if (far_off)
      CHECK(r.reused == 0);
    else
      CHECK(r.reused > n / 2);
  }
}

TEST_CASE("a negative reuse margin is refused", "[detector]") {
  cf::Params p;
  p.detection.reuse_margin_mm = -0.1;
  CHECK_THROWS_WITH(
      cf::ContactDetector(tmod::cube(), tmod::l_block(), p),
      Catch::Contains("parameter detection.reuse_margin_mm = -0.1 is outside [0, 1000000] mm"));
}

// The centre of the slab's plane (ContactPc::centre_W) along a sweep of poses: that of its
// deepest contact.
std::vector<Vec3> slab_centres(const std::vector<cf::Pose>& poses) {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  std::vector<Vec3> out;
  for (const cf::Pose& p : poses) {
    det.detect(p, cs);
    const cf::ContactPc* deepest = nullptr;
    for (const cf::ContactPc& c : cs)
      if (c.R_WT.col(1).y() > 0.99 && (!deepest || c.distance < deepest->distance)) deepest = &c;
    REQUIRE(deepest);
    out.push_back(deepest->centre_W);
  }
  return out;
}

// Largest step between consecutive centres over the mean step: a centre that jumped where a
// contact joins or leaves the plane (at a tolerance, or as its offset crosses epsilon) would
// make one step a sizeable share of the whole travel, tens of mean steps.
double largest_over_mean_step(const std::vector<Vec3>& c) {
  double largest = 0, sum = 0;
  for (std::size_t i = 1; i < c.size(); ++i) {
    const double s = (c[i] - c[i - 1]).norm();
    largest = std::max(largest, s), sum += s;
  }
  return largest / (sum / static_cast<double>(c.size() - 1));
}

TEST_CASE("a plane's force acts at the depth-weighted centre of its contacts", "[detector]") {
  const cf::Polyhedron a = tmod::cube(), b = tmod::l_block();
  cf::ContactDetector det(a, b);
  cf::ContactSet cs;
  SECTION("flush: the f-f, its edges' e-f and its corners' v-f weigh alike: the region's") {
    det.detect(pose(Eigen::Matrix3d::Identity(), {70, 35.3, 40}), cs);
    REQUIRE(cs.size() == 9);
    for (const cf::ContactPc& c : cs) {
      CHECK(c.fit == Approx(1));
      CHECK((c.centre_W - Vec3(70, 20.3, 40)).norm() < kTol);
    }
  }
  SECTION("tilting through the f-f tolerance, the centre runs to the low edge continuously") {
    // About z through the low edge x = 55 (cube corner at -15, -15), the edge 0.3 mm up: the
    // f-f's tolerance atan(1 / 30) = 0.033 rad is passed at step 333 of 600.
    std::vector<cf::Pose> poses;
    for (int i = 0; i <= 600; ++i) {
      const Eigen::Matrix3d R = rot(1e-4 * i, {0, 0, 1});
      const Vec3 low = R * Vec3(-15, -15, 0);
      poses.push_back(pose(R, Vec3(55, 20.3, 40) - low));
    }
    const std::vector<Vec3> c = slab_centres(poses);
    CHECK(c.front().x() == Approx(70).margin(1e-9));
    CHECK(c.back().x() == Approx(55).margin(1e-6));  // the low edge alone is in the band
    CHECK(largest_over_mean_step(c) < 5);
  }
  SECTION("a face lowered over the slab's outer edge: the f-e joins the plane continuously") {
    // The cube over x = 120 (half over the slab), turned 0.5 degrees about x: the f-e of its
    // bottom on the slab's edge lies in the cube's plane, epsilon-close to the slab's.
    std::vector<cf::Pose> poses;
    for (int i = 0; i <= 400; ++i)
      poses.push_back(pose(rot(0.5 * M_PI / 180, {1, 0, 0}), {128, 35.98 - 0.001 * i, 40}));
    CHECK(largest_over_mean_step(slab_centres(poses)) < 5);
  }
}

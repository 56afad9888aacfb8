// The generator's only CGAL translation unit.
#include "cfgen/verify/cgal_support.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <map>
#include <set>

namespace cf::gen {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct FaceInfo {
  int nesting = -1;
  bool in_domain() const { return nesting % 2 == 1; }
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fb0 = CGAL::Triangulation_face_base_with_info_2<FaceInfo, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fb0>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

// The classic nesting-level flood fill: faces inside an odd number of loops are in the domain.
void mark_domains(Cdt& cdt) {
  std::vector<Cdt::Face_handle> border;
  auto flood = [&](Cdt::Face_handle start, int level) {
    std::vector<Cdt::Face_handle> queue{start};
    while (!queue.empty()) {
      auto f = queue.back();
      queue.pop_back();
      if (f->info().nesting != -1) continue;
      f->info().nesting = level;
      for (int i = 0; i < 3; ++i) {
        Cdt::Edge e(f, i);
        auto n = f->neighbor(i);
        if (n->info().nesting == -1) (cdt.is_constrained(e) ? border : queue).push_back(n);
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    auto f = border.back();
    border.pop_back();
    if (f->info().nesting != -1) continue;
    int level = 0;
    for (int i = 0; i < 3; ++i) {
      auto n = f->neighbor(i);
      if (n->info().nesting != -1 && cdt.is_constrained(Cdt::Edge(f, i))) {
        level = n->info().nesting + 1;
        break;
      }
    }
    flood(f, level);
  }
}

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

bool is_convex(const std::vector<int>& poly, const std::vector<Eigen::Vector2d>& pts) {
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    if (cross(pts[poly[i]], pts[poly[(i + 1) % n]], pts[poly[(i + 2) % n]]) < -1e-12) return false;
  return true;
}

}  // namespace

std::vector<ConvexPiece> convex_partition(const std::vector<std::vector<Eigen::Vector2d>>& loops) {
  std::vector<Eigen::Vector2d> pts;
  std::set<std::pair<int, int>> boundary;  // directed sides of the loops (interior on the left)
  Cdt cdt;
  for (const auto& loop : loops) {
    const int base = static_cast<int>(pts.size());
    std::vector<Cdt::Vertex_handle> vh;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      pts.push_back(loop[k]);
      vh.push_back(cdt.insert(K::Point_2(loop[k].x(), loop[k].y())));
      vh.back()->info() = base + static_cast<int>(k);
    }
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const std::size_t k1 = (k + 1) % loop.size();
      cdt.insert_constraint(vh[k], vh[k1]);
      boundary.insert({base + static_cast<int>(k), base + static_cast<int>(k1)});
    }
  }
  mark_domains(cdt);
  // Triangles (CCW), then greedy Hertel-Mehlhorn merging across diagonals.
  std::vector<std::vector<int>> polys;
  for (auto f : cdt.finite_face_handles())
    if (f->info().in_domain())
      polys.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
  std::sort(polys.begin(), polys.end());  // deterministic order
  bool merged = true;
  while (merged) {
    merged = false;
    std::map<std::pair<int, int>, int> side_owner;
    for (std::size_t p = 0; p < polys.size(); ++p)
      for (std::size_t k = 0; k < polys[p].size(); ++k)
        side_owner[{polys[p][k], polys[p][(k + 1) % polys[p].size()]}] = static_cast<int>(p);
    for (std::size_t p = 0; p < polys.size() && !merged; ++p) {
      const auto& P = polys[p];
      for (std::size_t k = 0; k < P.size() && !merged; ++k) {
        const int a = P[k], b = P[(k + 1) % P.size()];
        if (boundary.count({a, b})) continue;
        auto it = side_owner.find({b, a});
        if (it == side_owner.end() || it->second == static_cast<int>(p)) continue;
        const auto& Q = polys[it->second];
        // P: ... a b ...; Q: ... b a ... -> walk P from b to a, then Q from a to b.
        std::vector<int> m;
        const std::size_t ib = (k + 1) % P.size();
        for (std::size_t i = 0; i < P.size(); ++i) m.push_back(P[(ib + i) % P.size()]);
        m.pop_back();  // drop a; Q supplies it
        const std::size_t qa =
            static_cast<std::size_t>(std::find(Q.begin(), Q.end(), a) - Q.begin());
        for (std::size_t i = 0; i + 1 < Q.size(); ++i) m.push_back(Q[(qa + i) % Q.size()]);
        if (!is_convex(m, pts)) continue;
        const int q = it->second;
        polys[p] = m;
        polys.erase(polys.begin() + q);
        merged = true;
      }
    }
  }
  std::vector<ConvexPiece> out;
  for (const auto& P : polys) {
    ConvexPiece piece;
    for (std::size_t k = 0; k < P.size(); ++k) {
      piece.points.push_back(pts[P[k]]);
      piece.boundary.push_back(boundary.count({P[k], P[(k + 1) % P.size()]}) > 0);
    }
    out.push_back(std::move(piece));
  }
  return out;
}

}  // namespace cf::gen

#pragma once
// A large synthetic CF graph for the graph reader's tests and benchmarks.

#include "fixtures.hpp"

#include <cf/graph.hpp>

#include <Eigen/Geometry>

#include <random>
#include <vector>

namespace cf::test {

inline bool share_plane(const cf::Pc& x, const cf::Pc& y) {
  using K = cf::ElementKind;
  return (cf::a_kind(x.type) == K::kFace && cf::a_kind(y.type) == K::kFace && x.a == y.a) ||
         (cf::b_kind(x.type) == K::kFace && cf::b_kind(y.type) == K::kFace && x.b == y.b);
}

/// A synthetic graph of `num_cfs` CFs of the cube against the small L-block of fixtures.hpp:
/// every single PC, then two-PC CFs of principal pairs, with 4 transitions each (gain and
/// lose to both single PCs), random full-precision witnesses and freedoms on the two-PC CFs.
/// Not a valid contact graph (the witnesses are random), but a valid file: what the graph
/// reader's tests and benchmarks need in bulk.
inline cf::CfGraph synthetic_graph(std::size_t num_cfs) {
  const cf::Polyhedron a = cf::test::box(10, 10, 10, "cube"), b = cf::test::small_l_block();
  std::vector<cf::Pc> singles;
  for (int t = 0; t < 6; ++t) {
    const auto type = static_cast<cf::PcType>(t);
    auto count = [](const cf::Polyhedron& m, cf::ElementKind k) {
      return static_cast<int>(k == cf::ElementKind::kVertex ? m.num_vertices()
                              : k == cf::ElementKind::kEdge ? m.num_edges()
                                                            : m.num_faces());
    };
    for (int i = 0; i < count(a, cf::a_kind(type)); ++i)
      for (int j = 0; j < count(b, cf::b_kind(type)); ++j) singles.push_back({type, i, j});
  }
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-50, 50);
  auto witness = [&] {
    cf::Pose p;
    p.R_BA = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
                 .normalized()
                 .toRotationMatrix();
    p.t_BA = cf::Vec3(uniform(rng), uniform(rng), uniform(rng));
    return p;
  };
  std::vector<cf::CfRecord> cfs;
  std::vector<cf::Transition> transitions;
  for (const cf::Pc& p : singles) {
    cf::CfRecord r;
    r.pcs = cf::PcSet({p});
    r.witness = witness();
    cfs.push_back(r);
    if (cfs.size() == num_cfs) break;
  }
  for (std::size_t i = 0; i < singles.size() && cfs.size() < num_cfs; ++i)
    for (std::size_t j = i + 1; j < singles.size() && cfs.size() < num_cfs; ++j) {
      // A CF's PCs are principal: none on a plane another holds, none dominating another.
      if (share_plane(singles[i], singles[j]) || cf::dominates(a, b, singles[i], singles[j]) ||
          cf::dominates(a, b, singles[j], singles[i]))
        continue;
      cf::CfRecord r;
      r.pcs = cf::PcSet({singles[i], singles[j]});
      r.witness = witness();
      r.dof = 2;
      r.translation_dof = 1;
      const cf::CfId id(static_cast<int>(cfs.size()));
      cfs.push_back(r);
      const cf::CfId ci(static_cast<int>(i)), cj(static_cast<int>(j));
      transitions.push_back({ci, id, cf::TransitionKind::kGain});
      transitions.push_back({cj, id, cf::TransitionKind::kGain});
      transitions.push_back({id, ci, cf::TransitionKind::kLose});
      transitions.push_back({id, cj, cf::TransitionKind::kLose});
    }
  return cf::CfGraph::from_parts(a, b, std::move(cfs), std::move(transitions),
                                 R"({"stats":{"synthetic":true}})");
}

}  // namespace cf::test

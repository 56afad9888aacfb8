#include "transitions.hpp"

#include <algorithm>
#include <numeric>

namespace oracle {

namespace {

// Kinds as Poly::in_closure numbers them.
constexpr int kV = 0, kE = 1, kF = 2;

// `x` is the PC with the larger element(s): the one the degenerate touch leaves.
bool neighbour_dir(const Poly& A, const Poly& B, const Pc& x, const Pc& y) {
  auto edge_bounds = [](const Poly& P, int e, int f) { return P.in_closure(kE, e, kF, f); };
  auto vertex_ends = [](const Poly& P, int v, int e) { return P.in_closure(kV, v, kE, e); };
  using T = PcType;
  if (x.type == T::FF && y.type == T::EF) return x.b == y.b && edge_bounds(A, y.a, x.a);
  if (x.type == T::FF && y.type == T::FE) return x.a == y.a && edge_bounds(B, y.b, x.b);
  if (x.type == T::EF && y.type == T::VF) return x.b == y.b && vertex_ends(A, y.a, x.a);
  if (x.type == T::EF && y.type == T::EE) return x.a == y.a && edge_bounds(B, y.b, x.b);
  if (x.type == T::FE && y.type == T::FV) return x.a == y.a && vertex_ends(B, y.b, x.b);
  if (x.type == T::FE && y.type == T::EE) return x.b == y.b && edge_bounds(A, y.a, x.a);
  if (x.type == T::VF && y.type == T::EE)
    return vertex_ends(A, x.a, y.a) && edge_bounds(B, y.b, x.b);
  if (x.type == T::FV && y.type == T::EE)
    return vertex_ends(B, x.b, y.b) && edge_bounds(A, y.a, x.a);
  return false;
}

}  // namespace

bool neighbouring_pcs(const Poly& A, const Poly& B, const Pc& x, const Pc& y) {
  return neighbour_dir(A, B, x, y) || neighbour_dir(A, B, y, x);
}

bool is_gain(const CfKey& from, const CfKey& to) {
  if (to.size() != from.size() + 1) return false;
  return std::includes(to.begin(), to.end(), from.begin(), from.end());
}

bool is_change(const Poly& A, const Poly& B, const CfKey& from, const CfKey& to) {
  if (from.size() != to.size() || from == to) return false;
  std::vector<std::size_t> perm(to.size());
  std::iota(perm.begin(), perm.end(), std::size_t{0});
  do {
    bool ok = true;
    for (std::size_t i = 0; i < from.size() && ok; ++i) {
      const Pc& x = from[i];
      const Pc& y = to[perm[i]];
      ok = x == y || neighbouring_pcs(A, B, x, y);
    }
    if (ok) return true;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return false;
}

}  // namespace oracle

#pragma once
// Test helpers: elements of an oracle Poly found by their coordinates (tests/oracle tests only;
// a lookup that finds nothing fails the running Catch2 test).

#include "poly.hpp"

#include <catch2/catch.hpp>

namespace oracle::test {

/// The vertex of P exactly at x.
inline int vertex_at(const Poly& P, const Vec3& x) {
  for (std::size_t v = 0; v < P.V.size(); ++v)
    if (P.V[v].p == x) return static_cast<int>(v);
  FAIL("no vertex at (" << x.transpose() << ") in " << P.name);
  return -1;
}

/// The edge from vertex v towards `dir` (within 1e-12 of its cosine: exact directions).
inline int edge_along(const Poly& P, int v, const Vec3& dir) {
  for (int e : P.V[v].edges) {
    const int o = P.E[e].v0 == v ? P.E[e].v1 : P.E[e].v0;
    if ((P.V[o].p - P.V[v].p).normalized().dot(dir.normalized()) > 1 - 1e-12) return e;
  }
  FAIL("no edge of " << P.name << " from vertex " << v << " along (" << dir.transpose() << ")");
  return -1;
}

}  // namespace oracle::test

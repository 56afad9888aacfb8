#pragma once
// Two models with the generator's per-model analysis (tools/cfgen/verify/analysis.hpp), for the
// tests of cfgen's parts. Only for tests that link cfgen_core.

#include "cfgen/verify/analysis.hpp"

#include <cf/polyhedron.hpp>

#include <utility>

namespace cf::test {

/// A against B, each analysed once; the ModelInfo point into the held models, so the pair
/// is neither copied nor moved.
struct AnalysedPair {
  Polyhedron A, B;
  cf::gen::ModelInfo ai, bi;
  AnalysedPair(Polyhedron a, Polyhedron b) : A(std::move(a)), B(std::move(b)) {
    ai = cf::gen::analyse_model(A);
    bi = cf::gen::analyse_model(B);
  }
  AnalysedPair(const AnalysedPair&) = delete;
  AnalysedPair& operator=(const AnalysedPair&) = delete;
};

}  // namespace cf::test

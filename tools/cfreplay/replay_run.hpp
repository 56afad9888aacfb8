#pragma once
// Runs the renderer over a trajectory: one output row per servo tick (docs/spec.md, section 5b).

#include "replay_io.hpp"

#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/renderer.hpp>

#include <functional>
#include <vector>

namespace cf::replay {

/// Fills a row from one renderer result.
Row make_row(const HapticResult& r);

/// Steps a fresh renderer over the samples. `each`, when given, sees every result (tests use
/// it for the per-PC diagnostics).
std::vector<Row> run(const CfGraph& graph, const std::vector<Sample>& samples, const Params& params,
                     const std::function<void(const Sample&, const HapticResult&)>& each = {});

}  // namespace cf::replay

#pragma once
/// @file
/// The certificate file (`cfgen --certificates FILE`, docs/certificates.md): every failed
/// candidate set of a run with its outcome and evidence, for a checker that shares no code with
/// cfgen.

#include "cfgen/decide/witness.hpp"
#include "cfgen/enumerate/enumerate.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace cf::tools {

/// A THIN set (gen::Enumeration::thin) as the graph's `stats.thin_sets` and the certificate
/// file list it: {"pcs", "clearance_mm", "margin_mm", "pose": {"R": rows, "t": mm}}.
nlohmann::json thin_set_json(const PcSet& pcs, const gen::Witness& w);

/// Writes `e.decisions` (a run with EnumerateOptions::certificates) as the certificate file at
/// `path`, whole or not at all, never over one of `inputs`. graph_path: the graph written
/// beside it, named in the file. search: the run's search (its models and tolerances).
/// @throws cf::Error "writing certificates '<path>': <reason>".
void write_certificates(const std::string& path, const std::vector<std::string>& inputs,
                        const std::string& graph_path, const gen::Enumeration& e,
                        const gen::WitnessSearch& search);

}  // namespace cf::tools

#pragma once
// Private: model <-> nlohmann::json, shared by the model reader and the graph reader.

#include <cf/polyhedron.hpp>

#include "json_util.hpp"

namespace cf::internal {

json polyhedron_to_json(const Polyhedron& model);

/// Reads a model object found at `where` (e.g. /models/A of a graph file).
/// @throws cf::Error naming the source and the JSON pointer of the fault.
Polyhedron polyhedron_from_json(const json& j, const JsonWhere& where);

}  // namespace cf::internal

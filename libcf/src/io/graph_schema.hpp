#pragma once
// Private: the graph file's JSON Schema (schemas/cf-graph.schema.json, embedded at build
// time) and validation against it with valijson.

#include <cf/graph.hpp>  // graph_schema_text()

#include <nlohmann/json.hpp>

#include <string>

namespace cf::internal {

/// The text of schemas/model.schema.json, which the graph schema refers to for models.A/B.
const char* model_schema_text();

/// Validates a whole graph document against the schema.
/// @throws cf::Error "reading '<source>' at <JSON pointer>: does not match the cf-graph
///   schema: <complaint>" for the first (deepest) violation.
void validate_graph_schema(const nlohmann::json& document, const std::string& source);

/// Validates one item of the graph's `cfs` (is_cf) or `transitions` array, number `index`,
/// against its definition in the schema: the full check reads the items one at a time.
/// @throws cf::Error as validate_graph_schema, the pointer starting /cfs/<index> or
///   /transitions/<index>.
void validate_graph_item(const nlohmann::json& item, bool is_cf, std::size_t index,
                         const std::string& source);

}  // namespace cf::internal

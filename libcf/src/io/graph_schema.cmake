# Embeds schemas/cf-graph.schema.json and the model schema it refers to
# (schemas/model.schema.json) into the library (graph_schema_text.cpp), so that
# CfGraph::load validates without finding the schemas at run time. Re-runs when they change.
set(_cf_graph_schema ${cf_root}/schemas/cf-graph.schema.json)
set(_cf_model_schema ${cf_root}/schemas/model.schema.json)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_cf_graph_schema} ${_cf_model_schema})
file(READ ${_cf_graph_schema} CF_GRAPH_SCHEMA_TEXT)
file(READ ${_cf_model_schema} CF_MODEL_SCHEMA_TEXT)
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/src/io/graph_schema_text.cpp.in
  ${CMAKE_CURRENT_BINARY_DIR}/graph_schema_text.cpp @ONLY)

# runtime_graph_test: identification and rendering on the generated default graphs. Included
# from tests/libcf/CMakeLists.txt when cfgen and cfreplay are built. Two fixture tests run
# cfgen on the default model pairs into this build tree; every runtime_graph_test case
# requires them and finds the graphs through CF_RUNTIME_GRAPH_DIR.
if(NOT TARGET cfgen OR NOT TARGET cfreplay)
  return()
endif()
set(cf_runtime_graph_dir ${CMAKE_CURRENT_BINARY_DIR}/runtime_graphs)
file(MAKE_DIRECTORY ${cf_runtime_graph_dir})
foreach(b l_block corner_block)
  add_test(NAME runtime_graph_generate_${b}
    COMMAND cfgen --quiet ${PROJECT_SOURCE_DIR}/data/models/cube.off
      ${PROJECT_SOURCE_DIR}/data/models/${b}.off -o ${cf_runtime_graph_dir}/cube_${b}.json)
  set_tests_properties(runtime_graph_generate_${b} PROPERTIES FIXTURES_SETUP cf_runtime_graphs TIMEOUT 300)
endforeach()

add_executable(runtime_graph_test runtime_graph_test.cpp)
target_link_libraries(runtime_graph_test PRIVATE cf_test_main cf::cf cf_warnings)
add_dependencies(runtime_graph_test cfgen)
catch_discover_tests(runtime_graph_test TEST_PREFIX "runtime_graph_test:"
  PROPERTIES TIMEOUT 600 FIXTURES_REQUIRED cf_runtime_graphs
    ENVIRONMENT CF_RUNTIME_GRAPH_DIR=${cf_runtime_graph_dir})

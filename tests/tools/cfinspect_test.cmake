# cfinspect tests. Included from tests/tools/CMakeLists.txt, this file registers the tests; run
# with `cmake -P` it is the checker each test runs: it runs cfinspect with ARGS and checks
# the exit status, the output against EXPECT (a regex), and for failures that stderr is
# exactly one line.
if(CMAKE_SCRIPT_MODE_FILE)
  separate_arguments(args UNIX_COMMAND "${ARGS}")
  execute_process(COMMAND ${CFINSPECT} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(MODE STREQUAL "fail")
    if(rc EQUAL 0)
      message(FATAL_ERROR "expected a non-zero exit status, got 0\nstdout: ${out}\nstderr: ${err}")
    endif()
    string(REGEX MATCHALL "\n" lines "${err}")
    list(LENGTH lines n)
    if(NOT n EQUAL 1)
      message(FATAL_ERROR "expected one line on stderr, got ${n}:\n${err}")
    endif()
    if(NOT err MATCHES "${EXPECT}")
      message(FATAL_ERROR "stderr does not match '${EXPECT}':\n${err}")
    endif()
  else()
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "exit status ${rc}\nstderr: ${err}")
    endif()
    if(NOT out MATCHES "${EXPECT}")
      message(FATAL_ERROR "stdout does not match '${EXPECT}':\n${out}")
    endif()
    if(DEFINED FILE_OUT)
      file(READ "${FILE_OUT}" content)
      if(NOT content MATCHES "${FILE_EXPECT}")
        message(FATAL_ERROR "${FILE_OUT} does not match '${FILE_EXPECT}':\n${content}")
      endif()
    endif()
    if(DEFINED SAME_AS)
      file(READ "${SAME_AS}" want)
      if(NOT out STREQUAL want)
        message(FATAL_ERROR "stdout differs from ${SAME_AS}")
      endif()
    endif()
  endif()
  return()
endif()

if(NOT TARGET cfinspect)
  return()
endif()
set(_g ${CF_TEST_DATA_DIR}/graphs)
set(_out ${CMAKE_CURRENT_BINARY_DIR}/cfinspect_out)
file(MAKE_DIRECTORY ${_out})
function(cfinspect_test name mode args expect)
  add_test(NAME cfinspect:${name}
    COMMAND ${CMAKE_COMMAND} -DCFINSPECT=$<TARGET_FILE:cfinspect> -DMODE=${mode} "-DARGS=${args}"
            "-DEXPECT=${expect}" ${ARGN} -P ${CMAKE_CURRENT_SOURCE_DIR}/cfinspect_test.cmake)
  set_tests_properties(cfinspect:${name} PROPERTIES TIMEOUT 120 LABELS cfinspect)
endfunction()

# What the witness check says of N CFs: verified by cfgen's verify, or not checked in a build
# without CGAL (the sanitizer build).
function(witnesses_checked out n)
  if(CF_WITH_CGAL)
    set(${out} "; ${n} witnesses verified" PARENT_SCOPE)
  else()
    set(${out} "; witnesses not checked: built without CGAL" PARENT_SCOPE)
  endif()
endfunction()

# Summary and queries on the hand-made cube / L-block graph (see tests/libcf/graph_test.cpp).
witnesses_checked(_w5 5)
cfinspect_test(summary ok "${_g}/box_l.json"
  "valid cf-graph v1 \\(schema check, items by the reader's rules${_w5}\\).*model A 'cube': 8 vertices, 12 edges \\(0 reflex\\), 6 faces.*model B 'L-block': 12 vertices, 18 edges \\(1 reflex\\), 8 faces.*CFs: 5.*by number of PCs: 1: 4, 2: 1, 3: 0.*f-f 4 \\(3\\), e-f 1 \\(1\\), f-e 0 \\(0\\), v-f 1 \\(1\\).*transitions: 8 \\(gain 2, lose 2, change 4\\), 0 without their reverse.*out-degree: min 1, mean 1.60, max 2.*connected components: 1 \\(largest 5 CFs, 0 isolated CFs\\)")
cfinspect_test(summary_sorted_keys ok "${_g}/box_l_sorted.json" "CFs: 5")
cfinspect_test(summary_json ok "${_g}/box_l.json --json"
  "\"valid\": true.*\"count\": 5.*\"2\": 1.*\"by_kind\": {[^}]*\"gain\": 2,[^}]*\"change\": 4.*\"components\": {[^}]*\"count\": 1")
cfinspect_test(holding ok "${_g}/box_l.json --holding f-f:2:4"
  "2 CFs hold f-f:2:4\n  CF 0: f-f:2:4\n  CF 2: f-f:2:4;f-f:5:5\n")
cfinspect_test(holding_none ok "${_g}/box_l.json --holding e-e:0:0" "^0 CFs hold e-e:0:0\n$")
cfinspect_test(neighbours ok "${_g}/box_l.json --neighbours 2"
  "CF 2 {f-f:2:4;f-f:5:5}: 2 transitions\n  -> CF 0 lose {f-f:2:4}\n  -> CF 1 lose {f-f:5:5}\n")
cfinspect_test(neighbours_json ok "${_g}/box_l.json --neighbours 3 --json"
  "\"neighbours\": \\[.*\"to\": 0,.*\"kind\": \"change\".*\"to\": 4,")
cfinspect_test(cf ok "${_g}/box_l.json --cf 3"
  "CF 3: e-f:0:4\n  witness R \\(rows\\):\n +\\[ *1, +0, +0\\]\n.*witness t \\(mm\\): \\[20, 10, +5\\]")
cfinspect_test(pose ok "${_g}/box_l.json --pose 20,10.3,5,1,0,0,0"
  "pose: matched-by-fit, CF 0 {f-f:2:4}, [0-9]+ candidate PCs within 1 mm\n  f-f:2:4 at 0.3 mm")
cfinspect_test(pose_no_contact ok "${_g}/box_l.json --pose 20,30,5,1,0,0,0" "pose: no-contact, CF -1")
cfinspect_test(dot ok "${_g}/box_l.json --dot ${_out}/box_l.dot" "wrote .*box_l.dot \\(5 nodes, 8 edges\\)"
  -DFILE_OUT=${_out}/box_l.dot
  "-DFILE_EXPECT=^digraph G {.*2\\[label=\"2: f-f:2:4;f-f:5:5\"\\];.*0->2 \\[label=\"gain\", style=solid\\];.*2->0 \\[label=\"lose\", style=dashed\\];.*3->4 \\[label=\"change\", style=dotted\\];")
cfinspect_test(print_schema ok "--print-schema" "draft-07" -DSAME_AS=${PROJECT_SOURCE_DIR}/schemas/cf-graph.schema.json)
cfinspect_test(help ok "--help" "--holding.*--neighbours.*--dot.*--pose.*--json.*--verify")
cfinspect_test(summary_fast ok "${_g}/box_l.json --fast" "valid cf-graph v1 \\(schema check, items by the reader's rules\\)\n")
cfinspect_test(summary_full_schema ok "${_g}/box_l.json --full-schema --fast"
  "valid cf-graph v1 \\(full schema check\\)\n")
cfinspect_test(summary_json_schema ok "${_g}/box_l.json --json --fast" "\"schema_check\": \"reader\"")
if(CF_WITH_CGAL)
  cfinspect_test(summary_fast_verify ok "${_g}/box_l.json --fast --verify -j 1"
    "valid cf-graph v1 \\(schema check, items by the reader's rules; 5 witnesses verified\\)")
  cfinspect_test(summary_json_witnesses ok "${_g}/box_l.json --json" "\"witnesses_verified\": 5")
else()
  cfinspect_test(verify_without_cgal fail "${_g}/box_l.json --verify"
    "--verify: this cfinspect was built without CGAL")
endif()

# Every error: non-zero exit, one line on stderr naming the file and the problem.
cfinspect_test(missing_file fail "${_g}/no_such.json" "^cfinspect: reading '.*no_such.json': cannot open: no such file\n$")
cfinspect_test(truncated fail "${_g}/bad/truncated.json" "reading '.*truncated.json': not valid JSON: syntax error at line 6, column 45")
cfinspect_test(schema_violation fail "${_g}/bad/schema_violation.json" "'.*schema_violation.json' at /stats: does not match the cf-graph schema")
cfinspect_test(witness_extra fail "${_g}/bad/witness_extra_member.json" "'.*witness_extra_member.json' at /cfs/2/witness")
cfinspect_test(index_out_of_range fail "${_g}/bad/index_out_of_range.json" "'.*index_out_of_range.json' at /cfs/3/pcs/0/b: e-f PC: b = 99")
cfinspect_test(missing_cf fail "${_g}/bad/missing_cf_transition.json" "at /transitions/2/to: to = 17 is not a CF id")
cfinspect_test(wrong_format fail "${_g}/bad/wrong_format.json" "at /format: format is \"cf-table\"")
cfinspect_test(corrupt_cbor fail "${_g}/bad/corrupt.cbor" "corrupt.cbor': not valid CBOR")
cfinspect_test(bad_cf_id fail "${_g}/box_l.json --cf 5" "'.*box_l.json': CF 5 does not exist \\(the graph has 5 CFs\\)")
cfinspect_test(bad_holding fail "${_g}/box_l.json --holding v-v:1:2" "--holding 'v-v:1:2': expected TYPE:A:B")
cfinspect_test(holding_range fail "${_g}/box_l.json --holding v-f:99:1" "--holding 'v-f:99:1': v-f PC: a = 99 is not an index into the vertices of model A 'cube'")
cfinspect_test(bad_pose fail "${_g}/box_l.json --pose 1,2,x,1,0,0,0" "--pose '1,2,x,1,0,0,0': 'x' is not a number")
cfinspect_test(dot_unwritable fail "${_g}/box_l.json --dot ${_out}/no/such/dir/x.dot" "writing DOT '.*x.dot': the directory '.*no/such/dir' does not exist")
cfinspect_test(no_args fail "" "no graph file given")
cfinspect_test(bad_option fail "${_g}/box_l.json --bogus" "--bogus")

# Every graph shipped in data/graphs must pass the full schema check and the witness check (docs/spec.md, section 5:
# "every written graph validates"). Globbed at configure time: re-run cmake after adding one.
file(GLOB _data_graphs ${PROJECT_SOURCE_DIR}/data/graphs/*.json ${PROJECT_SOURCE_DIR}/data/graphs/*.cbor)
foreach(_graph IN LISTS _data_graphs)
  get_filename_component(_name ${_graph} NAME)
  witnesses_checked(_w "[0-9]+")
  cfinspect_test(data_${_name} ok "${_graph} --full-schema" "valid cf-graph v1 \\(full schema check${_w}\\)")
endforeach()

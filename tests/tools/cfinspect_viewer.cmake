# Tests of cfinspect --html (the browser viewer, tools/cfinspect/viewer). Included from
# tests/tools/CMakeLists.txt after cfinspect_test.cmake, whose cfinspect_test() it uses.
if(NOT TARGET cfinspect)
  return()
endif()
set(_v ${CF_TEST_DATA_DIR}/viewer)
set(_box ${CF_TEST_DATA_DIR}/graphs/box_l.json)

# The command line: bad combinations and bad replays fail with one line naming the file.
cfinspect_test(html_replay_without_html fail "${_box} --replay ${_v}/replay_box_l.csv" "--replay and --trajectory go with --html")
cfinspect_test(html_over_graph fail "${_box} --html ${_box}" "writing HTML '.*box_l.json'")
if(CF_HAVE_VIEWER)
  cfinspect_test(html ok "${_box} --html ${_out}/box_l.html --replay ${_v}/replay_box_l.csv --cf 1"
    "wrote .*box_l.html \\(viewer of 5 CFs, with the replay\\)"
    -DFILE_OUT=${_out}/box_l.html "-DFILE_EXPECT=<script id=\"cf-graph\" type=\"application/json\">.*\"format\": \"cf-graph\".*id=\"cf-replay\".*\"cf\":1")
  cfinspect_test(html_replay_not_csv fail "${_box} --html ${_out}/x.html --replay ${_v}/two_poses.csv"
    "replay '.*two_poses.csv': not a cfreplay CSV")
  cfinspect_test(html_replay_bad_cf fail "${_box} --html ${_out}/x.html --replay ${_v}/replay_bad_cf.csv"
    "replay '.*replay_bad_cf.csv' line 2: CF '7' is not a CF of the graph \\(5 CFs\\)")
  cfinspect_test(html_trajectory_mismatch fail
    "${_box} --html ${_out}/x.html --replay ${_v}/replay_box_l.csv --trajectory ${_v}/two_poses.csv"
    "trajectory '.*two_poses.csv': 2 poses, but replay '.*' has 3 rows")
else()
  cfinspect_test(html_not_built fail "${_box} --html ${_out}/x.html" "built without the browser viewer")
endif()

# The page in headless Chromium (tools/cfinspect/viewer/test/viewer_test.mjs): exit 77 is a
# skip, when Chromium or the npm packages are missing outside CI; under CI=true it fails.
set(_why "")
if(NOT CF_NODE)
  set(_why "node not found")
elseif(NOT CF_HAVE_VIEWER)
  set(_why "cfinspect was built without the viewer (bash scripts/install-npm.sh, then configure again)")
elseif(NOT TARGET cfreplay)
  set(_why "no cfreplay target")
endif()
if(_why STREQUAL "")
  add_test(NAME cfinspect:viewer_browser
    COMMAND ${CF_NODE} ${PROJECT_SOURCE_DIR}/tools/cfinspect/viewer/test/viewer_test.mjs
      --cfinspect $<TARGET_FILE:cfinspect> --cfreplay $<TARGET_FILE:cfreplay>
      --graph ${PROJECT_SOURCE_DIR}/data/graphs/cube_l_block.json
      --trajectory ${PROJECT_SOURCE_DIR}/data/trajectories/cube_lblock_corner.csv
      --press ${PROJECT_SOURCE_DIR}/data/trajectories/cube_lblock_press.csv
      --out ${CMAKE_CURRENT_BINARY_DIR}/viewer_out)
else()
  add_test(NAME cfinspect:viewer_browser
    COMMAND sh -c "echo 'viewer_test: SKIPPED: ${_why}'; if [ \"$CI\" = true ]; then echo 'CI must run it' >&2; exit 1; fi; exit 77")
endif()
set_tests_properties(cfinspect:viewer_browser PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 180 LABELS "cfinspect;viewer")

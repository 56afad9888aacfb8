# Proves that the installed cf package works for a consumer (run by CTest as
# `cmake -D... -P check_package.cmake`):
#   1. installs libcf alone (its build directory's install rules) into a private prefix;
#   2. checks that no installed public header includes Boost, nlohmann_json or CGAL;
#   3. configures examples/consumer against that prefix with Boost, nlohmann_json and CGAL
#      made unfindable, builds it and runs it (it exits 0 when the cube's volume is right
#      and its servo loop renders the slab's push);
#   4. the same for examples/haptic_loop (when HAPTIC_LOOP_SOURCE_DIR is set), run for 1.5 s
#      at 1 kHz with --check on GRAPH (a device pressing into the L-block's floor).
# Inputs: CF_LIBCF_BINARY_DIR, CF_CONFIG, CONSUMER_SOURCE_DIR, WORK_DIR, GENERATOR,
#         MAKE_PROGRAM, CXX_COMPILER, CXX_COMPILER_LAUNCHER (optional),
#         HAPTIC_LOOP_SOURCE_DIR and GRAPH (optional).
cmake_minimum_required(VERSION 3.20)

foreach(var CF_LIBCF_BINARY_DIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "check_package.cmake: ${var} is not set")
  endif()
endforeach()
if(NOT CF_CONFIG)
  set(CF_CONFIG Release)
endif()

set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/build")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

message(STATUS "1. install libcf into ${prefix}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" --install "${CF_LIBCF_BINARY_DIR}" --prefix "${prefix}"
          --config "${CF_CONFIG}"
  COMMAND_ERROR_IS_FATAL ANY)

message(STATUS "2. installed public headers must not include private dependencies")
file(GLOB_RECURSE headers "${prefix}/include/cf/*")
if(NOT headers)
  message(FATAL_ERROR "no headers installed under ${prefix}/include/cf")
endif()
foreach(header IN LISTS headers)
  file(STRINGS "${header}" bad REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"](boost|nlohmann|CGAL)/")
  if(bad)
    message(FATAL_ERROR "${header} includes a private dependency: ${bad}")
  endif()
endforeach()

# Configures SOURCE against the installed package into BUILD, builds it, runs PROGRAM with
# the remaining arguments and fails unless it exits 0.
set(common_args --no-warn-unused-cli -G "${GENERATOR}"
  "-DCMAKE_BUILD_TYPE=${CF_CONFIG}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
  "-DCMAKE_PREFIX_PATH=${prefix}"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
  # Consumers need Eigen only: make the private dependencies unfindable (cfConfig.cmake
  # must not look for them; CMake then reports these variables as unused).
  -DCMAKE_DISABLE_FIND_PACKAGE_Boost=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON
  -DCMAKE_DISABLE_FIND_PACKAGE_CGAL=ON)
if(MAKE_PROGRAM)
  list(APPEND common_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER_LAUNCHER)
  list(APPEND common_args "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}")
endif()
function(build_and_run source build program expectation)
  execute_process(COMMAND "${CMAKE_COMMAND}" ${common_args} -S "${source}" -B "${build}" COMMAND_ERROR_IS_FATAL ANY)
  execute_process(COMMAND "${CMAKE_COMMAND}" --build "${build}" --config "${CF_CONFIG}" COMMAND_ERROR_IS_FATAL ANY)
  # Ninja/Makefiles put the program in the build directory, multi-config generators in a
  # per-configuration subdirectory.
  set(exe "${build}/${program}")
  if(NOT EXISTS "${exe}")
    set(exe "${build}/${CF_CONFIG}/${program}")
  endif()
  execute_process(COMMAND "${exe}" ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "${program} exited with ${result} (expected 0: ${expectation})")
  endif()
endfunction()

message(STATUS "3. configure, build and run examples/consumer against the installed package")
build_and_run("${CONSUMER_SOURCE_DIR}" "${consumer_build}" cf_consumer
              "volume 1000 mm^3 and the slab pushing the cube up")

if(HAPTIC_LOOP_SOURCE_DIR)
  message(STATUS "4. configure, build and run examples/haptic_loop against the installed package")
  build_and_run("${HAPTIC_LOOP_SOURCE_DIR}" "${WORK_DIR}/build-loop" cf_haptic_loop
                "--check: the rate held, a CF on every tick inside B, the proxy on the surface"
                --graph "${GRAPH}" --rate 1000 --duration 1.5 --check
                --trace "${WORK_DIR}/trace.csv" --device "${WORK_DIR}/device.csv")
endif()
message(STATUS "installed package OK")

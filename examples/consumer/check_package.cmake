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

message(STATUS "3. configure, build and run examples/consumer against the installed package")
set(configure_args --no-warn-unused-cli
  -S "${CONSUMER_SOURCE_DIR}" -B "${consumer_build}" -G "${GENERATOR}"
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
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER_LAUNCHER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" ${configure_args} COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${consumer_build}" --config "${CF_CONFIG}"
                COMMAND_ERROR_IS_FATAL ANY)

# Ninja/Makefiles put the program in the build directory, multi-config generators in a
# per-configuration subdirectory.
set(program "${consumer_build}/cf_consumer")
if(NOT EXISTS "${program}")
  set(program "${consumer_build}/${CF_CONFIG}/cf_consumer")
endif()
execute_process(COMMAND "${program}" RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "cf_consumer exited with ${result} (expected 0: volume 1000 mm^3)")
endif()

if(HAPTIC_LOOP_SOURCE_DIR)
  message(STATUS "4. configure, build and run examples/haptic_loop against the installed package")
  set(loop_build "${WORK_DIR}/build-loop")
  set(loop_args ${configure_args})
  list(TRANSFORM loop_args REPLACE "^${CONSUMER_SOURCE_DIR}$" "${HAPTIC_LOOP_SOURCE_DIR}")
  list(TRANSFORM loop_args REPLACE "^${consumer_build}$" "${loop_build}")
  execute_process(COMMAND "${CMAKE_COMMAND}" ${loop_args} COMMAND_ERROR_IS_FATAL ANY)
  execute_process(COMMAND "${CMAKE_COMMAND}" --build "${loop_build}" --config "${CF_CONFIG}"
                  COMMAND_ERROR_IS_FATAL ANY)
  set(loop "${loop_build}/cf_haptic_loop")
  if(NOT EXISTS "${loop}")
    set(loop "${loop_build}/${CF_CONFIG}/cf_haptic_loop")
  endif()
  execute_process(COMMAND "${loop}" --graph "${GRAPH}" --rate 1000 --duration 1.5 --check
                          --trace "${WORK_DIR}/trace.csv" --device "${WORK_DIR}/device.csv"
                  RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "cf_haptic_loop --check exited with ${result}")
  endif()
endif()
message(STATUS "installed package OK")

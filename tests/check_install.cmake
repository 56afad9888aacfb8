# Proves the complete install and libcf on its own (run by CTest as
# `cmake -D... -P check_install.cmake`):
#   1. installs the whole build into a private prefix;
#   2. checks the installed tree: the three tools, the library, its headers, the package
#      config, the schemas and the docs;
#   3. runs each installed tool with --version: "<tool> <version> (graph format N)";
#   4. configures libcf on its own (cmake -S libcf), builds and installs it into a second
#      prefix, and checks its library, headers and package config there.
# Inputs: BUILD_DIR (the top-level build tree), SOURCE_DIR, WORK_DIR, VERSION, CF_CONFIG,
#         GENERATOR, MAKE_PROGRAM, CXX_COMPILER, CXX_COMPILER_LAUNCHER (optional).
cmake_minimum_required(VERSION 3.20)

foreach(var BUILD_DIR SOURCE_DIR WORK_DIR VERSION GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "check_install.cmake: ${var} is not set")
  endif()
endforeach()
if(NOT CF_CONFIG)
  set(CF_CONFIG Release)
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# Fails unless every path (relative to PREFIX) exists.
function(require_files prefix)
  foreach(f IN LISTS ARGN)
    if(NOT EXISTS "${prefix}/${f}")
      message(FATAL_ERROR "the install into ${prefix} has no ${f}")
    endif()
  endforeach()
endfunction()

set(prefix "${WORK_DIR}/prefix")
message(STATUS "1. install the build into ${prefix}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --config "${CF_CONFIG}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)

message(STATUS "2. the installed tree")
include(GNUInstallDirs)
set(library_files
  "${CMAKE_INSTALL_INCLUDEDIR}/cf/graph.hpp" "${CMAKE_INSTALL_INCLUDEDIR}/cf/version.hpp"
  "${CMAKE_INSTALL_LIBDIR}/libcf.a" "${CMAKE_INSTALL_LIBDIR}/cmake/cf/cfConfig.cmake"
  "${CMAKE_INSTALL_LIBDIR}/cmake/cf/cfConfigVersion.cmake"
  "${CMAKE_INSTALL_LIBDIR}/cmake/cf/cfTargets.cmake")
require_files("${prefix}" ${library_files}
  bin/cfgen bin/cfreplay bin/cfinspect
  "${CMAKE_INSTALL_DATADIR}/cf/schemas/cf-graph.schema.json"
  "${CMAKE_INSTALL_DATADIR}/cf/schemas/model.schema.json"
  "${CMAKE_INSTALL_DATADIR}/doc/cf/spec.md" "${CMAKE_INSTALL_DATADIR}/doc/cf/README.md")

message(STATUS "3. the installed tools answer --version")
string(REPLACE "." "\\." version_re "${VERSION}")
foreach(tool cfgen cfreplay cfinspect)
  execute_process(COMMAND "${prefix}/bin/${tool}" --version OUTPUT_VARIABLE out
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "^${tool} ${version_re} \\(graph format [0-9]+\\)\n$")
    message(FATAL_ERROR "${prefix}/bin/${tool} --version: exit ${rc}, printed '${out}'")
  endif()
endforeach()

message(STATUS "4. libcf configured, built and installed on its own")
set(args -G "${GENERATOR}" "-DCMAKE_BUILD_TYPE=${CF_CONFIG}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
if(MAKE_PROGRAM)
  list(APPEND args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER_LAUNCHER)
  list(APPEND args "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -S "${SOURCE_DIR}/libcf" -B "${WORK_DIR}/libcf" ${args}
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK_DIR}/libcf" --config "${CF_CONFIG}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
execute_process(
  COMMAND "${CMAKE_COMMAND}" --install "${WORK_DIR}/libcf" --prefix "${WORK_DIR}/libcf_prefix"
          --config "${CF_CONFIG}"
  OUTPUT_QUIET COMMAND_ERROR_IS_FATAL ANY)
require_files("${WORK_DIR}/libcf_prefix" ${library_files})
message(STATUS "the install is complete and libcf builds on its own")

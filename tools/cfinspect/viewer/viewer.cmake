# The browser viewer (cfinspect --html): viewer/build.mjs bundles src/ with three.js (esbuild,
# both from npm, pinned in package-lock.json and installed by `npm ci`, which
# scripts/install-npm.sh runs) into one page and writes it as a C++ source. Without Node.js
# or node_modules, cfinspect is built with viewer_none.cpp and --html says what is missing.
# Sets CF_VIEWER_SOURCE.
set(_viewer ${CMAKE_CURRENT_SOURCE_DIR}/viewer)
find_program(CF_NODE node)
if(CF_NODE AND EXISTS ${_viewer}/node_modules/esbuild/package.json AND EXISTS ${_viewer}/node_modules/three/package.json)
  set(CF_VIEWER_SOURCE ${CMAKE_CURRENT_BINARY_DIR}/viewer_page.cpp)
  file(GLOB _viewer_src CONFIGURE_DEPENDS ${_viewer}/src/*)
  add_custom_command(OUTPUT ${CF_VIEWER_SOURCE}
    COMMAND ${CF_NODE} ${_viewer}/build.mjs ${CF_VIEWER_SOURCE}
    DEPENDS ${_viewer_src} ${_viewer}/build.mjs ${_viewer}/package-lock.json ${_viewer}/node_modules/three/package.json
    COMMENT "Bundling the cfinspect viewer (esbuild, three.js)" VERBATIM)
  set(CF_HAVE_VIEWER ON CACHE INTERNAL "cfinspect --html is built in")
else()
  message(STATUS "cfinspect: no browser viewer (needs node and `npm ci` in ${_viewer}: bash scripts/install-npm.sh, then configure again)")
  set(CF_VIEWER_SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/viewer_none.cpp)
  set(CF_HAVE_VIEWER OFF CACHE INTERNAL "cfinspect --html is built in")
endif()

# shellcheck shell=bash
# Shared by scripts/setup.sh and scripts/test.sh; source it, do not run it.
# Environment knobs (all optional):
#   CF_BUILD_DIR    build directory, relative to the repo root or absolute (default: build)
#   CF_BUILD_TYPE   CMAKE_BUILD_TYPE (default: Release)
#   CF_JOBS         parallel compile jobs (default: number of cores)
#   CF_CMAKE_ARGS   extra arguments for the CMake configure step, split on spaces
#                   (e.g. "-DCF_BUILD_BENCH=OFF")
#   CF_SKIP_DEPS=1  do not run scripts/install-deps.sh

CF_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$CF_ROOT" || exit 1
CF_BUILD_DIR="${CF_BUILD_DIR:-build}"
CF_BUILD_TYPE="${CF_BUILD_TYPE:-Release}"
CF_JOBS="${CF_JOBS:-$(nproc 2>/dev/null || echo 2)}"

cf_log() { printf '== %s\n' "$*"; }

cf_install_deps() {
  if [[ "${CF_SKIP_DEPS:-0}" == 1 ]]; then return 0; fi
  bash "$CF_ROOT/scripts/install-deps.sh"
  bash "$CF_ROOT/scripts/install-npm.sh"
}

cf_configure() {
  # Everything on, explicitly: a reused build tree may carry older choices in its cache.
  local args=(-S "$CF_ROOT" -B "$CF_BUILD_DIR" "-DCMAKE_BUILD_TYPE=$CF_BUILD_TYPE"
              -DCF_BUILD_TOOLS=ON -DCF_BUILD_TESTS=ON -DCF_BUILD_BENCH=ON)
  # The generator of an existing build tree cannot change; only pick Ninja for a new one.
  # Ccache, when installed, is picked up by the top-level CMakeLists.txt.
  if [[ ! -f "$CF_BUILD_DIR/CMakeCache.txt" ]]; then args+=(-G Ninja); fi
  # shellcheck disable=SC2206  # CF_CMAKE_ARGS is split on purpose
  local extra=(${CF_CMAKE_ARGS:-})
  cf_log "configure $CF_BUILD_DIR ($CF_BUILD_TYPE)"
  cmake "${args[@]}" "${extra[@]}"
}

cf_build() {
  cf_log "build $CF_BUILD_DIR (-j$CF_JOBS)"
  cmake --build "$CF_BUILD_DIR" -j "$CF_JOBS"
}

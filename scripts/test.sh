#!/usr/bin/env bash
# Installs missing dependencies, configures and builds everything in build/, then runs the
# whole test suite, then the sanitizer build's tests and the fuzz targets (scripts/sanitize.sh,
# scripts/fuzz.sh). The exit status is ctest's, or non-zero when the sanitizer tests or the
# fuzzing fail. Knobs: see scripts/common.sh (CF_SKIP_SANITIZE=1: the main suite only).
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

cf_install_deps
cf_configure
cf_build
cf_log "test $CF_BUILD_DIR"
status=0
ctest --test-dir "$CF_BUILD_DIR" --output-on-failure -j2 || status=$?
# The sanitizer build (ASan + UBSan: libcf, cfinspect, cfreplay and their tests) and the
# fuzz targets, about 30 s each (docs/bad-input.md). CF_SKIP_SANITIZE=1 skips both.
if [[ "${CF_SKIP_SANITIZE:-0}" != 1 ]]; then
  bash "$CF_ROOT/scripts/sanitize.sh" || status=$((status == 0 ? 1 : status))
  bash "$CF_ROOT/scripts/fuzz.sh" || status=$((status == 0 ? 1 : status))
fi
exit "$status"

#!/usr/bin/env bash
# Installs missing dependencies, configures and builds everything in build/, then runs the
# whole test suite. The exit status is ctest's. Knobs: see scripts/common.sh.
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

cf_install_deps
cf_configure
cf_build
cf_log "test $CF_BUILD_DIR"
exec ctest --test-dir "$CF_BUILD_DIR" --output-on-failure -j2

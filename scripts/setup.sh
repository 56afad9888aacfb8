#!/usr/bin/env bash
# One-command set-up: installs missing dependencies, configures and builds everything in
# build/ (Ninja, Release, ccache when present), then runs the main job on the bundled
# default models. Knobs: see scripts/common.sh.
set -euo pipefail

# The bundled default models the main job runs on (paths relative to the repo root).
DEFAULT_MODELS=(
  data/models/cube.off
  data/models/l_block.off
  data/models/corner_block.off
  data/models/peg.off
  data/models/block_with_hole.off
)

# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

# ---------------------------------------------------------------------------------------
# MAIN JOB. For now: extract the features (faces, edges, vertices) of each default model
# with cfgen and write them to build/features/<name>.json.
# TODO(lead): replace with graph generation (cfgen A B -o GRAPH) + replay (cfreplay).
# ---------------------------------------------------------------------------------------
main_job() {
  local cfgen="$CF_BUILD_DIR/tools/cfgen/cfgen"
  local outdir="$CF_BUILD_DIR/features"
  if [[ ! -x "$cfgen" ]]; then
    cf_log "main job skipped: $cfgen was not built (tools/ not there yet, or CF_BUILD_TOOLS=OFF)"
    return 0
  fi
  mkdir -p "$outdir"
  local model name out failures=0 done_count=0
  cf_log "main job: features of the default models -> $outdir/"
  for model in "${DEFAULT_MODELS[@]}"; do
    if [[ ! -f "$model" ]]; then
      echo "  skip  $model: file not found (default model not bundled yet)"
      continue
    fi
    name="$(basename "$model")"
    name="${name%.*}"
    out="$outdir/$name.json"
    # Written whole or not at all.
    if "$cfgen" --features "$model" >"$out.tmp"; then
      mv -f "$out.tmp" "$out"
      printf '  ok    %-28s -> %s (%s bytes)\n' "$model" "$out" "$(wc -c <"$out" | tr -d ' ')"
      done_count=$((done_count + 1))
    else
      rm -f "$out.tmp"
      echo "  FAIL  $model: cfgen --features exited non-zero (message above)"
      failures=$((failures + 1))
    fi
  done
  cf_log "main job: $done_count written, $failures failed, $((${#DEFAULT_MODELS[@]} - done_count - failures)) skipped"
  ((failures == 0))
}

cf_install_deps
cf_configure
cf_build
main_job
cf_log "done. Run the tests with: bash scripts/test.sh"

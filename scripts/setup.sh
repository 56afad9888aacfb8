#!/usr/bin/env bash
# One-command set-up: installs missing dependencies, configures and builds everything in
# build/ (Ninja, Release, ccache when present), then runs the main job on the bundled
# default models. Knobs: see scripts/common.sh.
set -euo pipefail

# The bundled default model pairs (A B graph), paths relative to the repo root.
DEFAULT_PAIRS=(
  "data/models/cube.off data/models/l_block.off data/graphs/cube_l_block.json"
  "data/models/cube.off data/models/corner_block.off data/graphs/cube_corner_block.json"
  "data/models/peg.off data/models/hole_block.off data/graphs/peg_hole_block.json"
)
# The replay the main job runs (trajectory, graph, output prefix).
DEFAULT_REPLAY="data/trajectories/cube_lblock_corner.csv data/graphs/cube_l_block.json"

# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

# ---------------------------------------------------------------------------------------
# MAIN JOB: the CF graph of every default pair (cfgen), then one scripted trajectory replayed
# through the run-time loop (cfreplay) with its force/moment CSV and SVG plot.
# ---------------------------------------------------------------------------------------
main_job() {
  local cfgen="$CF_BUILD_DIR/tools/cfgen" cfreplay="$CF_BUILD_DIR/tools/cfreplay"
  local pair a b graph
  for pair in "${DEFAULT_PAIRS[@]}"; do
    read -r a b graph <<<"$pair"
    cf_log "main job: cfgen $a $b -o $graph"
    "$cfgen" "$a" "$b" -o "$graph"
  done
  local traj replay_graph out="$CF_BUILD_DIR/replay"
  read -r traj replay_graph <<<"$DEFAULT_REPLAY"
  mkdir -p "$out"
  cf_log "main job: cfreplay --graph $replay_graph --trajectory $traj"
  "$cfreplay" --graph "$replay_graph" --trajectory "$traj" -o "$out/replay.csv" --plot "$out/replay.svg"
  cf_log "main job: wrote $out/replay.csv ($(($(wc -l <"$out/replay.csv") - 1)) ticks) and $out/replay.svg"
  # The browser viewer of that graph with the replay (docs/viewer.md); open it from disk.
  if "$CF_BUILD_DIR/tools/cfinspect/cfinspect" "$replay_graph" --fast --html "$out/viewer.html" \
       --replay "$out/replay.csv" --trajectory "$traj" >/dev/null; then
    cf_log "main job: wrote $out/viewer.html (open it in a browser)"
  fi
}

cf_install_deps
cf_configure
cf_build
main_job
cf_log "done. Run the tests with: bash scripts/test.sh"

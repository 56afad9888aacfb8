#!/usr/bin/env bash
# Runs every libFuzzer target of fuzz/ (built by scripts/sanitize.sh, ASan + UBSan) for a
# bounded time, two at a time, on the seed corpus (the tests' and the bundled files) plus
# the regression inputs of fuzz/regressions/<target>/. A crash, a sanitizer report, a leak,
# a timeout or an out-of-memory stops the run: the input is kept as
# build-asan/fuzz-findings/<target>/crash-*; fix the bug and add that input to
# fuzz/regressions/<target>/ (docs/bad-input.md).
#   CF_FUZZ_SECONDS   seconds per target (default 30)
#   CF_SAN_BUILD_DIR  the sanitizer build tree (default build-asan)
set -euo pipefail
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
SAN_DIR="${CF_SAN_BUILD_DIR:-build-asan}"
SECONDS_EACH="${CF_FUZZ_SECONDS:-30}"
FINDINGS="$SAN_DIR/fuzz-findings"
SEEDS="$SAN_DIR/fuzz-seeds"

# Seed corpora: the tests' files, per target.
rm -rf "$SEEDS"
seed() {  # target files...
  local t="$1"
  shift
  mkdir -p "$SEEDS/$t"
  local f
  for f in "$@"; do [[ -f "$f" ]] && cp "$f" "$SEEDS/$t/"; done
  return 0
}
seed fuzz_off data/models/*.off tests/data/models/*.off
seed fuzz_obj data/models/*.obj tests/data/models/*.obj
seed fuzz_stl_ascii tests/data/models/*.stl
seed fuzz_stl_binary fuzz/regressions/fuzz_stl_binary/*
seed fuzz_ply tests/data/models/*.ply
seed fuzz_graph_json tests/data/graphs/*.json tests/data/graphs/bad/*.json
seed fuzz_graph_cbor tests/data/graphs/*.cbor tests/data/graphs/bad/*.cbor
seed fuzz_trajectory data/trajectories/*.csv

targets=(fuzz_off fuzz_obj fuzz_stl_ascii fuzz_stl_binary fuzz_ply fuzz_graph_json fuzz_graph_cbor fuzz_trajectory)
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

run_one() {  # target
  local t="$1" bin="$SAN_DIR/fuzz/$1" work="$SAN_DIR/fuzz-work/$1"
  mkdir -p "$work" "$FINDINGS/$t" "fuzz/regressions/$t"
  # The regression inputs first, each once; then fuzzing from the seeds and the regressions.
  local regs=(fuzz/regressions/"$t"/*)
  if [[ -e "${regs[0]}" ]]; then
    "$bin" -rss_limit_mb=2048 -timeout=10 "${regs[@]}" >"$FINDINGS/$t.regressions.log" 2>&1 ||
      { echo "fuzz: $t: a regression input fails again (see $FINDINGS/$t.regressions.log)"; return 1; }
  fi
  if "$bin" -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -timeout=10 -max_len=65536 \
       -artifact_prefix="$FINDINGS/$t/" -print_final_stats=1 \
       "$work" "$SEEDS/$t" "fuzz/regressions/$t" >"$FINDINGS/$t.log" 2>&1; then
    echo "fuzz: $t: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$FINDINGS/$t.log" | grep -o '[0-9]*$') runs in ${SECONDS_EACH} s, no finding"
  else
    echo "fuzz: $t: FINDING (log: $FINDINGS/$t.log; input: $(ls "$FINDINGS/$t" | head -1))"
    tail -n 40 "$FINDINGS/$t.log"
    return 1
  fi
}
export -f run_one
export SAN_DIR SECONDS_EACH FINDINGS SEEDS

cf_log "fuzz ${#targets[@]} targets, ${SECONDS_EACH} s each, two at a time"
status=0
printf '%s\n' "${targets[@]}" | xargs -P 2 -I{} bash -c 'run_one {}' || status=1
exit "$status"

#!/usr/bin/env bash
# Speedup of cfgen's shards (docs/generator.md, "Shards"): one process of one thread, then K
# processes of one thread each sharing a fresh checkpoint directory, for each K given; prints
# the wall time of the run (until every shard ends), the CPU time of all its processes, and
# shard 0's wait for the others. Every shard-0 graph is compared with the one process's.
#
#   bash scripts/shard-speedup.sh A_MODEL B_MODEL [K...]     (default K: 2 4)
# Figures go to docs/performance.md, "Sharded, MPI and resumed runs".
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cfgen="${CF_BUILD_DIR:-build}/tools/cfgen"
a="$1"
b="$2"
shift 2
ks=("$@")
[[ ${#ks[@]} -gt 0 ]] || ks=(2 4)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# wall s, user+sys s of the command
timed() {
  /usr/bin/time -f "%e %U %S" -o "$work/time" "$@"
  awk '{printf "%.1f %.1f\n", $1, $2 + $3}' "$work/time"
}

read -r wall cpu < <(timed "$cfgen" "$a" "$b" -o "$work/one.json" -j 1 -q)
printf "%-28s wall %7.1f s  cpu %7.1f s\n" "1 process, 1 thread" "$wall" "$cpu"
for k in "${ks[@]}"; do
  rm -rf "$work/ck" "$work/shard.json"
  start=$(date +%s.%N)
  pids=()
  for ((i = 0; i < k; i++)); do
    /usr/bin/time -f "%e %U %S" -o "$work/time_$i" "$cfgen" "$a" "$b" -o "$work/shard.json" -j 1 \
      --checkpoint "$work/ck" --shard "$i/$k" 2>"$work/err_$i" &
    pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p"; done
  end=$(date +%s.%N)
  cpu=$(cat "$work"/time_* | awk '{s += $2 + $3} END {printf "%.1f", s}')
  waited=$(grep -o "waited [0-9.e+-]* s" "$work/err_0" | awk '{print $2}')
  same=$(cmp -s "$work/one.json" "$work/shard.json" && echo "same graph" || echo "GRAPH DIFFERS")
  printf "%-28s wall %7.1f s  cpu %7.1f s  shard 0 waited %s s  %s\n" "$k shards, 1 thread each" \
    "$(echo "$end - $start" | bc)" "$cpu" "${waited:-?}" "$same"
done

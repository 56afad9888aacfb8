#!/usr/bin/env bash
# Speedup of cfgen's shards and MPI ranks (docs/generator.md, "Shards", "MPI"): one process of
# one thread, then, for each K given, K shards of one thread each sharing a fresh checkpoint
# directory, and `mpirun -n K` of one thread each (when mpirun is installed). Prints the wall
# time of the run (until every process ends), the CPU time of all its processes, the CPU
# beyond one process's, and shard or rank 0's tail: how long it ran after every other process
# had ended (the records, the transitions and the graph's file, which it does alone), as a
# share of the run's CPU (shards only: the other ranks of an MPI run wait for rank 0 at the
# end). Every graph is compared with the one process's.
#
#   bash scripts/shard-speedup.sh A_MODEL B_MODEL [K...]     (default K: 2 4)
# Figures go to docs/performance.md, "Sharded, MPI and resumed runs".
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cfgen="$(realpath "${CF_BUILD_DIR:-build}/tools/cfgen")"
a="$(realpath "$1")"
b="$(realpath "$2")"
shift 2
ks=("$@")
[[ ${#ks[@]} -gt 0 ]] || ks=(2 4)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Process i of a run: its CPU (user + system) in time_i, the moment it ended in end_i.
one() {
  local i="$1"
  shift
  /usr/bin/time -f "%U %S" -o "$work/time_$i" "$@" 2>"$work/err_$i"
  date +%s.%N >"$work/end_$i"
}
export -f one
export work

report() {  # label, start, K
  local label="$1" start="$2" k="$3" end cpu tail last
  end=$(cat "$work"/end_* | sort -n | tail -1)
  cpu=$(cat "$work"/time_* | awk '{s += $1 + $2} END {printf "%.1f", s}')
  last=$( (for ((i = 1; i < k; i++)); do cat "$work/end_$i"; done; echo 0) | sort -n | tail -1)
  tail=$(echo "$(cat "$work/end_0") - $last" | bc)
  # The other ranks of an MPI run wait for rank 0 at the end: its tail is not seen from here.
  [[ $label != mpirun* ]] || tail=0
  printf "%-30s wall %6.1f s  cpu %6.1f s  beyond one %4.0f%%  0's tail %4.1f s (%2.0f%% of cpu)  %s\n" \
    "$label" "$(echo "$end - $start" | bc)" "$cpu" "$(echo "100 * ($cpu - $one_cpu) / $one_cpu" | bc -l)" \
    "$tail" "$(echo "100 * $tail / $cpu" | bc -l)" \
    "$(cmp -s "$work/one.json" "$work/g.json" && echo "same graph" || echo "GRAPH DIFFERS")"
}

rm -f "$work"/time_* "$work"/end_*
one 0 "$cfgen" "$a" "$b" -o "$work/one.json" -j 1 -q --no-checkpoint
one_cpu=$(awk '{printf "%.2f", $1 + $2}' "$work/time_0")
printf "%-30s cpu %6.1f s\n" "1 process, 1 thread" "$one_cpu"
for k in "${ks[@]}"; do
  rm -rf "$work/ck" "$work/g.json" "$work"/time_* "$work"/end_*
  start=$(date +%s.%N)
  for ((i = 0; i < k; i++)); do
    one "$i" "$cfgen" "$a" "$b" -o "$work/g.json" -j 1 --checkpoint "$work/ck" --shard "$i/$k" &
  done
  wait
  report "$k shards, 1 thread each" "$start" "$k"
  if command -v mpirun >/dev/null 2>&1; then
    rm -f "$work/g.json" "$work"/time_* "$work"/end_*
    start=$(date +%s.%N)
    mpirun --oversubscribe -n "$k" bash -c \
      'one "$OMPI_COMM_WORLD_RANK" "$0" "$@"' "$cfgen" "$a" "$b" -o "$work/g.json" -j 1 -q --no-checkpoint
    report "mpirun -n $k, 1 thread each" "$start" "$k"
  fi
done

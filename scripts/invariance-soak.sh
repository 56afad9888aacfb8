#!/usr/bin/env bash
# Invariance soak: runs `oracle_invariance` (tests/oracle) on N seeds of the oracle's pairs and
# prints a summary table: per seed the pairing, the CFs of the graph of the files as written and
# of the copy moved by random rigid motions and renumbered, the sets only one of them holds
# (and how many of those the oracle finds a sound witness for: CFs the other run missed), and
# the verdict; then totals. Issue 40 asks for the same CF sets on every pair.
#
#   bash scripts/invariance-soak.sh N [START] [-- oracle_invariance options]
#
# START defaults to 1. Options after `--` go to every run (e.g. `-- --motion-seed 3 -j 2`, or
# `-- -- --thorough` for cfgen's own options). Each run's report (the differing sets) is kept in
# $ORACLE_INVARIANCE_DIR (default build/oracle-invariance) as seed_N.txt; reproduce one with
# `oracle_invariance --seed N --keep DIR`.
# Environment: ORACLE_INVARIANCE (the binary; default build/tests/oracle/oracle_invariance),
# CF_CFGEN_PATH (the cfgen binary it runs; default: the one it was built with).
set -uo pipefail

# shellcheck source=scripts/soak-args.sh
source "$(dirname "${BASH_SOURCE[0]}")/soak-args.sh"
soak_args invariance-soak.sh oracle_invariance 1 "${ORACLE_INVARIANCE:-}" "${ORACLE_INVARIANCE_DIR:-}" oracle-invariance "$@"

printf '%-6s %-34s %8s %8s %10s %10s %9s %9s\n' seed pairing cfs moved only_first only_moved sound verdict
tot_cfs=0 tot_first=0 tot_moved=0 tot_sound=0 same=0 differ=0 failed=0
for ((seed = START; seed < START + N; ++seed)); do
  soak_run "$seed"
  if [[ $rc -eq 2 || -z $(get cfs) ]]; then
    printf '%-6s %-34s %s\n' "$seed" "${pairing:0:34}" "ERROR (see $log)"
    failed=$((failed + 1))
    continue
  fi
  c=$(get cfs) m=$(get moved) f=$(get only_first) o=$(get only_moved) snd=$(get sound)
  verdict=same
  [[ $rc -eq 1 ]] && verdict=DIFFERENT
  printf '%-6s %-34s %8s %8s %10s %10s %9s %9s\n' "$seed" "${pairing:0:34}" "$c" "$m" "$f" "$o" "$snd" "$verdict"
  tot_cfs=$((tot_cfs + c)) tot_first=$((tot_first + f)) tot_moved=$((tot_moved + o))
  tot_sound=$((tot_sound + ${snd%+*} + ${snd#*+}))
  if [[ $rc -eq 0 ]]; then same=$((same + 1)); else differ=$((differ + 1)); fi
done
echo
echo "pairs: $((same + differ)) run, $same the same, $differ different, $failed failed"
if [[ $tot_cfs -gt 0 ]]; then
  awk -v c="$tot_cfs" -v f="$tot_first" -v o="$tot_moved" -v s="$tot_sound" 'BEGIN {
    printf "CFs of the files as written: %d; only there: %d, only in the moved copies: %d (%.2f%% of the CFs differ); %d of these with a witness the oracle finds sound\n",
      c, f, o, 100 * (f + o) / c, s }'
fi
[[ $differ -eq 0 && $failed -eq 0 ]]

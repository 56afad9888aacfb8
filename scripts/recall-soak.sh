#!/usr/bin/env bash
# Recall soak: runs the independent oracle (tests/oracle, `oracle_recall`) on N seeds and prints
# a summary table: per seed the pairing, CFs in cfgen's graph, CFs the oracle sampled, misses
# (sampled CFs the graph lacks), CFs it lists as THIN (stats.thin_sets, not misses), recall,
# unsound witnesses; then totals and the misses grouped
# by signature (number of PCs and their types).
#
#   bash scripts/recall-soak.sh N [START] [-- oracle_recall options]
#
# START defaults to 1000 (away from the fixed CI seeds). Options after `--` go to every
# oracle_recall run (e.g. `-- --budget 5 -j 2 --cfgen-timeout 900`; large n-gon pegs make cfgen
# run for many minutes). Each run's full report (misses with PC lists
# and poses, unsound witnesses) is kept in $ORACLE_SOAK_DIR (default build/oracle-soak) as
# seed_N.txt; reproduce one with `oracle_recall --seed N --keep DIR`.
# Environment: ORACLE_RECALL (the binary; default build/tests/oracle/oracle_recall),
# CF_CFGEN_PATH (the cfgen binary oracle_recall runs; default: the one it was built with).
set -uo pipefail

# shellcheck source=scripts/soak-args.sh
source "$(dirname "${BASH_SOURCE[0]}")/soak-args.sh"
soak_args recall-soak.sh oracle_recall 1000 "${ORACLE_RECALL:-}" "${ORACLE_SOAK_DIR:-}" oracle-soak "$@"

printf '%-8s %-40s %7s %8s %7s %5s %8s %8s %8s\n' seed pairing graph sampled misses thin recall unsound cfgen_s
tot_s=0 tot_m=0 tot_t=0 tot_u=0 tot_marg=0 failed=0
declare -A sig=()  # set, so that ${#sig[@]} is 0 under set -u when nothing was missed
for ((seed = START; seed < START + N; ++seed)); do
  soak_run "$seed"
  if [[ $rc -eq 2 || -z $(get graph) ]]; then
    printf '%-8s %-40s %s\n' "$seed" "${pairing:0:40}" "ERROR (see $log)"
    failed=$((failed + 1))
    continue
  fi
  g=$(get graph) s=$(get sampled) m=$(get misses) th=$(get thin) r=$(get recall) u=$(get unsound) mg=$(get marginal) c=$(get cfgen)
  printf '%-8s %-40s %7s %8s %7s %5s %8s %8s %8s\n' "$seed" "${pairing:0:40}" "$g" "$s" "$m" "$th" "$r" "$u" "${c%s}"
  tot_s=$((tot_s + s)) tot_m=$((tot_m + m)) tot_u=$((tot_u + u)) tot_marg=$((tot_marg + mg))
  while read -r entry; do
    [[ -z $entry ]] && continue
    k=${entry% x*} n=${entry##* x}
    sig[$k]=$(( ${sig[$k]:-0} + n ))
  done < <(sed -n 's/^  misses by signature: //p' "$log" | tr ' ' '\n' | paste -d' ' - -)
done
echo
if [[ $tot_s -gt 0 ]]; then
  rec=$(awk -v s="$tot_s" -v m="$tot_m" 'BEGIN { printf "%.2f", 100 * (s - m) / s }')
else
  rec=100
fi
echo "total: $N seeds ($failed failed), $tot_s CFs sampled, $tot_m misses, $tot_t listed thin, recall $rec%, $tot_u unsound and $tot_marg marginal witnesses"
if [[ ${#sig[@]} -gt 0 ]]; then
  echo "misses by signature (PCs:types):"
  for k in "${!sig[@]}"; do printf '  %-28s %6d\n' "$k" "${sig[$k]}"; done | sort
fi
echo "reports: $OUT/seed_N.txt"
[[ $tot_m -eq 0 && $tot_u -eq 0 && $failed -eq 0 ]]

#!/usr/bin/env bash
# How far `cfgen --estimate` is from the run it predicts (docs/generator.md, "Estimates"):
# for each pair, the estimate at one thread, then the run at one thread (CPU = user +
# system, peak resident size), and the ratios predicted / measured. With CF_ESTIMATE_DEBUG
# set, the estimate also prints the sums its constants apply to (found, failed, the levels'
# CPU), from which tools/cfgen/enumerate/estimate.cpp's constants are fitted.
#
#   bash scripts/estimate-errors.sh A1 B1 [A2 B2 ...]
# Figures go to docs/performance.md, "Estimates".
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cfgen="${CF_BUILD_DIR:-build}/tools/cfgen"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
[[ $# -ge 2 && $(($# % 2)) -eq 0 ]] || { echo "usage: $0 A1 B1 [A2 B2 ...]" >&2; exit 2; }

# "1 min 40 s" / "4.2 s" / "2 h 10 min" -> seconds
seconds() {
  awk '{s = 0; for (i = 1; i < NF; i += 2) { v = $i; u = $(i + 1);
          s += (u == "h") ? v * 3600 : (u == "min") ? v * 60 : v } print s}' <<<"$1"
}

printf "%-40s %12s %12s %6s %10s %10s %6s %9s %9s %6s\n" pair "CFs pred" CFs ratio "CPU pred" CPU ratio \
  "peak pred" peak ratio
while [[ $# -ge 2 ]]; do
  a="$1" b="$2"
  shift 2
  "$cfgen" "$a" "$b" --estimate -j 1 >"$work/est.txt"
  cfs_pred=$(sed -n 's/^graph: ~\([0-9,]*\) CFs.*/\1/p' "$work/est.txt" | tr -d ,)
  cpu_pred=$(seconds "$(sed -n 's/^time: .* (\(.*\) on one)$/\1/p' "$work/est.txt")")
  mb_pred=$(sed -n 's/^peak memory: ~\([0-9,]*\) MB$/\1/p' "$work/est.txt" | tr -d ,)
  /usr/bin/time -f "%U %S %M" -o "$work/time" "$cfgen" "$a" "$b" -o "$work/g.json" -j 1 -q --no-checkpoint
  read -r user sys kb <"$work/time"
  cfs=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["stats"]["cfs"])' "$work/g.json")
  awk -v n="$(basename "$a") $(basename "$b")" -v cp="$cfs_pred" -v c="$cfs" -v tp="$cpu_pred" \
    -v t="$(awk -v u="$user" -v s="$sys" 'BEGIN {print u + s}')" -v mp="$mb_pred" -v m="$((kb / 1024))" \
    'BEGIN {printf "%-40s %12d %12d %6.2f %9.1fs %9.1fs %6.2f %7dMB %7dMB %6.2f\n", n, cp, c, cp / c, tp, t, tp / t, mp, m, mp / m}'
done

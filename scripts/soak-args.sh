# Sourced by the oracle's soak scripts (recall-soak.sh, invariance-soak.sh): reads their
# command line `N [START] [-- TOOL_OPTIONS]` and finds the tool.
#
#   soak_args SCRIPT TOOL DEFAULT_START BIN_OVERRIDE OUT_OVERRIDE OUT_NAME "$@"
#
# sets N, START, SOAK_ARGS (the options after `--`), BIN (BIN_OVERRIDE when not empty, else
# build/tests/oracle/TOOL) and OUT (OUT_OVERRIDE when not empty, else build/OUT_NAME; made);
# exits 2 after the usage, or when the tool is missing.
soak_args() {
  local script=$1 tool=$2 bin=$4 out=$5 out_name=$6
  START=$3
  shift 6
  local use="usage: bash scripts/$script N [START] [-- $tool options]"
  [[ $# -ge 1 ]] || { echo "$use" >&2; exit 2; }
  N=$1
  shift
  if [[ $# -ge 1 && $1 != "--" ]]; then
    START=$1
    shift
  fi
  [[ $# -ge 1 && $1 == "--" ]] && shift
  [[ $N =~ ^[0-9]+$ && $START =~ ^[0-9]+$ ]] || { echo "$use" >&2; exit 2; }
  SOAK_ARGS=("$@")
  local root
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  BIN="${bin:-$root/build/tests/oracle/$tool}"
  OUT="${out:-$root/build/$out_name}"
  if [[ ! -x $BIN ]]; then
    echo "${script%.sh}: $BIN not found; build it with: cmake --build build --target $tool" >&2
    exit 2
  fi
  mkdir -p "$OUT"
}

# soak_run SEED: runs the tool on SEED with SOAK_ARGS, its report kept as $OUT/seed_SEED.txt
# (log); sets rc (its exit status), line (the report's first line) and pairing.
soak_run() {
  log="$OUT/seed_$1.txt"
  "$BIN" --seed "$1" "${SOAK_ARGS[@]}" >"$log" 2>&1
  rc=$?
  line=$(head -n 1 "$log")
  pairing=$(sed -n 's/^[^|]*| \([^:]*\):.*/\1/p' <<<"$line")
}

# get KEY: the value of KEY=VALUE in the last report's first line.
get() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<" $line"; }

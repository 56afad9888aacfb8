#!/usr/bin/env bash
# Sharded, resumable and stopped cfgen runs end to end (docs/generator.md, "Shards",
# "Checkpoints", "Stopping a run"): two shards of the cube against the L-block sharing a
# checkpoint must give the bundled graph byte for byte, and so must a run resumed from a
# checkpoint that lost some of its chunks, and mpirun -n 2 with and without a checkpoint;
# checkpoints of other runs and bad --shard values are refused with a message that names the
# problem, and nothing is written; SIGINT and SIGTERM stop a run with status 130 or 143,
# keeping its finished chunks for a rerun.
#
#   cfgen_shard_test.sh CFGEN SOURCE_DIR WORK_DIR [MPIEXEC]
# With MPIEXEC (cfgen built with MPI): `mpirun -n 2 cfgen` must write the same graph.
set -uo pipefail
cfgen="$1"
src="$2"
work="$3/cfgen_shard"
mpiexec="${4:-}"
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1
A="$src/data/models/cube.off"
B="$src/data/models/l_block.off"
fail=0
check() {  # name, expected status, stderr regex, command...
  local name="$1" want="$2" re="$3"
  shift 3
  "$@" >out.txt 2>err.txt
  local rc=$?
  if [[ $rc -ne $want ]] || { [[ -n $re ]] && ! grep -Eq -- "$re" err.txt; }; then
    echo "FAIL $name: status $rc (want $want), stderr:"
    cat err.txt
    fail=1
  else
    echo "ok   $name"
  fi
}
same_as_golden() {  # graph files that must equal the bundled graph byte for byte
  local g
  for g in "$@"; do
    if cmp -s "$g" "$src/data/graphs/cube_l_block.json"; then
      echo "ok   $g equals data/graphs/cube_l_block.json"
    else
      echo "FAIL $g differs from data/graphs/cube_l_block.json"
      fail=1
    fi
  done
}

# Two shards at once, sharing a checkpoint directory: each computes its chunks of every stage
# and takes the other's; shard 0 writes the bundled graph byte for byte, shard 1 nothing. They
# run where the golden graph was made (the model paths, as typed, go into the graph).
env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off -o "$work/sharded.json" \
  --checkpoint "$work/shared" --shard 1/2 -j 1 2>shard1_err.txt &
pid1=$!
check "shard 0/2" 0 "shard 0/2: took [1-9][0-9]* chunks from the other shards" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off -o "$work/sharded.json" \
  --checkpoint "$work/shared" --shard 0/2 -j 1
wait "$pid1"
rc=$?
if [[ $rc -ne 0 ]] || ! grep -q "shard 1/2: took [1-9][0-9]* chunks from the other shards, .*shard 0 writes the graph" shard1_err.txt; then
  echo "FAIL shard 1/2: status $rc, stderr:"
  cat shard1_err.txt
  fail=1
else
  echo "ok   shard 1/2"
fi
same_as_golden sharded.json
# A rerun of either shard finds every chunk in the checkpoint and computes nothing.
check "shard 0/2 rerun" 0 "resumed [1-9][0-9]* finished chunks" env -C "$src" "$cfgen" data/models/cube.off \
  data/models/l_block.off -o "$work/sharded2.json" --checkpoint "$work/shared" --shard 0/2 -j 1
same_as_golden sharded2.json
check "--shard without --checkpoint" 2 "--shard requires --checkpoint" "$cfgen" "$A" "$B" --shard 0/2 -o g.json
check "bad --shard" 2 "--shard '3/2': i must be in 0..1" "$cfgen" "$A" "$B" --shard 3/2 --checkpoint ck0 -o g.json
check "--shard not i/K" 2 "--shard 'two': expected i/K" "$cfgen" "$A" "$B" --shard two --checkpoint ck0 -o g.json
if [[ -e g.json ]]; then
  echo "FAIL a refused run wrote g.json"
  fail=1
fi

if [[ -n $mpiexec ]]; then
  check "mpirun -n 2" 0 "" env -C "$src" "$mpiexec" -n 2 --oversubscribe --allow-run-as-root "$cfgen" \
    data/models/cube.off data/models/l_block.off -o "$work/mpi.json" -q -j 1
  # With a checkpoint, then resumed by one process: every rank keeps its chunks of every stage,
  # the neighbour rounds' screening too, which one process computes again (it is not worth
  # keeping for one process): the rerun resumes the chunks a run of one process keeps.
  check "mpirun -n 2 --checkpoint" 0 "" env -C "$src" "$mpiexec" -n 2 --oversubscribe --allow-run-as-root "$cfgen" \
    data/models/cube.off data/models/l_block.off --checkpoint "$work/mpick" -o "$work/mpi_ck.json" -q -j 1
  check "one process, --checkpoint" 0 "" env -C "$src" "$cfgen" \
    data/models/cube.off data/models/l_block.off --checkpoint "$work/oneck" -o "$work/one_ck.json" -q -j 1
  mpichunks=$(ls mpick/stage*_chunk*.json 2>/dev/null | wc -l)
  onechunks=$(ls oneck/stage*_chunk*.json 2>/dev/null | wc -l)
  if [[ $mpichunks -le $onechunks || $onechunks -lt 50 ]]; then
    echo "FAIL mpirun kept $mpichunks chunks, one process $onechunks (want more than 50, and more for mpirun)"
    fail=1
  fi
  check "resumed from mpirun's checkpoint" 0 "resumed $onechunks finished chunks" \
    env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --checkpoint "$work/mpick" -o "$work/mpi_ck2.json" -j 2
  same_as_golden mpi.json mpi_ck.json one_ck.json mpi_ck2.json
else
  echo "skip mpirun (cfgen built without MPI)"
fi

# Checkpoints: a whole run keeps every chunk of every stage; with all but the chunks of the
# first two stages (level 1, the first level-2 round) and three of the third removed (as if
# killed), the rerun resumes those and writes the same graph. These runs search every set
# (--no-symmetry): one search per orbit leaves the cube and the L-block a few chunks a stage.
check "checkpointed run" 0 "" env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off \
  --no-symmetry --checkpoint "$work/ck" -o "$work/ck1.json" -q -j 2
nchunks=$(ls ck/stage*_chunk*.json 2>/dev/null | wc -l)
if [[ $nchunks -lt 100 ]]; then
  echo "FAIL the checkpoint holds $nchunks chunks, expected at least 100 (64 a stage)"
  fail=1
fi
find ck -name 'stage*_chunk*.json' ! -name 'stage0000[01]_chunk*.json' ! -name 'stage00003_chunk000[012].json' -delete
nkept=$(ls ck/stage*_chunk*.json | wc -l)
check "resumed run" 0 "resumed $nkept finished chunks" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --no-symmetry --checkpoint "$work/ck" \
  -o "$work/ck2.json" -j 2
if cmp -s ck1.json ck2.json; then
  echo "ok   ck2.json (resumed) equals ck1.json"
else
  echo "FAIL ck2.json (resumed) differs from ck1.json"
  fail=1
fi
# A run killed mid-way (SIGKILL: no chance to tidy up) resumes from the chunks it finished and
# writes the graph an uninterrupted run writes. The peg in the block with a hole takes about
# 40 s on one thread; it is killed once it has finished level 1 (64 chunks) and some of the
# first level-2 round.
env -C "$src" "$cfgen" data/models/peg.off data/models/hole_block.off --no-symmetry --checkpoint "$work/kill" \
  -o "$work/killed.json" -q -j 1 &
pid=$!
for _ in $(seq 600); do
  [[ $(ls kill/stage*_chunk*.json 2>/dev/null | wc -l) -ge 70 ]] && break
  sleep 0.1
done
kill -9 "$pid"
wait "$pid" 2>/dev/null
nkill=$(ls kill/stage*_chunk*.json 2>/dev/null | wc -l)
if [[ -e killed.json ]]; then
  echo "FAIL killed run: it wrote its graph before it was killed"
  fail=1
elif [[ $nkill -lt 70 ]]; then
  echo "FAIL killed run: $nkill chunks kept after a minute, expected 70 or more"
  fail=1
else
  check "resumed after kill -9" 0 "resumed $nkill finished chunks" env -C "$src" "$cfgen" data/models/peg.off \
    data/models/hole_block.off --no-symmetry --checkpoint "$work/kill" -o "$work/killed.json" -j 2
  env -C "$src" "$cfgen" data/models/peg.off data/models/hole_block.off --no-symmetry -o "$work/whole.json" -q -j 2
  if cmp -s killed.json whole.json; then
    echo "ok   killed.json equals an uninterrupted run's graph"
  else
    echo "FAIL killed.json differs from an uninterrupted run's graph"
    fail=1
  fi
fi
# Ctrl-C (SIGINT) stops a run between tasks: status 130, the finished chunks kept, no graph
# written. The run keeps them in GRAPH.json.ckpt, the directory a run predicted to be long
# keeps by default; the same command without --checkpoint takes them up, writes the graph of
# an uninterrupted run and removes the directory. (A job this script starts in the background
# ignores SIGINT, and so does cfgen then; --default-signal gives it the disposition it has
# when started from a terminal.)
ck_int="$work/interrupted.json.ckpt"
env --default-signal=INT -C "$src" "$cfgen" data/models/peg.off data/models/hole_block.off --no-symmetry --checkpoint "$ck_int" \
  -o "$work/interrupted.json" -j 1 2>int_err.txt &
pid=$!
for _ in $(seq 600); do
  [[ $(ls "$ck_int"/stage*_chunk*.json 2>/dev/null | wc -l) -ge 70 ]] && break
  sleep 0.1
done
kill -INT "$pid"
wait "$pid"
rc=$?
nint=$(ls "$ck_int"/stage*_chunk*.json 2>/dev/null | wc -l)
if [[ $rc -ne 130 ]] || ! grep -q "cfgen: stopped (SIGINT); finished chunks are kept in '$ck_int'" int_err.txt; then
  echo "FAIL SIGINT: status $rc (want 130), stderr:"
  cat int_err.txt
  fail=1
elif [[ -e interrupted.json ]]; then
  echo "FAIL SIGINT: the stopped run wrote its graph"
  fail=1
else
  echo "ok   SIGINT: status 130, $nint chunks kept"
  check "resumed after SIGINT from GRAPH.json.ckpt" 0 "resumed $nint finished chunks" env -C "$src" "$cfgen" \
    data/models/peg.off data/models/hole_block.off --no-symmetry -o "$work/interrupted.json" -j 2
  if [[ -e whole.json ]] && cmp -s interrupted.json whole.json; then
    echo "ok   interrupted.json equals an uninterrupted run's graph"
  else
    echo "FAIL interrupted.json differs from an uninterrupted run's graph"
    fail=1
  fi
  if [[ -e $ck_int ]]; then
    echo "FAIL $ck_int was not removed once the graph was written"
    fail=1
  else
    echo "ok   the default checkpoint directory removed once the graph was written"
  fi
fi
check "--no-checkpoint with --checkpoint" 2 "--checkpoint excludes --no-checkpoint" \
  "$cfgen" "$A" "$B" --no-checkpoint --checkpoint ck0 -o g.json
# --estimate prints the run predicted and writes nothing; the level-1 count is exact (668
# single PCs of the peg against the block that local convexity allows).
check "--estimate" 0 "" "$cfgen" "$src/data/models/peg.off" "$src/data/models/hole_block.off" --estimate -j 2
if grep -q "^level 1: 668 candidate sets in [0-9]* orbits (counted)" out.txt && grep -q "^time: " out.txt &&
  grep -q "^peak memory: " out.txt; then
  echo "ok   --estimate: level 1 counted, time and memory predicted"
else
  echo "FAIL --estimate printed:"
  cat out.txt
  fail=1
fi
check "--estimate with -o" 2 "--output excludes --estimate" "$cfgen" "$A" "$B" --estimate -o g.json
# SIGTERM (a batch system's) with --no-checkpoint: status 143, nothing kept, nothing written.
"$cfgen" "$src/data/models/peg.off" "$src/data/models/hole_block.off" --no-symmetry --no-checkpoint -o term.json -j 1 \
  2>term_err.txt &
pid=$!
for _ in $(seq 600); do
  grep -q "level 1:" term_err.txt 2>/dev/null && break
  sleep 0.1
done
kill -TERM "$pid"
wait "$pid"
rc=$?
if [[ $rc -ne 143 ]] || ! grep -q "cfgen: stopped (SIGTERM); nothing kept" term_err.txt || [[ -e term.json ]]; then
  echo "FAIL SIGTERM: status $rc (want 143, no term.json), stderr:"
  cat term_err.txt
  fail=1
else
  echo "ok   SIGTERM: status 143, nothing written"
fi
check "checkpoint of other options" 1 "was made from other models or options" \
  "$cfgen" "$A" "$B" --max-pcs 2 --no-symmetry --checkpoint ck -o g.json
check "checkpoint of a run that searched every set" 1 "was made from other models or options" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --checkpoint "$work/ck" -o "$work/g.json"
cp ck/stage00001_chunk0002.json ck/stage00001_chunk0003.json
check "chunk of other tasks" 1 "reading checkpoint chunk '.*stage00001_chunk0003.json': made by another run" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --no-symmetry --checkpoint "$work/ck" -o "$work/g.json"
echo "garbage" >ck/stage00001_chunk0001.json
check "damaged chunk" 1 "reading checkpoint chunk '.*stage00001_chunk0001.json': not JSON" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --no-symmetry --checkpoint "$work/ck" -o "$work/g.json"
touch not_a_dir
check "checkpoint is a file" 1 "checkpoint 'not_a_dir': exists and is not a directory" \
  "$cfgen" "$A" "$B" --checkpoint not_a_dir -o g.json
if [[ -e g.json ]]; then
  echo "FAIL a refused run wrote g.json"
  fail=1
fi
exit $fail

#!/usr/bin/env bash
# Sharded and resumable cfgen runs end to end (docs/generator.md, "Shards", "Checkpoints"):
# two shards of the cube against the L-block, merged in reverse order from another directory,
# must give the bundled graph byte for byte, and so must a run resumed from a checkpoint that
# lost some of its chunks, and mpirun -n 2 with and without a checkpoint; parts that do not make one whole run and checkpoints of other runs
# are refused with a message that names the problem, and nothing is written.
#
#   cfgen_shard_test.sh CFGEN SOURCE_DIR WORK_DIR [MPIEXEC]
# With MPIEXEC (cfgen built with MPI): `mpirun -n 2 cfgen` must write the same graph.
set -uo pipefail
cfgen="$1"
src="$2"
work="$3/cfgen_shard"
mpiexec="${4:-}"
rm -rf "$work"
mkdir -p "$work/elsewhere"
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

# The shards run where the golden graph was made (the model paths, as typed, go into the
# graph); the merge runs elsewhere.
check "shard 0/2" 0 "shard 0/2: [0-9]+ of [0-9]+ level-2 candidates" \
  env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --shard 0/2 -o "$work/p0.part" -j 2
check "shard 1/2" 0 "" env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --shard 1/2 \
  -o "$work/p1.part" -q -j 2
(cd elsewhere && "$cfgen" merge ../p1.part ../p0.part -o merged.json -q -j 2) || fail=1
same_as_golden elsewhere/merged.json

check "missing shard" 1 "1 of 2 shards are missing \(shard 1\)" "$cfgen" merge p0.part -o g.json
check "shard given twice" 1 "shard 0/2 is given twice" "$cfgen" merge p0.part p0.part p1.part -o g.json
# A part of another run: other options (a one-level run, which is quick).
check "part of another run" 0 "" "$cfgen" "$A" "$B" --max-pcs 1 --shard 1/2 -o other.part -q
check "parts of two runs" 1 "comes from another run than" "$cfgen" merge p0.part other.part -o g.json
printf '{"format": "cfgen shard part", "version": 1, "shard": 0' >cut.part
check "truncated part" 1 "reading shard part 'cut.part': not JSON" "$cfgen" merge cut.part p1.part -o g.json
check "not a part" 1 "reading shard part '.*cube.off': not JSON" "$cfgen" merge "$A" -o g.json
check "bad --shard" 2 "--shard '3/2': i must be in 0..1" "$cfgen" "$A" "$B" --shard 3/2 -o g.json
check "--shard not i/K" 2 "--shard 'two': expected i/K" "$cfgen" "$A" "$B" --shard two -o g.json
check "merge without -o" 2 "output is required|--output is required" "$cfgen" merge p0.part p1.part
if [[ -e g.json ]]; then
  echo "FAIL a refused merge wrote g.json"
  fail=1
fi
# A model changed after the shards ran: its bytes no longer match the parts' fingerprint.
cp "$A" a_copy.off
check "shard of a copy" 0 "" "$cfgen" a_copy.off "$B" --max-pcs 1 --shard 0/1 -o copy.part -q
echo "# touched" >>a_copy.off
check "model changed" 1 "are not the files the shards read" "$cfgen" merge copy.part -o g.json

if [[ -n $mpiexec ]]; then
  check "mpirun -n 2" 0 "" env -C "$src" "$mpiexec" -n 2 --oversubscribe --allow-run-as-root "$cfgen" \
    data/models/cube.off data/models/l_block.off -o "$work/mpi.json" -q -j 1
  # With a checkpoint, then resumed by one process: every stage's chunks are kept by rank 0.
  check "mpirun -n 2 --checkpoint" 0 "" env -C "$src" "$mpiexec" -n 2 --oversubscribe --allow-run-as-root "$cfgen" \
    data/models/cube.off data/models/l_block.off --checkpoint "$work/mpick" -o "$work/mpi_ck.json" -q -j 1
  mpichunks=$(ls mpick/stage*_chunk*.json 2>/dev/null | wc -l)
  check "resumed from mpirun's checkpoint" 0 "resumed $mpichunks finished chunks" \
    env -C "$src" "$cfgen" data/models/cube.off data/models/l_block.off --checkpoint "$work/mpick" -o "$work/mpi_ck2.json" -j 2
  same_as_golden mpi.json mpi_ck.json mpi_ck2.json
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
check "--checkpoint with --shard" 2 "excludes" "$cfgen" "$A" "$B" --checkpoint ck --shard 0/2 -o g.json
if [[ -e g.json ]]; then
  echo "FAIL a refused run wrote g.json"
  fail=1
fi
exit $fail

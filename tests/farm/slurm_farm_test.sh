#!/bin/bash
# The farm test of issue 16 (docs/farm.md): an 8-frame shot (a focus pull in the frames' own
# metadata, overscan, ACEScg colours in and out through lensmith's test OCIO config) rendered as a Slurm job array through tools/slurm/submit-bokeh-shot on a
# private single-node cluster (tools/slurm/test-cluster) must equal, byte for byte, the same shot
# rendered locally in one process on another number of threads; a task cancelled half way must
# leave only whole frames (no partial or temporary files), and a resubmission with --skip-existing
# completes the shot. Exit 77 (ctest: "Skipped", with the reason printed) when Slurm is not
# installed or cannot start here.
# Usage: slurm_farm_test.sh LENSMITH MAKE_TEST_SHOT SOURCE_DIR WORK_DIR
set -euo pipefail
lensmith=$1 make_shot=$2 source=$3 work=$4
skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAILED: $*"; exit 1; }

rm -rf "$work"
mkdir -p "$work"
command -v slurmctld >/dev/null 2>&1 && command -v slurmd >/dev/null 2>&1 && command -v sbatch >/dev/null 2>&1 ||
  skip "Slurm is not installed (Debian's slurm-wlm; tools/install-deps.sh installs it)"
cluster=$source/tools/slurm/test-cluster
trap '"$cluster" stop "$work/cluster" || true' EXIT
if ! started=$("$cluster" start "$work/cluster" 2>"$work/cluster-start.err"); then
  cat "$work/cluster-start.err"
  skip "a single-node Slurm could not be started here (the reason is above)"
fi
eval "$started"  # export SLURM_CONF=...
echo "cluster up: $SLURM_CONF"

"$make_shot" "$source/examples/bokeh-scene.exr" "$work/shot" 1001 1008 --acescg
camera=(--lens canon-35mm-f1.8-1956 --frames 1001-1008 --image "$work/shot/plate.####.exr" --pinhole-focal-length 50
        --input-colorspace ACEScg --ocio "$source/tests/data/ocio/config.ocio")
submit=("$source/tools/slurm/submit-bokeh-shot" --lensmith "$lensmith" --log-dir "$work/logs")

# 1. The shot on the farm, in 3 uneven chunks (2, 3, 3 frames) of one CPU each, waiting for all.
"${submit[@]}" --chunks 3 --cpus-per-task 1 --wait -- "${camera[@]}" -o "$work/farm/out.####.exr" ||
  { tail -n 20 "$work"/logs/*.log; fail "the farm job failed"; }
# 2. The same shot locally, one process, two threads.
mkdir -p "$work/local"
"$lensmith" bokeh "${camera[@]}" -o "$work/local/out.####.exr" --threads 2 --quiet
for frame in $(seq 1001 1008); do
  cmp "$work/farm/out.$frame.exr" "$work/local/out.$frame.exr" || fail "frame $frame differs between the farm and the local run"
done
echo "8 frames: the farm's equal the local run's, byte for byte"
[ "$(ls "$work"/logs/*.log | wc -l)" -eq 3 ] || fail "expected one log per task"
grep -q "chunk 2/3" "$work"/logs/*_2.log || fail "task 2's log does not say its chunk"
if grep -l $'\r' "$work"/logs/*.log; then fail "a progress bar (carriage returns) in a farm log"; fi

# 3. A task cancelled half way: one chunk of all 8 frames, cancelled once its second frame is written.
job=$("${submit[@]}" --chunks 1 --cpus-per-task 1 -- "${camera[@]}" -o "$work/killed/out.####.exr" 2>/dev/null)
for _ in $(seq 600); do
  [ -e "$work/killed/out.1002.exr" ] && break
  sleep 0.1
done
[ -e "$work/killed/out.1002.exr" ] || fail "job $job wrote no second frame in 60 s"
scancel "$job"
for _ in $(seq 300); do
  [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && break
  sleep 0.1
done
written=$(ls "$work/killed" | grep -c '^out\.' || true)
[ "$written" -lt 8 ] || fail "the cancelled task had already finished every frame; the test proves nothing"
leftovers=$(ls -A "$work/killed" | grep -v '^out\.[0-9]*\.exr$' || true)
[ -z "$leftovers" ] || fail "the cancelled task left $leftovers"
for file in "$work"/killed/out.*.exr; do
  cmp "$file" "$work/local/$(basename "$file")" || fail "$file, written before the cancel, is not the whole frame"
done
echo "cancelled after $written frames: only whole frames, nothing else left"
# 4. Resumed: the missing frames only.
"${submit[@]}" --frames-per-task 4 --wait -- "${camera[@]}" -o "$work/killed/out.####.exr" --skip-existing ||
  fail "the resumed job failed"
for frame in $(seq 1001 1008); do
  cmp "$work/killed/out.$frame.exr" "$work/local/out.$frame.exr" || fail "resumed frame $frame differs"
done
echo "resumed with --skip-existing: all 8 frames, equal to the local run"

#!/bin/bash
# tools/slurm/submit-bokeh-shot without a cluster (docs/farm.md): --dry-run shows each array task's
# frames as lensmith itself chunks them, and bad farm or bokeh options are refused before anything
# is submitted, with exit 2 and a message naming the problem.
# Usage: submit_script_test.sh LENSMITH SOURCE_DIR WORK_DIR
set -uo pipefail
lensmith=$1 source=$2 work=$3
submit="$source/tools/slurm/submit-bokeh-shot"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
cp "$source/examples/bokeh-scene.exr" plate.1001.exr
fail() { echo "FAILED: $*"; exit 1; }
shot=(--image plate.####.exr -o out/out.####.exr --lens canon-35mm-f1.8-1956 --frames 1001-1008)

# 8 frames in 3 tasks: 2, 3 and 3 frames (frame_chunk's near-equal split), and the sbatch command.
out=$("$submit" --lensmith "$lensmith" --chunks 3 --cpus-per-task 4 --dry-run -- "${shot[@]}") || fail "dry run failed: $out"
echo "$out"
grep -q -- "--array=0-2" <<<"$out" || fail "no --array=0-2 in the sbatch command"
grep -q -- "--cpus-per-task=4" <<<"$out" || fail "no --cpus-per-task=4"
grep -q "^task 0: frames 1001 1002 $" <<<"$out" || fail "task 0 is not frames 1001-1002"
grep -q "^task 2: frames 1006 1007 1008 $" <<<"$out" || fail "task 2 is not frames 1006-1008"
# --frames-per-task 3 of 1001-1010x3 (4 frames): 2 tasks.
out=$("$submit" --lensmith "$lensmith" --frames-per-task 3 --dry-run -- "${shot[@]:0:6}" --frames 1001-1010x3) || fail "$out"
grep -q "^task 1: frames 1007 1010 $" <<<"$out" || fail "frames-per-task 3 of 4 frames: 2 tasks, task 1 1007 and 1010: $out"
[ ! -e out ] || fail "a dry run made the output folder"

refused() {  # refused PATTERN ARGS...: exit 2 and PATTERN in the message
  local pattern=$1; shift
  local err status
  err=$("$submit" --lensmith "$lensmith" "$@" 2>&1 >/dev/null); status=$?
  [ "$status" -eq 2 ] || fail "expected exit 2 for: $* (got $status: $err)"
  grep -q -- "$pattern" <<<"$err" || fail "expected '$pattern' in: $err"
}
refused "--chunks 0: expected a whole number" --chunks 0 --dry-run -- "${shot[@]}"
refused "give one" --chunks 2 --frames-per-task 2 --dry-run -- "${shot[@]}"
refused "unknown option --nodes" --nodes 3 -- "${shot[@]}"
refused "leave it out" --dry-run -- "${shot[@]}" --threads 8
refused "leave it out" --dry-run -- "${shot[@]}" --chunk 0/2
refused "nothing was submitted" --dry-run -- "${shot[@]:0:6}" --frames 1001-
refused "not found or not executable" --lensmith /nonexistent/lensmith --dry-run -- "${shot[@]}"
refused "no lensmith bokeh options" --dry-run --
echo "submit-bokeh-shot: dry runs and refusals as documented"

#!/usr/bin/env bash
# A sweep through a real Slurm cluster (run inside tests/sweep/with_slurm_cluster.sh): 8 compose
# cells, one per task, in arrays split at MaxArraySize 4 with a %2 throttle; one task requeued
# while it runs (scontrol requeue), one cell made to fail; the aggregation job after the arrays;
# `status` names the task to resubmit; the resubmission runs exactly it; the aggregated tables
# equal the local backend's, byte for byte.
#   slurm_sweep_scenario.sh MMH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
mmh="$1"; src="$2"; work="$3"
fail() { echo "FAILED: $*" >&2; for f in "$work"/slurm_sweep/logs/*; do echo "== $f" >&2; tail -n 5 "$f" >&2; done; exit 1; }
story="$src/examples/synthetic_story"
cat >"$work/spec.json" <<SPEC
{
  "command": "compose",
  "inputs": {"takes": ["$story/take_1.tum", "$story/take_2.tum", "$story/take_3.tum"],
             "annotations": ["$story/take_1.csv", "$story/take_2.csv", "$story/take_3.csv"]},
  "axes": [{"key": "montage.labelling.mu", "values": [10, 1000]},
           {"key": "montage.labelling.min_segment_length", "values": [0, 30, 60, 90]}],
  "metrics": [{"name": "total_cost", "file": "summary.json", "key": "total_cost"},
              {"name": "segments", "file": "summary.json", "key": "segments"}],
  "slurm": {"throttle": 2, "cells_per_task": 1}
}
SPEC
dir="$work/slurm_sweep"
cd "$work"
cells=$("$mmh" sweep --dry-run --spec spec.json --out "$dir")
# Lines "ID  point P  replicate R ...": the cells of points 2 and 5.
slow=$(awk '$2 == "point" && $3 == 2 {print $1}' <<<"$cells")
failing=$(awk '$2 == "point" && $3 == 5 {print $1}' <<<"$cells")
[[ -n "$slow" && -n "$failing" ]] || fail "dry run: $cells"

wait_queue_empty() {
  for _ in $(seq 600); do
    [[ -z "$(squeue -h -o %i)" ]] && return 0
    sleep 0.5
  done
  squeue >&2; fail "the queue did not empty in 300 s"
}

# Submit with one slow cell (to requeue while it runs) and one failing cell.
out=$(MMH_SWEEP_FAULT="sleep:$slow,fail:$failing" "$mmh" sweep --backend slurm --spec spec.json --out "$dir")
echo "$out"
grep -q "8 cells in 8 tasks of up to 1 cells" <<<"$out" || fail "manifest: $out"
arrays=$(grep -c "^submitted array job" <<<"$out")
[[ $arrays -eq 2 ]] || fail "expected 2 arrays (MaxArraySize 4), got $arrays"
grep -q -- "--array=0-3%2, tasks from 0" <<<"$out" || fail "first array: $out"
grep -q -- "--array=0-3%2, tasks from 4" <<<"$out" || fail "second array: $out"
first=$(grep "^submitted array job" <<<"$out" | head -1 | awk '{print $4}')
grep -q "submitted the aggregation as job" <<<"$out" || fail "no aggregation job"
grep -q "^#SBATCH --requeue" "$dir/slurm/array.sh" || fail "array.sh is not requeue-able"

# Requeue task 2 (the slow cell) while it runs.
for _ in $(seq 600); do
  state=$(squeue -h -j "${first}_2" -o %T 2>/dev/null || true)
  [[ "$state" == RUNNING ]] && break
  sleep 0.2
done
[[ "$state" == RUNNING ]] || fail "task 2 never ran (state '$state')"
sleep 1
scontrol requeue "${first}_2"
echo "requeued ${first}_2"
wait_queue_empty

[[ -f "$dir/results.csv" ]] || fail "the aggregation job wrote no results.csv"
ls "$dir"/logs/aggregate_*.log >/dev/null || fail "no aggregation log"
[[ $(ls "$dir"/logs/task_*.log | wc -l) -ge 8 ]] || fail "not one log per task"
grep -q "$failing" "$dir/failures.csv" || fail "the failing cell is not in failures.csv"
[[ $(($(wc -l <"$dir/failures.csv") - 1)) -eq 1 ]] || fail "failures.csv: $(cat "$dir/failures.csv")"
[[ -f "$dir/cells/$slow/status.json" ]] || fail "the requeued cell is not complete"
leftovers=$(find "$dir/cells" -maxdepth 1 -name '.*' | wc -l)
[[ $leftovers -eq 0 ]] || fail "temporary folders left: $(ls -a "$dir/cells")"
grep -q "RUNNING\|requeue\|Requeue" "$dir"/logs/task_"${first}"_2.log 2>/dev/null || true
status=$("$mmh" sweep status "$dir")
echo "$status"
grep -q "8 cells: 7 done, 1 failed, 0 missing" <<<"$status" || fail "status: $status"
grep -q -- "resubmit: sbatch --array=1 --export=ALL,MMH_SWEEP_TASK_OFFSET=4" <<<"$status" ||
  fail "status does not name task 5 for resubmission: $status"

# Resubmit: exactly the task with the failed cell.
out=$("$mmh" sweep --backend slurm --spec spec.json --out "$dir")
echo "$out"
[[ $(grep -c "^submitted array job" <<<"$out") -eq 1 ]] || fail "resubmission: $out"
grep -q -- "--array=1%2, tasks from 4" <<<"$out" || fail "resubmission array: $out"
wait_queue_empty
status=$("$mmh" sweep status "$dir")
grep -q "8 cells: 8 done, 0 failed, 0 missing" <<<"$status" || fail "after resubmission: $status"

# The local backend on the same spec: the same tables, the same cell outputs.
"$mmh" sweep --quiet --jobs 2 --spec spec.json --out "$work/local_sweep"
for f in results.csv summary.csv variance_shares.csv failures.csv; do
  cmp "$dir/$f" "$work/local_sweep/$f" || fail "$f differs between Slurm and local"
done
for cell in "$dir"/cells/*/; do
  id=$(basename "$cell")
  for f in montage.tum segments.csv timeline.csv config.resolved.json; do
    cmp "$cell/out/$f" "$work/local_sweep/cells/$id/out/$f" || fail "cell $id: $f differs"
  done
done
echo "slurm sweep scenario: ok"

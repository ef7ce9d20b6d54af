#!/usr/bin/env bash
# On a real Slurm: a one-node cluster on this machine (munged, slurmctld and
# slurmd started here with a config written to a temporary directory, two
# CPUs), scripts/slurm/submit.sh runs a small grid as a job array and the
# cells equal a plain local run bit for bit. Then three trainings are
# stopped three ways: a plain `scancel --signal=TERM` (to the job step) and
# USR1 to the batch shell (as --signal=B:USR1@120 does) each save the state,
# exit 75 and requeue the task, which logs that it starts again after a
# requeue; a plain `scancel` saves the state and is not requeued. While the
# requeued tasks wait (BeginTime), `tcbench status` counts their cells as
# queued, not missing, and submit.sh resubmits only the cancelled one; all
# end with the uninterrupted cells. Needs root and Debian's slurm-wlm and
# munge (scripts/setup.sh --tests installs them); skips loudly otherwise.
# A per-clip grid (docs/protocol.md, "Per-clip fitting") over two array
# tasks equals its local run too.
# The daemons are stopped whatever happens.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
skip() { echo "SKIP: $*"; exit 77; }
source "$TCB_SOURCE_DIR/scripts/slurm/local-cluster.sh"
if why=$(slurm_local_missing); then skip "$why"; fi

tmp=$(mktemp -d)
chmod 755 "$tmp"
refs=()
trap '[ ${#refs[@]} -eq 0 ] || kill "${refs[@]}" 2> /dev/null; slurm_local_stop "$tmp"; rm -rf "$tmp"' EXIT
cd "$tmp"
why=$(slurm_local_start "$tmp" 2) || skip "$why"
export SLURM_CONF="$tmp/slurm.conf"

# A grid of four cells, submitted as an array of one-CPU tasks.
cat > grid.json <<'JSON'
{ "name": "grid", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1], "threads": 1,
  "evaluation": { "pairs": 5, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 30, "checkpoint_every": 0 } } ] }
JSON
"$TCBENCH" run grid.json --out plain --quiet 2> /dev/null
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" grid.json --out "$tmp/slurm" \
    --sbatch "--wait -c 1 -o $tmp/task-%a.log" > submit.txt 2>&1 || { cat submit.txt task-*.log slurmctld.log; exit 1; }
grep -qxF "submit.sh: using $(realpath "$TCBENCH") (TCBENCH)" submit.txt || { cat submit.txt; exit 1; }
same_cells plain slurm

# A per-clip grid (each clip fitted on its own: a cell per clip and method)
# over two array tasks equals its local run.
cat > clips.json <<'JSON'
{ "name": "clips", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "protocol": "clips", "fit": "per_clip", "pool_size": 1000, "input_points": 300,
                  "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 20, "normalization": "clip_bbox",
                  "sequences": [ { "name": "quadruped_walk", "role": "test", "clip_starts": [0, 3] } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 20, "checkpoint_every": 0 } } ] }
JSON
"$TCBENCH" run clips.json --out clips-plain --quiet 2> /dev/null
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" clips.json --tasks 2 --out "$tmp/clips-slurm" \
    --sbatch "--wait -c 1 -o $tmp/clips-%a.log" > submit.txt 2>&1 || { cat submit.txt clips-*.log; exit 1; }
[ "$(find clips-slurm/cells -name 'seed_0.json' | wc -l)" -eq 4 ] || { echo "FAIL: per-clip cells"; exit 1; }
same_cells clips-plain clips-slurm

# Stops: three trainings (cells 1-3) after a nearest cell (0), one-CPU tasks.
sed 's/"iterations": 30/"iterations": 800/; s/"seeds": \[0, 1\]/"seeds": [0, 1, 2]/
     s/{ "name": "nearest" }/{ "name": "nearest", "seeds": [0] }/' grid.json > long.json
# The uninterrupted cells, by two local runs sharing the cells, meanwhile.
refs=()
for _ in 1 2; do "$TCBENCH" run long.json --out plain-long --quiet 2> /dev/null & refs+=($!); done
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" long.json --out "$tmp/long" --max-running 3 \
    --sbatch "-c 1 -o $tmp/long-%a.log" > submit-long.txt 2>&1 || { cat submit-long.txt; exit 1; }
job=$(sed -n 's/^Submitted batch job \([0-9]*\)$/\1/p' submit-long.txt)
scontrol show job "$job" | grep -q "ArrayTaskThrottle=3" || { echo "FAIL: --max-running"; scontrol show job "$job"; exit 1; }
cell() { echo "long/cells/synth/quadruped_walk/mca/seed_$(($1 - 1)).json"; } # cell ID's file
fail() { echo "FAIL: $1"; cat long-*.log; squeue; exit 1; }
# training ID: wait until cell ID's task holds its lock and is into the training.
training() {
    for _ in $(seq 600); do [ -e "$(cell "$1").lock" ] && break; sleep 0.1; done
    [ -e "$(cell "$1").lock" ] || fail "task $1 did not start"
    sleep 1
}
# scancel ARGS, again while slurmctld answers that the job "can not be
# altered now, try again later" (a task still configuring on a loaded
# machine); any other error at once.
signal() {
    for _ in $(seq 50); do
        scancel "$@" 2> scancel.err && return 0
        grep -q "try again later" scancel.err || { cat scancel.err; return 1; }
        sleep 0.2
    done
    cat scancel.err
    return 1
}
training 1
training 2
signal --signal=TERM "${job}_1" || fail "could not signal task 1"
signal "${job}_2" || fail "could not cancel task 2"
training 3
signal --batch --signal=USR1 "${job}_3" || fail "could not signal task 3"
# Slurm holds a requeued job back (BeginTime: until the old job's
# credential has expired, 120 s); let it start sooner, but only 2 s after
# the requeue: slurmd refuses a credential created within the second its
# predecessor was revoked in (and the job then fails and leaves the queue).
for k in 1 3; do
    for _ in $(seq 600); do
        scontrol show job "${job}_$k" 2> /dev/null | grep -q "Reason=BeginTime" && break
        sleep 0.1
    done
done
for _ in $(seq 100); do [ -z "$(squeue -h -j "${job}_2" 2> /dev/null)" ] && break; sleep 0.1; done
# Cells 1 and 3 are queued (their tasks wait), cell 2 missing (cancelled).
"$TCBENCH" status long.json --out long > status.txt
grep -qxF "queued   1,3: pending or running in Slurm (job $job)" status.txt &&
    grep -qF "long: 4 cells: 1 done, 0 diverged, 0 failed, 0 running, 0 stale, 1 missing, 2 queued in Slurm" status.txt &&
    grep -qxF "resubmit the cells a run computes (1 missing, 0 failed, 0 stale): --array=2" status.txt ||
    { echo "FAIL: status"; cat status.txt; squeue -r; exit 1; }
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" long.json --out "$tmp/long" \
    --sbatch "-c 1 -o $tmp/again-%a.log" > submit-again.txt 2>&1 || { cat submit-again.txt; exit 1; }
again=$(sed -n 's/^Submitted batch job \([0-9]*\)$/\1/p' submit-again.txt)
scontrol show job "$again" | grep -qw "ArrayTaskId=2" || { echo "FAIL: not cell 2 alone"; scontrol show job "$again"; exit 1; }
sleep 2
scontrol update JobId="${job}_1" StartTime=now
scontrol update JobId="${job}_3" StartTime=now
for _ in $(seq 1500); do
    [ -s "$(cell 1)" ] && [ -s "$(cell 2)" ] && [ -s "$(cell 3)" ] && [ -z "$(squeue -h 2> /dev/null)" ] && break
    sleep 0.2
done
[ -s "$(cell 1)" ] && [ -s "$(cell 2)" ] && [ -s "$(cell 3)" ] ||
    { cat again-*.log; scontrol show job "${job}_1"; tail -20 slurmctld.log slurmd.log; fail "the tasks did not finish"; }
# Where a stop lands depends on the machine's speed: mid-training mostly.
saved="stopped (at iteration [0-9]+ of 800; training state saved|at pair|before cell)"
requeued="starts again after a requeue (restart 1); a \"CANCELLED ... DUE TO JOB REQUEUE\" line above"
for k in 1 3; do
    grep -qE "$saved" "long-$k.log" && grep -qF "stopped with its state saved; requeueing ${job}_$k (" "long-$k.log" &&
        grep -qF "tcbench: task ${job}_$k $requeued" "long-$k.log" || fail "task $k was not requeued"
done
grep -qF "SIGTERM received" long-1.log && grep -qF "SIGUSR1 received" long-3.log || fail "not the signals sent"
grep -qE "$saved" long-2.log && grep -qF "Slurm is ending ${job}_2 (" long-2.log &&
    ! grep -qF "requeueing" long-2.log || fail "the cancelled task was requeued"
[ "$(grep -c "computed" long-0.log)" -eq 1 ] || fail "the other task ran again"
[ -z "$(find long/work -name train.ckpt)" ] || fail "training state left"
for r in "${refs[@]}"; do wait "$r" || { echo "FAIL: the local run"; exit 1; }; done
refs=()
same_cells plain-long long
echo "slurm test passed"

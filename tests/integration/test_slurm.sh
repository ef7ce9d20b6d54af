#!/usr/bin/env bash
# On a real Slurm: a one-node cluster on this machine (munged, slurmctld and
# slurmd started here with a config written to a temporary directory, two
# CPUs), scripts/slurm/submit.sh runs a small grid as a job array and the
# cells equal a plain local run bit for bit; a training task told to stop
# (USR1 to its batch shell, as --signal=B:USR1@120 does) saves its state,
# exits 75, requeues itself and ends with the uninterrupted cell. Needs root
# and Debian's slurm-wlm and munge (scripts/setup.sh --tests installs them);
# skips loudly otherwise. The daemons are stopped whatever happens.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
skip() { echo "SKIP: $*"; exit 77; }
source "$TCB_SOURCE_DIR/scripts/slurm/local-cluster.sh"
if why=$(slurm_local_missing); then skip "$why"; fi

tmp=$(mktemp -d)
chmod 755 "$tmp"
trap 'slurm_local_stop "$tmp"; rm -rf "$tmp"' EXIT
cd "$tmp"
why=$(slurm_local_start "$tmp" 2) || skip "$why"
export SLURM_CONF="$tmp/slurm.conf"

# A grid of four cells, submitted as an array of one-CPU tasks.
cat > grid.json <<'JSON'
{ "name": "grid", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1], "threads": 1,
  "evaluation": { "pairs": 5, "pool_size": 1000, "input_points": 300 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 100, "checkpoint_every": 0 } } ] }
JSON
"$TCBENCH" run grid.json --out plain --quiet 2> /dev/null
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" grid.json --out "$tmp/slurm" \
    --sbatch "--wait -c 1 -o $tmp/task-%a.log" > submit.txt 2>&1 || { cat submit.txt task-*.log slurmctld.log; exit 1; }
same_cells plain slurm

# Preemption: USR1 to the batch shell mid-training; the task requeues itself.
sed 's/"iterations": 100/"iterations": 800/; s/"seeds": \[0, 1\]/"seeds": [0]/' grid.json > long.json
"$TCBENCH" run long.json --out plain-long --quiet 2> /dev/null
TCBENCH="$TCBENCH" "$TCB_SOURCE_DIR/scripts/slurm/submit.sh" long.json --out "$tmp/long" \
    --sbatch "-c 1 -o $tmp/long-%a.log" > submit-long.txt 2>&1 || { cat submit-long.txt; exit 1; }
job=$(sed -n 's/^Submitted batch job \([0-9]*\)$/\1/p' submit-long.txt)
train=long/work/synth/quadruped_walk/mca/seed_0
lock=long/cells/synth/quadruped_walk/mca/seed_0.json.lock
for _ in $(seq 600); do [ -e "$lock" ] && break; sleep 0.1; done
sleep 1 # into the training
scancel --batch --signal=USR1 "${job}_1" || { echo "FAIL: could not signal the task"; cat long-1.log; exit 1; }
# Slurm holds a requeued job back (BeginTime: until the old job's
# credential has expired, 120 s); let it start sooner, but only 2 s after
# the requeue: slurmd refuses a credential created within the second its
# predecessor was revoked in (and the job then fails and leaves the queue).
for _ in $(seq 600); do
    scontrol show job "${job}_1" 2> /dev/null | grep -q "Reason=BeginTime" && break
    sleep 0.1
done
sleep 2
scontrol update JobId="${job}_1" StartTime=now
for _ in $(seq 1200); do
    [ -s long/cells/synth/quadruped_walk/mca/seed_0.json ] && [ -z "$(squeue -h -j "$job" 2> /dev/null)" ] && break
    sleep 0.2
done
[ -s long/cells/synth/quadruped_walk/mca/seed_0.json ] || {
    echo "FAIL: the requeued task did not finish"
    cat long-*.log; squeue; scontrol show job "${job}_1"; tail -20 slurmctld.log slurmd.log
    exit 1
}
# Where the stop lands depends on the machine's speed: mid-training mostly.
grep -qE "stopped (at iteration [0-9]+ of 800; training state saved|at pair|before cell)" long-1.log &&
    grep -qF "stopped with its state saved; requeueing ${job}_1" long-1.log || { echo "FAIL: no requeue"; cat long-1.log; exit 1; }
[ "$(grep -c "computed" long-0.log)" -eq 1 ] || { echo "FAIL: the other task ran again"; cat long-0.log; exit 1; }
[ ! -e "$train/train.ckpt" ] || { echo "FAIL: training state left"; exit 1; }
same_cells plain-long long
echo "slurm test passed"

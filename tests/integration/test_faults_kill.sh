#!/usr/bin/env bash
# SIGKILL at any moment (issue 18): a grid of every kind of work — a
# stateless method, a training with frequent checkpoints, nrICP's
# consecutive maps and deform chains — is killed again and again, at seeded random moments
# and at chosen ones (mid-training after a checkpoint, mid-evaluation,
# mid-registration). After every kill each cell file present is complete and
# equal to an uninterrupted run's; the run resumed after the last kill
# finishes with every cell equal to the uninterrupted run's, bit for bit,
# and leaves no temporary or lock. A failure prints the seed; rerun with
# TCB_FAULT_SEED=<seed> to replay its delays.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

seed=${TCB_FAULT_SEED:-18}
RANDOM=$seed
enter_temp_dir

cat > grid.json <<'JSON'
{ "name": "kill", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 400, "input_points": 150, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 4,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 40, "checkpoint_every": 5 } },
               { "name": "nricp", "params": { "strategy": "propagate_simple" } },
               { "name": "deform", "method": "nricp", "params": { "strategy": "propagate_deform" } } ] }
JSON
now_ms() { echo $(($(date +%s%N) / 1000000)); }
t0=$(now_ms)
"$TCBENCH" run grid.json --out full --quiet
full_ms=$(($(now_ms) - t0))
echo "uninterrupted run: $full_ms ms; kill delays drawn with seed $seed"

n=0
# kill_run CONDITION...: a run of the grid on `killed`, SIGKILLed once
# CONDITION holds (or left to finish), then checked: whatever cells it
# left are whole and right. Its log is run<n>.log.
kill_run() {
    n=$((n + 1))
    CI= "$TCBENCH" run grid.json --out killed 2> "run$n.log" &
    pid=$!
    kill_when "$pid" "$@"
    pid=""
    cells_within full killed > /dev/null || { echo "FAIL: after kill $n"; cat "run$n.log"; exit 1; }
}
past() { [ "$(now_ms)" -ge "$1" ]; }
logged() { grep -qF -- "$1" "run$n.log"; }
training_saved() { compgen -G 'killed/work/synth/*/mca/seed_0/train.ckpt' > /dev/null; }

for _ in 1 2 3; do
    kill_run past $(($(now_ms) + (RANDOM * 32768 + RANDOM) % full_ms))
done
# Chosen moments, each on work the random kills may have finished: the
# grid starts over in a fresh directory for them.
rm -rf killed
kill_run training_saved
kill_run logged "nricp: consecutive maps"
kill_run logged "nricp: deform chains"
kill_run logged "mca/seed 0: "
kill_run past $(($(now_ms) + full_ms / 3))
n=$((n + 1))
CI= "$TCBENCH" run grid.json --out killed 2> "run$n.log"
grep -q "resuming training at iteration [1-9]" run*.log || { echo "FAIL: no training was resumed"; cat run*.log; exit 1; }
same_cells full killed
leftovers=$(find killed splits -name '*.tmp-*' -o -name '*.lock*')
[ -z "$leftovers" ] || { echo "FAIL: left behind: $leftovers"; exit 1; }
echo "kill test passed ($n runs)"

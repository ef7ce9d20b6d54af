#!/usr/bin/env bash
# Preemption (Slurm's SIGTERM, or --signal=USR1): a run asked to stop saves
# its training at the next iteration (without periodic checkpoints too),
# releases the cell, leaves no result for it and exits 75; the rerun resumes
# and ends with the cell of an uninterrupted run, bit for bit. A stop during
# an evaluation keeps the fitted model and only redoes the evaluation. An
# nricp fit stopped mid-way keeps the consecutive maps it has.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

enter_temp_dir

cat > train.json <<'JSON'
{ "name": "train", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 20, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "mca", "params": { "preset": "tiny", "iterations": 400, "checkpoint_every": 0 } } ] }
JSON
work=work/synth/quadruped_walk/mca/seed_0
cell=cells/synth/quadruped_walk/mca/seed_0.json
"$TCBENCH" run train.json --out full --quiet

# stop_when SIGNAL LOG TEXT: signal the run once LOG shows TEXT; its exit status.
stop_when() {
    local sig=$1 log=$2 text=$3 rc=0
    for _ in $(seq 3000); do grep -qF -- "$text" "$log" 2>/dev/null && break; sleep 0.02; done
    kill "-$sig" "$pid"
    wait "$pid" || rc=$?
    pid=""
    return "$rc"
}

# During the training: SIGTERM.
CI= "$TCBENCH" run train.json --out stopped 2> term.log &
pid=$!
rc=0; stop_when TERM term.log "mca: " || rc=$?
[ "$rc" -eq 75 ] || { echo "FAIL: exit $rc after SIGTERM, expected 75"; cat term.log; exit 1; }
grep -q "stopped at iteration [0-9]* of 400; training state saved in .*train.ckpt" term.log || { cat term.log; exit 1; }
[ -s "stopped/$work/train.ckpt" ] && [ ! -e "stopped/$cell" ] && [ -z "$(find stopped -name '*.lock')" ] ||
    { echo "FAIL: expected a training state, no cell and no lock"; find stopped; exit 1; }
CI= "$TCBENCH" run train.json --out stopped 2> resume.log
grep -q "resuming training at iteration [1-9]" resume.log || { echo "FAIL: did not resume"; cat resume.log; exit 1; }
same_cells full stopped

# During the evaluation: SIGUSR1; the model checkpoint is reused, not refitted.
rm "stopped/$cell"
CI= "$TCBENCH" run train.json --out stopped 2> usr1.log &
pid=$!
rc=0; stop_when USR1 usr1.log "seed 0: " || rc=$?
[ "$rc" -eq 75 ] && grep -qF "of the evaluation (the fitted model is kept)" usr1.log || { echo "FAIL: exit $rc"; cat usr1.log; exit 1; }
CI= "$TCBENCH" run train.json --out stopped 2> again.log
grep -q "resuming training" again.log && { echo "FAIL: the fitted model was not kept"; cat again.log; exit 1; }
same_cells full stopped
# nricp's consecutive maps: SIGTERM mid-fit saves the maps done so far;
# the rerun registers only the others and ends with the same cell.
cat > maps.json <<'JSON'
{ "name": "maps", "splits_dir": "maps_splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 20, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "nricp", "params": { "strategy": "propagate_bijective" } } ] }
JSON
work=work/synth/quadruped_walk/nricp/seed_0
cell=cells/synth/quadruped_walk/nricp/seed_0.json
"$TCBENCH" run maps.json --out maps_full --quiet
CI= "$TCBENCH" run maps.json --out maps_stopped 2> maps_term.log &
pid=$!
rc=0; stop_when TERM maps_term.log "nricp: consecutive maps: " || rc=$?
[ "$rc" -eq 75 ] || { echo "FAIL: nricp: exit $rc after SIGTERM, expected 75"; cat maps_term.log; exit 1; }
grep -q "stopped after [1-9][0-9]* of 22 consecutive maps; maps saved in .*nricp_maps.partial" maps_term.log ||
    { cat maps_term.log; exit 1; }
[ -s "maps_stopped/$work/nricp_maps.partial" ] && [ ! -e "maps_stopped/$cell" ] ||
    { echo "FAIL: expected the partial maps and no cell"; find maps_stopped; exit 1; }
CI= "$TCBENCH" run maps.json --out maps_stopped 2> maps_resume.log
grep -q "resuming the consecutive maps with [1-9][0-9]* of 22 done" maps_resume.log ||
    { echo "FAIL: nricp did not resume"; cat maps_resume.log; exit 1; }
[ ! -e "maps_stopped/$work/nricp_maps.partial" ] || { echo "FAIL: the partial maps were left behind"; exit 1; }
same_cells maps_full maps_stopped
echo "preemption test passed"

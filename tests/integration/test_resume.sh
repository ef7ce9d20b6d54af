#!/usr/bin/env bash
# Resume: a run killed (SIGKILL) midway and rerun yields cell files identical
# to an uninterrupted run (timings and peak RSS aside) and leaves no
# temporaries; a finished run reruns as all skips; a checkpoint (good or
# corrupt) gives the same cell as a fit, one without its record is fitted
# again; changed settings refuse to resume.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/harness_methods.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

enter_temp_dir
build_harness_methods "$tmp/libharness_methods.so"

cat > grid.json <<JSON
{ "name": "grid", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1],
  "plugins": ["$tmp/libharness_methods.so"],
  "evaluation": { "pairs": 10, "pool_size": 1000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" },
                                 { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" },
               { "name": "slow", "method": "slow_noisy", "params": { "delay_ms": 40, "noise": 0.01 } } ] }
JSON
n_cells=12
count_cells() { find "$1/cells" -name 'seed_*.json' 2>/dev/null | wc -l; }


"$TCBENCH" run grid.json --out full --quiet
[ "$(count_cells full)" -eq $n_cells ] || { echo "FAIL: uninterrupted run incomplete"; exit 1; }

# Kill a second run once a few cells are done, then resume it.
"$TCBENCH" run grid.json --out killed --quiet 2> killed.log &
pid=$!
three_done() { [ "$(count_cells killed)" -ge 3 ]; }
kill_when "$pid" three_done
pid=""
done_at_kill=$(count_cells killed)
if [ "$done_at_kill" -lt 3 ] || [ "$done_at_kill" -ge $n_cells ]; then
    echo "FAIL: killed with $done_at_kill of $n_cells cells done (expected a partial run)"
    cat killed.log; exit 1
fi
# What a kill during an atomic write leaves behind, on a cell still to do:
# the cell's temporary, its lock's (a claim killed before its link), the
# config's.
mkdir -p killed/cells/synth/quadruped_trot/slow
touch killed/cells/synth/quadruped_trot/slow/seed_1.json.tmp-Ab12Cd \
      killed/cells/synth/quadruped_trot/slow/seed_1.json.lock.tmp-Ef56Gh killed/config.json.tmp-Xy34Zw
"$TCBENCH" run grid.json --out killed --quiet 2> resume.log
grep -qF "$((n_cells - done_at_kill)) computed, $done_at_kill already done" resume.log ||
    { cat resume.log; exit 1; }
same_cells full killed
leftovers=$(find killed splits -name '*.tmp-*')
[ -z "$leftovers" ] || { echo "FAIL: temporaries left: $leftovers"; exit 1; }

# A finished run skips every cell.
"$TCBENCH" run grid.json --out killed --quiet 2> rerun.log
grep -qF "0 computed, $n_cells already done" rerun.log || { cat rerun.log; exit 1; }
# A process killed between writing its cell and releasing the lock leaves
# a finished cell with a dead holder's lock: the next run removes it, and a
# live holder's stays.
true & dead=$!
wait "$dead"
stale=killed/cells/synth/quadruped_walk/nearest/seed_0.json.lock
live=killed/cells/synth/quadruped_walk/nearest/seed_1.json.lock
printf '{"host": "%s", "pid": %d, "started": 1.5}\n' "$(hostname)" "$dead" > "$stale"
printf '{"host": "%s", "pid": %d, "started": 1.5}\n' "$(hostname)" "$$" > "$live"
"$TCBENCH" run grid.json --out killed --quiet 2> stale.log
grep -qF "0 computed, $n_cells already done" stale.log || { cat stale.log; exit 1; }
[ ! -e "$stale" ] || { echo "FAIL: a dead process's lock outlived its finished cell"; exit 1; }
[ -e "$live" ] || { echo "FAIL: a live holder's lock was removed"; exit 1; }
rm "$live"

# Evaluation resumed from a checkpoint (then from a corrupt one) matches.
cell=killed/cells/synth/quadruped_trot/slow/seed_1.json
ckpt=killed/work/synth/quadruped_trot/slow/seed_1/model.ckpt
[ -s "$ckpt" ] || { echo "FAIL: no checkpoint at $ckpt"; exit 1; }
rm "$cell"
"$TCBENCH" run grid.json --out killed --quiet 2> ckpt.log
grep -qF "1 computed" ckpt.log || { cat ckpt.log; exit 1; }
same_cells full killed
echo "garbage" > "$ckpt"
rm "$cell"
"$TCBENCH" run grid.json --out killed 2> corrupt.log
grep -qF "not reused" corrupt.log || { echo "FAIL: corrupt checkpoint not reported"; cat corrupt.log; exit 1; }
same_cells full killed

# fit_s counts the whole fit: the seconds a method reports for the training
# it continued, and, when the model checkpoint is reused, the fit time
# recorded beside it (not the moment it takes to load the model).
fit_s() { /usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["timings"]["fit_s"])' "$1"; }
at_least_1000() { /usr/bin/python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) >= 1000 else 1)' "$1"; }
sed 's/"noise": 0.01/"noise": 0.01, "resumed_fit_s": 1000/' grid.json > resumed.json
"$TCBENCH" run resumed.json --out resumed --only slow --quiet
rcell=resumed/cells/synth/quadruped_trot/slow/seed_1.json
at_least_1000 "$(fit_s "$rcell")" || { echo "FAIL: fit_s $(fit_s "$rcell") leaves out the resumed 1000 s"; exit 1; }
rm "$rcell"
"$TCBENCH" run resumed.json --out resumed --only slow --quiet 2> reused.log
at_least_1000 "$(fit_s "$rcell")" ||
    { echo "FAIL: a reused checkpoint reports fit_s $(fit_s "$rcell")"; cat reused.log; exit 1; }
rm "$rcell" resumed/work/synth/quadruped_trot/slow/seed_1/model.ckpt.fit.json
"$TCBENCH" run resumed.json --out resumed --only slow 2> unrecorded.log
grep -qF "model.ckpt: not reused (resumed/work/synth/quadruped_trot/slow/seed_1/model.ckpt.fit.json: " unrecorded.log ||
    { echo "FAIL: a checkpoint without its record was not refused"; cat unrecorded.log; exit 1; }
at_least_1000 "$(fit_s "$rcell")" || { echo "FAIL: the refit reports fit_s $(fit_s "$rcell")"; exit 1; }

# Cells made with other settings are not silently mixed in: a method whose
# params changed is refused by the run directory (the others run), and
# once --force --only recomputed it, the old config is refused for it.
sed 's/"noise": 0.01/"noise": 0.02/' grid.json > changed.json
rc=0
"$TCBENCH" run changed.json --out killed --quiet 2> changed.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "holds slow's cells with other settings (methods[slow].params.noise: 0.01 there, 0.02 here)" changed.log ||
    { echo "FAIL: changed params resumed (exit $rc)"; cat changed.log; exit 1; }
"$TCBENCH" run changed.json --out killed --quiet --only slow --force
"$TCBENCH" run grid.json --out killed --quiet --only oracle --force
rc=0
"$TCBENCH" run grid.json --out killed --quiet 2> mixed.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "(methods[slow].params.noise: 0.02 there, 0.01 here)" mixed.log ||
    { echo "FAIL: a cell of other params resumed (exit $rc)"; cat mixed.log; exit 1; }
echo "resume test passed"

#!/usr/bin/env bash
# Many processes, one run directory (issue 16's launcher-free case): four
# `tcbench run` started at once finish the config with every cell computed
# exactly once, also when one of them is SIGKILLed midway and a fifth is
# started later (the dead one's lock is taken over, and said so); the cells
# equal a plain run's bit for bit and no lock is left behind.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/harness_methods.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

tmp=$(mktemp -d)
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
cd "$tmp"
build_harness_methods "$tmp/libharness_methods.so"

cat > grid.json <<JSON
{ "name": "grid", "cache_dir": "", "seeds": [0, 1, 2], "threads": 1,
  "plugins": ["$tmp/libharness_methods.so"],
  "evaluation": { "pairs": 10, "pool_size": 1000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" },
                                 { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "slow", "method": "slow_noisy", "params": { "delay_ms": 30, "noise": 0.01 } } ] }
JSON
n_cells=12
count_cells() { find "$1/cells" -name 'seed_*.json' 2>/dev/null | wc -l; }
computed() { # the cells the runs whose logs are given computed, summed
    local total=0 n
    for n in $(sed -n 's/^cells: [0-9]* in all, \([0-9]*\) computed.*/\1/p' "$@"); do total=$((total + n)); done
    echo "$total"
}

"$TCBENCH" run grid.json --out plain --quiet 2> /dev/null

# Four at once.
for k in 1 2 3 4; do "$TCBENCH" run grid.json --out shared --quiet 2> "run$k.log" & pids+=($!); done
wait "${pids[@]}"
pids=()
[ "$(computed run?.log)" -eq $n_cells ] || { echo "FAIL: $(computed run?.log) cells computed for $n_cells"; cat run?.log; exit 1; }
grep -q "running in other processes" run?.log || { echo "FAIL: no process met another's lock"; cat run?.log; exit 1; }
same_cells plain shared

# Four at once, one of them killed while it holds a lock; a fifth finishes.
# The victim starts first and is stopped (SIGSTOP) while it holds the lock
# of a cell it has not written; the others start beside it, and it is
# killed in that state. Started all together, the others could claim every
# cell before the victim held one (seen on an idle machine); a victim
# merely watched could finish its last cell, or write it and be killed
# before releasing its lock, and leave nothing to take over (seen on a
# loaded one).
"$TCBENCH" run grid.json --out killed 2> victim.log & victim=$!
pids+=("$victim")
# A lock of a slow cell (0.3 s): a nearest cell takes milliseconds.
holds_lock() {
    local lock
    for lock in killed/cells/*/*/slow/*.lock; do
        [ -e "$lock" ] && [ ! -e "${lock%.lock}" ] && grep -q "$victim" "$lock" 2>/dev/null && return 0
    done
    return 1
}
stop_when "$victim" holds_lock || { echo "FAIL: the victim never held a lock"; cat victim.log; exit 1; }
for k in 1 2 3; do "$TCBENCH" run grid.json --out killed --quiet 2> "k$k.log" & pids+=($!); done
sleep 0.2
kill -9 "$victim"
wait "$victim" 2>/dev/null || true
wait "${pids[@]:1:3}" || true
pids=()
"$TCBENCH" run grid.json --out killed 2> fifth.log
grep -qF "took over the lock of " k?.log fifth.log || { echo "FAIL: the victim's lock was not taken over"; cat k?.log fifth.log; exit 1; }
[ "$(count_cells killed)" -eq $n_cells ] || { echo "FAIL: incomplete"; exit 1; }
same_cells plain killed
[ -z "$(find shared killed -name '*.lock*')" ] || { echo "FAIL: locks left"; find shared killed -name '*.lock*'; exit 1; }
# A lock of another machine: left alone while its heartbeat is fresh, taken
# over once it is older than --lock-timeout.
cell=foreign/cells/synth/quadruped_walk/nearest/seed_1.json
mkdir -p "$(dirname "$cell")"
echo '{"host": "node-17", "pid": 4242, "started": 1.5}' > "$cell.lock"
"$TCBENCH" run grid.json --out foreign --quiet 2> fresh.log
grep -qF "cells: 12 in all, 11 computed, 0 already done, 0 failed, 1 running in other processes" fresh.log ||
    { cat fresh.log; exit 1; }
"$TCBENCH" cells grid.json --out foreign > cells.txt
grep -qE "nearest +1  running \(node-17 pid 4242, heartbeat [0-9]+ s ago\)" cells.txt || { cat cells.txt; exit 1; }
"$TCBENCH" run grid.json --out foreign --dry-run > dry.txt
grep -qE "^ +1  nearest +1  running +[0-9.]+ s" dry.txt &&
    grep -qF "cells: 12, 11 finished, 1 running in other processes, 0 to run" dry.txt || { cat dry.txt; exit 1; }
touch -d '-2 minutes' "$cell.lock"
# Older than --lock-timeout: stale, and the next run computes it.
"$TCBENCH" cells grid.json --out foreign --lock-timeout 60 > cells.txt
grep -qE "nearest +1  stale \(node-17 pid 4242: its heartbeat stopped, heartbeat 1[0-9]{2} s ago\)" cells.txt ||
    { cat cells.txt; exit 1; }
"$TCBENCH" status foreign --lock-timeout 60 > status.txt
grep -qE "^stale +[0-9]+  synth/quadruped_walk/nearest seed 1: \(node-17 pid 4242: its heartbeat stopped" status.txt &&
    grep -qF "1 running, 0 stale" <("$TCBENCH" status foreign) &&
    grep -qE "^resubmit the cells a run computes \(0 missing, 0 failed, 1 stale\): --array=[0-9]+$" status.txt ||
    { cat status.txt; exit 1; }
"$TCBENCH" run grid.json --out foreign --lock-timeout 60 2> stale.log
grep -qF "took over the lock of node-17 pid 4242: its heartbeat stopped" stale.log || { cat stale.log; exit 1; }
same_cells plain foreign

# A holder of this host that is gone (killed, its machine restarted) is
# stale at once, whatever its heartbeat's age.
cell=gone/cells/synth/quadruped_walk/nearest/seed_2.json
mkdir -p "$(dirname "$cell")"
sleep 0 & dead=$!
wait $dead
printf '{"host": "%s", "pid": %d, "started": 1.5}' "$(uname -n)" "$dead" > "$cell.lock"
"$TCBENCH" cells grid.json --out gone > cells.txt
grep -qE "nearest +2  stale \(.* pid $dead: its process is gone, heartbeat [0-9]+ s ago\)" cells.txt ||
    { cat cells.txt; exit 1; }
"$TCBENCH" run grid.json --out gone 2> gone.log
grep -qF "took over the lock of $(uname -n) pid $dead: its process is gone" gone.log || { cat gone.log; exit 1; }
same_cells plain gone

# A live holder's progress: each heartbeat (every --lock-timeout/4 s) notes
# it beside the lock, `cells` shows it, and it goes with the lock.
sed 's/"delay_ms": 30/"delay_ms": 300/; s/"seeds": \[0, 1, 2\]/"seeds": [0]/' grid.json > progress.json
cell=prog/cells/synth/quadruped_walk/slow/seed_0.json
"$TCBENCH" run progress.json --out prog --only slow --lock-timeout 4 --quiet 2> prog.log & pids+=($!)
for _ in $(seq 200); do [ -s "$cell.lock.progress" ] && break; sleep 0.1; done
"$TCBENCH" cells progress.json --out prog > prog_cells.txt
wait "${pids[@]}"
pids=()
grep -qE "slow +[0-9]+  running \(.* heartbeat [0-9]+ s ago; synth/quadruped_walk/slow/seed 0 [0-9]+/10 \([0-9]+ %\)\)" \
    prog_cells.txt || { echo "FAIL: no progress in cells"; cat prog_cells.txt prog.log; exit 1; }
[ -z "$(find prog -name '*.lock*')" ] || { echo "FAIL: lock or progress left"; find prog -name '*.lock*'; exit 1; }
echo "concurrent runs test passed"

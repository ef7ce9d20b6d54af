#!/usr/bin/env bash
# A grid on a one-node Slurm against one local run, on the same machine:
#   bench/slurm_vs_local.sh CONFIG [tcbench run options, e.g. --root anim=DIR]
# runs CONFIG once with `tcbench run --threads CPUS` and once as a Slurm job
# array of one-CPU tasks (scripts/slurm/submit.sh, one task per cell, CPUS
# of them at a time) on a one-node Slurm this script starts
# (scripts/slurm/local-cluster.sh), each into a fresh run directory, and
# prints both wall times, their ratio and each task's overhead: from the
# moment a CPU was there for it (the submission, or the end of the cell it
# waited for) to its first training iteration (its cell's lock appearing,
# plus the cell's own load time). Needs root, slurm-wlm and munge; exits 77
# saying why otherwise. TCBENCH names the binary (default build/tcbench),
# CPUS the node's CPUs (default 2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tcbench=$(realpath "${TCBENCH:-$root/build/tcbench}")
cpus=${CPUS:-2}
config=$(realpath "${1:?usage: bench/slurm_vs_local.sh CONFIG [tcbench run options]}")
shift
source "$root/scripts/slurm/local-cluster.sh"
if why=$(slurm_local_missing); then echo "slurm_vs_local: $why" >&2; exit 77; fi
py=/usr/bin/python3

tmp=$(mktemp -d)
chmod 755 "$tmp"
trap 'slurm_local_stop "$tmp"; rm -rf "$tmp"' EXIT
why=$(slurm_local_start "$tmp" "$cpus") || { echo "slurm_vs_local: $why" >&2; exit 77; }
export SLURM_CONF="$tmp/slurm.conf"
now() { date +%s.%N; }

ncells=$("$tcbench" cells "$config" "$@" --out "$tmp/local" | grep -cE '^ *[0-9]+ ')
echo "config: $config ($ncells cells), $cpus CPUs, $(nproc) online"

t0=$(now)
"$tcbench" run "$config" "$@" --out "$tmp/local" --threads "$cpus" --quiet > "$tmp/local.log" 2>&1 ||
    { cat "$tmp/local.log"; exit 1; }
t_local=$($py -c "print(f'{$(now) - $t0:.1f}')")
echo "local: tcbench run --threads $cpus: $t_local s"

# Watches the Slurm run directory: when each cell's lock and file appear.
$py - "$tmp/slurm/cells" > "$tmp/events" <<'PY' &
import os, sys, time
seen = set()
while True:
    for d, _, files in os.walk(sys.argv[1]):
        for f in files:
            p = os.path.join(d, f)
            if (f.endswith(".json.lock") or f.endswith(".json")) and p not in seen:
                seen.add(p)
                print(f"{time.time():.3f} {p}", flush=True)
    time.sleep(0.02)
PY
watcher=$!
t0=$(now)
TCBENCH="$tcbench" "$root/scripts/slurm/submit.sh" "$config" --out "$tmp/slurm" "$@" \
    --sbatch "--wait -c 1 -o $tmp/task-%a.log" > "$tmp/submit.txt" 2>&1 ||
    { cat "$tmp/submit.txt" "$tmp"/task-*.log; exit 1; }
t_slurm=$($py -c "print(f'{$(now) - $t0:.1f}')")
sleep 0.1
kill "$watcher"
echo "slurm: $ncells one-CPU array tasks, $cpus at a time: sbatch --wait returned after $t_slurm s"

# The last cell written, from the submission: the grid's wall time (sbatch
# --wait polls the controller and returns some seconds later).
# Overhead per task: a CPU frees at the submission (CPUS of them) and at
# each cell's end; the k-th cell to start had the k-th free CPU.
$py - "$tmp/events" "$t0" "$cpus" "$t_local" <<'PY'
import json, sys
events, t0, cpus = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
lock, done = {}, {}
for line in open(events):
    t, p = line.split(maxsplit=1)
    p = p.strip()
    if p.endswith(".json.lock"): lock.setdefault(p[:-5], float(t))
    else: done.setdefault(p, float(t))
t_local = float(sys.argv[4])
last = max(done[p] for p in lock) - t0
print(f"slurm: last cell written {last:.1f} s after the submission; slurm / local: {last / t_local:.3f}")
# A cell done within the watcher's 20 ms had a lock it did not see: its
# start is its end less its own timings.
for p, t in done.items():
    if p not in lock: lock[p] = t - sum(json.load(open(p))["timings"].values())
starts = sorted((t, p) for p, t in lock.items())
free = sorted([t0] * cpus + [done[p] for p in lock if p in done])
print("per task: free CPU -> lock, + load = first iteration; cell")
over = []
for k, (t, p) in enumerate(starts):
    load = json.load(open(p))["timings"]["load_s"]
    o = t - free[k] + load
    over.append(o)
    print(f"  {t - free[k]:6.2f} s + {load:5.2f} s = {o:6.2f} s  {p.split('/cells/')[1]}")
print(f"overhead per task: mean {sum(over) / len(over):.2f} s, max {max(over):.2f} s")
PY

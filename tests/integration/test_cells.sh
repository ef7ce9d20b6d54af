#!/usr/bin/env bash
# Cells by number: `tcbench cells` lists a config's cells in an order that
# depends only on the config; `run --cell` and `run --shard I/N` (or
# `--shard auto` under a Slurm array) run exactly those, and shards put
# together equal a plain run bit for bit. `status` counts the cells of
# tasks squeue lists as queued; scripts/slurm/submit.sh finds tcbench.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

cat > g.json <<'JSON'
{ "name": "g", "output": "plain", "seeds": [0, 1], "evaluation": { "pairs": 15 },
  "datasets": [
    { "name": "a", "source": "synthetic", "frames": 6, "sequences": [ { "name": "quadruped_walk", "role": "test" } ] },
    { "name": "b", "source": "synthetic", "frames": 6,
      "sequences": [ { "name": "quadruped_walk", "role": "test" }, { "name": "humanoid_jacks", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest", "seeds": [3], "datasets": ["b"] } ] }
JSON
expect 0 "" "$TCBENCH" cells g.json
/usr/bin/python3 - <<'PY'
rows = [l.split() for l in open("out.txt").read().splitlines()[1:]]
want = [("a", "quadruped_walk", "oracle", "0"), ("a", "quadruped_walk", "oracle", "1"),
        ("b", "quadruped_walk", "oracle", "0"), ("b", "quadruped_walk", "oracle", "1"), ("b", "quadruped_walk", "nearest", "3"),
        ("b", "humanoid_jacks", "oracle", "0"), ("b", "humanoid_jacks", "oracle", "1"), ("b", "humanoid_jacks", "nearest", "3")]
assert [tuple(r[1:5]) for r in rows] == want, rows
assert [r[0] for r in rows] == [str(k) for k in range(8)] and {r[5] for r in rows} == {"missing"}, rows
PY
"$TCBENCH" run g.json --quiet 2> /dev/null

expect 0 "cells: 3 in all, 3 computed" "$TCBENCH" run g.json --out picked --cell 1,4-5 --quiet
ls picked/cells/a/quadruped_walk/oracle/seed_1.json picked/cells/b/quadruped_walk/nearest/seed_3.json \
   picked/cells/b/humanoid_jacks/oracle/seed_0.json > /dev/null
[ "$(find picked/cells -name '*.json' | wc -l)" -eq 3 ]
expect 0 "" "$TCBENCH" cells g.json --out picked
[ "$(grep -c ' done$' out.txt)" -eq 3 ] && grep -qE "^ +4 .* nearest +3  done$" out.txt || { cat out.txt; exit 1; }

# Three shards, one of them as a Slurm array task (ids 5..7 of an array 5-7).
expect 0 "cells: 3 in all" "$TCBENCH" run g.json --out sharded --shard 0/3 --quiet
SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_MIN=5 SLURM_ARRAY_TASK_MAX=7 \
    expect 0 "cells: 3 in all" "$TCBENCH" run g.json --out sharded --shard auto --quiet
SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_COUNT=3 \
    expect 0 "cells: 2 in all" "$TCBENCH" run g.json --out sharded --shard auto --quiet
same_cells plain sharded

# `status` asks squeue for the tasks scripts/slurm/submit.sh queued (their
# job comment names the run directory): their cells are queued, not
# missing, nor in the --array list; a task of N shards stands for every id
# that is its index modulo N. A fake squeue here, Slurm's in test_slurm.sh.
"$TCBENCH" run g.json --out queue --cell 0,3 --quiet 2> /dev/null
mkdir fake
cat > fake/squeue <<SH
#!/bin/sh
cat <<'Q'
57|1|PENDING|tcbench run=$tmp/queue
57|2|RUNNING|tcbench run=$tmp/queue
57|4|COMPLETED|tcbench run=$tmp/queue
58|0|PENDING|tcbench shards=3 run=$tmp/queue
59|5|PENDING|tcbench run=$tmp/queue-other
60|N/A|PENDING|tcbench run=$tmp/queue
61|7|PENDING|another job
Q
SH
chmod +x fake/squeue
# A run directory submit.sh never submitted is not asked about.
PATH="$tmp/fake:$PATH" expect 0 "" "$TCBENCH" status g.json --out queue
grep -q "queued" out.txt && { echo "FAIL: status asked squeue about a run never submitted"; cat out.txt; exit 1; }
echo "2026-12-03T00:00:00Z g.json" > queue/slurm-submissions.log
PATH="$tmp/fake:$PATH" expect 0 "" "$TCBENCH" status g.json --out queue
grep -qxF "queued   1-2,6: pending or running in Slurm (jobs 57 58)" out.txt &&
    grep -qxF "queue: 8 cells: 2 done, 0 diverged, 0 failed, 0 running, 0 stale, 3 missing, 3 queued in Slurm" out.txt &&
    grep -qxF "resubmit the cells a run computes (3 missing, 0 failed, 0 stale): --array=4-5,7" out.txt || { cat out.txt; exit 1; }
# squeue failing: a warning, and the counts as without it; no squeue: nothing.
printf '#!/bin/sh\necho "squeue: error: Unable to contact slurm controller" >&2\nexit 1\n' > fake/squeue
PATH="$tmp/fake:$PATH" expect 0 "warning: squeue failed (squeue: error: Unable to contact slurm controller), so cells queued in Slurm count as missing" \
    "$TCBENCH" status g.json --out queue
grep -qxF "queue: 8 cells: 2 done, 0 diverged, 0 failed, 0 running, 0 stale, 6 missing" out.txt || { cat out.txt; exit 1; }
PATH=/nonexistent "$TCBENCH" status g.json --out queue > out.txt 2> err.txt
[ ! -s err.txt ] && grep -qxF "resubmit the cells a run computes (6 missing, 0 failed, 0 stale): --array=1-2,4-7" out.txt ||
    { cat out.txt err.txt; exit 1; }

# submit.sh finds tcbench ($TCBENCH, else the checkout's build/tcbench, else
# PATH's) and says which; here every cell is done, so it submits nothing.
mkdir -p tree/scripts/slurm tree/build bin
cp "$TCB_SOURCE_DIR"/scripts/slurm/submit.sh "$TCB_SOURCE_DIR"/scripts/slurm/tcbench-array.sbatch tree/scripts/slurm/
ln -s "$TCBENCH" bin/tcbench
expect 0 "submit.sh: using $(realpath "$TCBENCH") (tcbench on PATH)" env -u TCBENCH PATH="$tmp/bin:/usr/bin:/bin" tree/scripts/slurm/submit.sh g.json
grep -qF "submit.sh: nothing to submit: every cell of g.json is done, running or queued" err.txt || { cat err.txt; exit 1; }
ln -s "$TCBENCH" tree/build/tcbench
expect 0 "(this checkout's build)" env -u TCBENCH PATH="$tmp/bin:/usr/bin:/bin" tree/scripts/slurm/submit.sh g.json
rm tree/build/tcbench
expect 2 "submit.sh: no tcbench: neither $tmp/tree/build/tcbench (cmake --build build) nor tcbench on PATH; or set TCBENCH=/path/to/tcbench" \
    env -u TCBENCH PATH=/usr/bin:/bin tree/scripts/slurm/submit.sh g.json

expect 2 "--cell 8: cell 8 does not exist (the config has 8 cells, 0-7)" "$TCBENCH" run g.json --cell 8
expect 2 "--cell 3-x: expected ids and ranges such as 3,5-7" "$TCBENCH" run g.json --cell 3-x
expect 2 "--cell 5-2: range 5-2 runs backwards" "$TCBENCH" run g.json --cell 5-2
expect 2 "--shard 3/3: expected I/N with 0 <= I < N, or auto" "$TCBENCH" run g.json --shard 3/3
expect 2 "--shard auto: SLURM_ARRAY_TASK_ID is not set" env -u SLURM_ARRAY_TASK_ID "$TCBENCH" run g.json --shard auto
echo "cells test passed"

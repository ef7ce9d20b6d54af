#!/usr/bin/env bash
# Failures are failures (issue 26): a cell that could not be computed (an
# external method that crashes, added to an existing run directory with no
# flag) is "failed", a diverged training is a result ("diverged"). `tcbench run` exits 1 when a cell of this run failed
# and lists the failed cells with their messages (the command's last log
# line among them) at the end; `status` lists them and counts them apart
# from diverged ones; a rerun, once the method is fixed, computes only the
# failed cell again (no --force) and exits 0; the report shows the failed
# cell as failed, pooled with nothing. Skipped without numpy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

py=/usr/bin/python3
"$py" -c "import numpy" 2>/dev/null || { echo "skipped: /usr/bin/python3 cannot import numpy"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fake=$TCB_SOURCE_DIR/tests/integration/external_fake.py

# method.sh MODE: the researcher's method, edited in place to fix it (its
# params, the command, stay the same).
method() { printf '#!/bin/sh\nexec %s %s %s "$@"\n' "$py" "$fake" "$1" > method.sh; chmod +x method.sh; }
cat > grid.json <<JSON
{ "name": "grid", "output": "run", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1], "threads": 1,
  "evaluation": { "pairs": 6, "pool_size": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 8,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mine", "method": "external", "params": { "command": ["$tmp/method.sh"] } },
               { "name": "unstable", "method": "external",
                 "params": { "command": ["$py", "$fake", "diverge"] }, "seeds": [0] } ] }
JSON

# The grid without the researcher's method first: a diverged cell is a
# result, the run exits 0.
/usr/bin/python3 - <<'PY'
import json
c = json.load(open("grid.json"))
c["methods"] = [m for m in c["methods"] if m["name"] != "mine"]
json.dump(c, open("base.json", "w"))
PY
expect 0 "cells: 3 in all, 3 computed, 0 already done, 0 failed, 1 diverged" "$TCBENCH" run base.json --quiet
# The method added to the same directory, no --force: it crashes.
method fail
expect 1 "cells: 5 in all, 2 computed, 3 already done, 2 failed" "$TCBENCH" run grid.json --quiet
# The list at the end: each failed cell with its message, the log's last line in it.
grep -qxF "failed cells (no result; a rerun retries them):" err.txt || { cat err.txt; exit 1; }
for s in 0 1; do
    grep -qE "^synth/quadruped_walk/mine/seed $s: fit: .*exited with status 2.*line 15$" err.txt ||
        { echo "FAIL: seed $s is not listed with its last log line"; cat err.txt; exit 1; }
done
! sed -n '/^failed cells/,$p' err.txt | grep -q unstable || { echo "FAIL: a diverged cell listed as failed"; cat err.txt; exit 1; }

"$py" - <<'PY'
import json
c = lambda m, s: json.load(open("run/cells/synth/quadruped_walk/%s/seed_%d.json" % (m, s)))
assert c("mine", 0)["status"] == "failed" and "line 15" in c("mine", 0)["message"], c("mine", 0)["message"]
assert c("unstable", 0)["status"] == "diverged", c("unstable", 0)["status"]
assert c("nearest", 1)["status"] == "ok"
PY

expect 0 "2 failed" "$TCBENCH" status run
grep -qF "run: 5 cells: 2 done, 1 diverged, 2 failed, 0 running, 0 stale, 0 missing" out.txt || { cat out.txt; exit 1; }
grep -qE "^failed +2  synth/quadruped_walk/mine seed 0: fit: .*line 15$" out.txt || { cat out.txt; exit 1; }
grep -qE "^diverged +4  synth/quadruped_walk/unstable seed 0: " out.txt || { cat out.txt; exit 1; }
grep -qF "resubmit the cells a run computes (0 missing, 2 failed, 0 stale): --array=2-3" out.txt || { cat out.txt; exit 1; }
expect 0 "" "$TCBENCH" run grid.json --dry-run
grep -qF "cells: 5, 3 finished, 2 to run" out.txt || { cat out.txt; exit 1; }

# The report: the failed row says so and pools no numbers.
"$TCBENCH" report run --quiet 2> /dev/null
grep -E "^\| *mine " run/report/tables.md | grep -q "failed" || { cat run/report/tables.md; exit 1; }

# Still broken: the rerun retries, fails again, exits 1.
expect 1 "cells: 5 in all, 2 computed, 3 already done, 2 failed" "$TCBENCH" run grid.json --quiet

# Fixed: only the failed cells are computed again, without --force.
touch -d '1 hour ago' run/cells/synth/quadruped_walk/{nearest,unstable}/seed_*.json
method oracle
expect 0 "cells: 5 in all, 2 computed, 3 already done, 0 failed" "$TCBENCH" run grid.json --quiet
[ "$(find run/cells -name '*.json' -mmin -30 | sort | tr '\n' ' ')" = \
  "run/cells/synth/quadruped_walk/mine/seed_0.json run/cells/synth/quadruped_walk/mine/seed_1.json " ] ||
    { echo "FAIL: the rerun rewrote other cells"; find run/cells -name '*.json' -mmin -30; exit 1; }
expect 0 "0 failed" "$TCBENCH" status run
echo "failed cells test passed"

#!/usr/bin/env bash
# The researcher's loop, end to end, as issue 26 played it: a fresh venv and
# `pip install .`; in the researcher's own directory (not the checkout, whose
# copy is deleted) and a fresh shell, numpy predictions scored on a test
# sequence with tcbench.Evaluator equal the `nearest` cell bit for bit when
# they are nearest's; an external Python method (the venv's interpreter
# through TCBENCH_PYTHON) added to the config joins the existing run
# directory without --force; it crashes: the run exits 1 naming the cell,
# the interpreter and the traceback's last line; fixed, a rerun computes
# that cell alone, bit-identical to nearest (it is nearest); `tcbench check`
# against a baseline written before the method existed passes and lists
# the new row as not in the baseline.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/venv.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
venv_install "$tmp" || { echo "FAIL: pip install"; cat "$tmp/pip.log"; exit 1; }
rm -rf "$tmp/src"
work=$tmp/project
mkdir "$work"
cd "$work"

grid() { # the config with the methods given as JSON objects
    cat > grid.json <<JSON
{ "name": "grid", "output": "runs/grid", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 12, "pool_size": 500, "input_points": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 10, "normalization": "first_frame",
                  "sequences": [ { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" }$1 ] }
JSON
}
grid ""
"$TCBENCH" run grid.json --quiet 2> run0.log || { cat run0.log; exit 1; }
"$TCBENCH" check runs/grid baseline.json --update > /dev/null
cells=runs/grid/cells/synth/quadruped_trot

# ---- Python from the venv: the whole split scored from numpy
in_venv "$tmp" "$work" python3 - "$TCB_SOURCE_DIR/tests/integration" "$tmp/venv" <<'PY'
import os, sys
import numpy as np
import tcbench
assert os.path.realpath(tcbench.library_path()).startswith(os.path.realpath(sys.argv[2]) + "/")
sys.path.insert(0, sys.argv[1])
from pychecks import same

ev = tcbench.Evaluator("grid.json", "synth", "quadruped_trot")
verts = ev.sequence["verts"]
def nearest(i, j):  # float32 distances, as the C search measures them
    a, b = verts[i], verts[j]
    return ((a[:, None, :] - b[None]) ** 2).sum(-1).argmin(1)
r = ev.evaluate({k: nearest(i, j) for k, (i, j) in enumerate(ev.pairs)})
ref = tcbench.read_cell("runs/grid/cells/synth/quadruped_trot/nearest/seed_0.json")
same(r["summary"], ref["summary"], "summary")
same(r["pairs"], ref["pairs"], "pairs")
assert r["summary"]["geo"]["mean"] > 0 and r["summary"]["sl2"]["mean"] > 0
print("evaluator equals nearest's cell: m_sL2 %.6g, m_geo %.6g" % (r["summary"]["sl2"]["mean"], r["summary"]["geo"]["mean"]))
PY

# ---- an external method joins the run directory, and crashes
sed -e 's/    return frames\[i\]$/    return frames[i, :, [0, 1, 3]].T  # a bug/' \
    "$TCB_SOURCE_DIR/examples/python/skeleton.py" > mine.py
grep -qF "# a bug" mine.py || { echo "FAIL: the bug was not planted"; exit 1; }
grid ', { "name": "mine", "method": "external", "params": { "command": ["mine.py"] } }'
mtime() { stat -c %Y.%y "$cells/$1/seed_0.json"; }
before="$(mtime oracle) $(mtime nearest)"
status=0
TCBENCH_PYTHON="$tmp/venv/bin/python" "$TCBENCH" run grid.json --quiet 2> crash.log || status=$?
[ "$status" -eq 1 ] || { echo "FAIL: a crashed cell, exit $status"; cat crash.log; exit 1; }
grep -qF "cells: 3 in all, 1 computed, 2 already done, 1 failed" crash.log || { cat crash.log; exit 1; }
line=$(grep -F "synth/quadruped_trot/mine/seed 0: " crash.log | tail -1)
for want in "IndexError: index 3 is out of bounds" "program $tmp/venv/bin/python [TCBENCH_PYTHON]"; do
    grep -qF "$want" <<< "$line" || { echo "FAIL: the failure does not say '$want'"; cat crash.log; exit 1; }
done
[ "$before" = "$(mtime oracle) $(mtime nearest)" ] || { echo "FAIL: finished cells were recomputed"; exit 1; }
"$TCBENCH" status runs/grid > status.txt 2>&1 || { echo "FAIL: status"; cat status.txt; exit 1; }
grep -qF "1 failed" status.txt || { cat status.txt; exit 1; }

# ---- fixed, rerun: that cell alone
sed -i 's/    return frames\[i, .*# a bug$/    return frames[i]/' mine.py
! grep -qF "# a bug" mine.py || { echo "FAIL: the bug was not fixed"; exit 1; }
TCBENCH_PYTHON="$tmp/venv/bin/python" "$TCBENCH" run grid.json --quiet 2> fixed.log || { cat fixed.log; exit 1; }
grep -qF "cells: 3 in all, 1 computed, 2 already done, 0 failed" fixed.log || { cat fixed.log; exit 1; }
[ "$before" = "$(mtime oracle) $(mtime nearest)" ] || { echo "FAIL: finished cells were recomputed"; exit 1; }
/usr/bin/python3 - "$cells" <<'PY'
import json, sys
a, b = (json.load(open("%s/%s/seed_0.json" % (sys.argv[1], m))) for m in ("mine", "nearest"))
assert a["status"] == "ok" and a["summary"] == b["summary"] and a["pairs"] == b["pairs"], "mine differs from nearest"
PY

# ---- the baseline from before the method: still passes, the new row listed
"$TCBENCH" check runs/grid baseline.json > check.txt || { echo "FAIL: check"; cat check.txt; exit 1; }
grep -qE "mine.*not in the baseline" check.txt || { cat check.txt; exit 1; }
echo "researcher's loop test passed"

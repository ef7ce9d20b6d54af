#!/usr/bin/env bash
# Paths to code in a config resolve against the config file's directory
# (issue 26): a plug-in and an external method's script named beside the
# config are found when tcbench runs from another directory, and
# `inspect` of the run from a third directory finds them through the run
# directory's record; "output" stays relative to the current directory.
# Skipped without numpy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"
source "$TCB_SOURCE_DIR/tests/integration/harness_methods.sh"

/usr/bin/python3 -c "import numpy" 2>/dev/null || { echo "skipped: /usr/bin/python3 cannot import numpy"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/project/configs" "$tmp/elsewhere"
cd "$tmp/project"
build_harness_methods configs/libharness_methods.so
cp "$TCB_SOURCE_DIR/examples/python/skeleton.py" configs/
cat > configs/grid.json <<'JSON'
{ "name": "grid", "output": "runs/grid", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "plugins": ["libharness_methods.so"],
  "evaluation": { "pairs": 3, "pool_size": 300 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" }, { "name": "probe", "method": "thread_probe" },
               { "name": "mine", "method": "external", "params": { "command": ["/usr/bin/python3", "skeleton.py", "fit"] } } ] }
JSON
# From the project's root: the code beside the config is found, the output
# lands under the current directory.
expect 0 "cells: 3 in all, 3 computed" "$TCBENCH" run configs/grid.json --quiet
[ -d runs/grid/cells ] && [ ! -e configs/runs ] || { echo "FAIL: output not relative to the current directory"; exit 1; }
grep -qF "\"$tmp/project/configs/skeleton.py\", \"fit\"" runs/grid/config.json &&
    grep -qF "\"$tmp/project/configs/libharness_methods.so\"" runs/grid/config.json ||
    { echo "FAIL: the record does not name the code that ran"; cat runs/grid/config.json; exit 1; }
/usr/bin/python3 - <<'PY'
import json
c = lambda m: json.load(open("runs/grid/cells/synth/quadruped_walk/%s/seed_0.json" % m))
assert c("mine")["status"] == "ok" and c("mine")["summary"] == c("nearest")["summary"], c("mine")["message"]
PY
# From elsewhere: the same config is the same run; inspect reads the record.
cd "$tmp/elsewhere"
expect 0 "0 computed, 3 already done" "$TCBENCH" run ../project/configs/grid.json --out ../project/runs/grid --quiet
expect 0 "(agree: " "$TCBENCH" inspect ../project/runs/grid mine 1 --out insp --quiet
echo "config paths test passed"

#!/usr/bin/env bash
# An atlas training that blows up (lr 10) ends its cell with status
# "diverged", the iteration and the losses in the message, and the report
# shows it in the table instead of numbers; a diverged training is the
# method's result, not a failed cell: the run exits 0.
set -euo pipefail
: "${TCBENCH:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
cat > diverge.json <<'JSON'
{ "name": "diverge", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "mca", "params": { "preset": "tiny", "lr": 10 } } ] }
JSON
"$TCBENCH" run diverge.json --out run --quiet --report 2> run.log
grep -qF "1 in all, 1 computed, 0 already done, 0 failed, 1 diverged" run.log || { cat run.log; exit 1; }
/usr/bin/python3 - run/cells/synth/quadruped_walk/mca/seed_0.json <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
assert c["status"] == "diverged", c["status"]
assert "iteration" in c["message"] and "diverged, loss" in c["message"], c["message"]
print("cell:", c["message"])
PY
grep -qF "| mca | *diverged* |" run/report/tables.md || { cat run/report/tables.md; exit 1; }
grep -q "^synth,quadruped_walk,validation,mca,diverged," run/report/results.csv
echo "divergence test passed"

#!/usr/bin/env bash
# The tcbench CLI end to end: every command's --help, usage errors (exit 2,
# naming the offending word), datasets, methods, run, report and check.
set -euo pipefail
: "${TCBENCH:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# ---- help and usage errors
for cmd in run report methods datasets check score version help; do
    expect 0 "usage: tcbench $cmd" "$TCBENCH" "$cmd" --help
    grep -q "^example" out.txt || { echo "FAIL: $cmd --help has no example"; exit 1; }
    expect 0 "usage: tcbench $cmd" "$TCBENCH" help "$cmd"
done
expect 0 "commands:" "$TCBENCH" --help
expect 0 "commands:" "$TCBENCH" help
expect 2 "usage: tcbench" "$TCBENCH"
expect 2 "tcbench: unknown command 'frobnicate'" "$TCBENCH" frobnicate
expect 2 "tcbench: unknown command 'frobnicate'" "$TCBENCH" help frobnicate
expect 2 "tcbench: run: unknown option '--bogus'" "$TCBENCH" run x.json --bogus
expect 2 "tcbench: unknown option '--bogus'" "$TCBENCH" --bogus methods
expect 2 "tcbench: report: unknown option '--force'" "$TCBENCH" report somewhere --force
expect 2 "tcbench: run: missing CONFIG" "$TCBENCH" run
expect 2 "tcbench: check: missing RUN_DIR BASELINE" "$TCBENCH" check onlyone
expect 2 "tcbench: run: option '--out' needs a value" "$TCBENCH" run x.json --out
expect 2 "tcbench: run: option '--force' takes no value" "$TCBENCH" run x.json --force=1
expect 2 "tcbench: version: unexpected argument 'extra'" "$TCBENCH" version extra
expect 2 "no-such.json" "$TCBENCH" run no-such.json
[ "$(wc -l < err.txt)" -eq 1 ] || { echo "FAIL: error is not one line"; cat err.txt; exit 1; }
expect 0 "tcbench " "$TCBENCH" version

# ---- datasets and methods
expect 0 "quadruped_walk" "$TCBENCH" datasets list
expect 2 "datasets: unknown action 'frob'" "$TCBENCH" datasets frob
expect 2 "--out applies to 'datasets synth' only" "$TCBENCH" datasets list --out x
expect 2 "datasets synth: --out DIR is required" "$TCBENCH" datasets synth
expect 2 "--frames: expected a non-negative integer, got 'x'" \
    "$TCBENCH" datasets synth --out synth --frames x
expect 2 "no synthetic sequence named 'nope'" "$TCBENCH" datasets synth --out synth --sequence nope
expect 0 "synth/quadruped_walk" "$TCBENCH" datasets synth --out synth --sequence quadruped_walk --frames 3
[ "$(ls synth)" = "quadruped_walk" ] || { echo "FAIL: --sequence wrote $(ls synth)"; exit 1; }
[ "$(ls synth/quadruped_walk | grep -c '^mesh_[0-9]*\.obj$')" -eq 3 ] ||
    { echo "FAIL: expected 3 OBJ frames"; ls synth/quadruped_walk; exit 1; }
expect 0 "oracle" "$TCBENCH" methods
grep -q "^nearest *built-in" out.txt || { echo "FAIL: methods table"; cat out.txt; exit 1; }

# ---- run
cat > tiny.json <<'JSON'
{ "name": "tiny", "output": "runs/tiny", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 20, "pool_size": 2000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
expect 0 "tcbench report runs/tiny" "$TCBENCH" run tiny.json --quiet
grep -qF "cells: 2 in all, 2 computed, 0 already done, 0 failed" err.txt || { cat err.txt; exit 1; }
for m in oracle nearest; do
    [ -f "runs/tiny/cells/synth/quadruped_walk/$m/seed_0.json" ] || { echo "FAIL: no $m cell"; exit 1; }
done
[ -f splits/synth/quadruped_walk.json ] || { echo "FAIL: no split file"; exit 1; }
/usr/bin/python3 - <<'PY'
import json
cfg = json.load(open("runs/tiny/config.json"))
assert cfg["evaluation"]["pairs"] == 20 and cfg["evaluation"]["input_points"] == 2500, cfg
assert cfg["threads"] == 2 and cfg["seeds"] == [0], cfg
for m in ("oracle", "nearest"):
    c = json.load(open("runs/tiny/cells/synth/quadruped_walk/%s/seed_0.json" % m))
    assert c["status"] == "ok" and c["summary"]["n_pairs"] == 20 and len(c["pairs"]) == 20, c["status"]
    assert c["split"]["path"] == "splits/synth/quadruped_walk.json", c["split"]
oracle = json.load(open("runs/tiny/cells/synth/quadruped_walk/oracle/seed_0.json"))
assert oracle["summary"]["sl2"]["mean"] == 0 and oracle["summary"]["auc"]["mean"] == 1
PY
expect 0 "0 computed, 2 already done" "$TCBENCH" run tiny.json --quiet
expect 0 "cells: 1 in all, 1 computed" "$TCBENCH" run tiny.json --quiet --only nearest --force
expect 2 "--only: tiny.json has no method labelled 'nope'" "$TCBENCH" run tiny.json --only nope
sed 's/"name": "nearest"/"name": "nope"/' tiny.json > unknown.json
expect 2 "unknown.json: methods[1]: no method named 'nope'" "$TCBENCH" run unknown.json
sed 's/{ "name": "nearest" }/{ "name": "nearest", "params": { "bogus": 1 } }/' tiny.json > params.json
expect 2 "params.json: methods[1].params: " "$TCBENCH" run params.json
grep -qF "bogus" err.txt || { echo "FAIL: bad params not named"; cat err.txt; exit 1; }
sed 's/"pairs": 20/"pairs": 30/' tiny.json > more.json
expect 2 "splits/synth/quadruped_walk.json" "$TCBENCH" run more.json --out runs/more

# ---- report
expect 0 "| oracle" "$TCBENCH" report runs/tiny
grep -qF "runs/tiny/report/" err.txt || { echo "FAIL: report location"; cat err.txt; exit 1; }
[ -s runs/tiny/report/tables.md ] || { echo "FAIL: no tables.md"; exit 1; }
expect 0 "rep/" "$TCBENCH" report runs/tiny --out rep --quiet
[ ! -s out.txt ] || { echo "FAIL: --quiet printed the tables"; exit 1; }
[ -s rep/tables.md ] && [ -s rep/results.csv ] || { echo "FAIL: report --out"; ls rep; exit 1; }
expect 2 "" "$TCBENCH" report no-such-run
expect 0 "report: runs/tiny/report/" "$TCBENCH" run tiny.json --quiet --report

# ---- check
expect 0 "baseline written" "$TCBENCH" check runs/tiny base.json --update
expect 0 "" "$TCBENCH" check runs/tiny base.json
/usr/bin/python3 - <<'PY'
import json
b = json.load(open("base.json"))
row = next(r for r in b["rows"] if r["method"] == "nearest")
row["sl2"] = row["sl2"] * 2 + 1
json.dump(b, open("drift.json", "w"), indent=1)
PY
expect 1 "drifted" "$TCBENCH" check runs/tiny drift.json
expect 2 "missing.json" "$TCBENCH" check runs/tiny missing.json
echo "cli test passed"

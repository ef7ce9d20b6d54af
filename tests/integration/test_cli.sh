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

# ---- integer flags and single-value flags: refused when the line is parsed,
# before any file is read (x.json need not exist), one line naming the flag
one_line() { [ "$(wc -l < err.txt)" -eq 1 ] || { echo "FAIL: not one line"; cat err.txt; exit 1; }; }
for bad in 0 -1 x 1025 2.5 ''; do
    expect 2 "run: --threads: expected an integer from 1 to 1024, got '$bad'" "$TCBENCH" run x.json --threads "$bad"
    one_line
done
expect 2 "score: --threads: expected an integer from 1 to 1024, got '0'" "$TCBENCH" score x.json --threads 0
expect 2 "inspect: --threads: expected an integer from 1 to 1024, got '0'" "$TCBENCH" inspect r m 0 --threads 0
expect 2 "frames: --threads: expected an integer from 1 to 1024, got '-2'" "$TCBENCH" frames r m --threads=-2
expect 2 "frames: --count: expected an integer from 1 to 16, got '0'" "$TCBENCH" frames r m --count 0
expect 2 "frames: --count: expected an integer from 1 to 16, got '17'" "$TCBENCH" frames r m --count 17
expect 2 "frames: --seed: expected an integer from 0 to 2147483647, got '-1'" "$TCBENCH" frames r m --seed -1
expect 2 "inspect: --seed: expected an integer from 0 to 2147483647, got '3000000000'" \
    "$TCBENCH" inspect r m 0 --seed 3000000000
expect 2 "score: --seed: expected an integer from 0 to 2147483647, got 'one'" "$TCBENCH" score x.json --seed one
expect 2 "run: --lock-timeout: expected an integer from 1 to 1000000000, got '0'" \
    "$TCBENCH" run x.json --lock-timeout 0
expect 2 "datasets: --samples: expected an integer from 1 to 10000000, got '0'" \
    "$TCBENCH" datasets align d --out f.json --samples 0
expect 2 "datasets: --seed: expected an integer from 0 to 9223372036854775807, got '-5'" \
    "$TCBENCH" datasets synth --out synth --seed -5
expect 2 "datasets: --frames: expected an integer from 1 to 100000, got '0'" "$TCBENCH" datasets synth --out s --frames 0
expect 2 "score: option '--pred' given twice ('a', then 'b')" "$TCBENCH" score x.json --pred a --pred b
one_line
expect 2 "run: option '--out' given twice ('a', then 'b')" "$TCBENCH" run x.json --out a --out=b
expect 2 "frames: option '--style' given twice" "$TCBENCH" frames r m --style texture --style transfer
expect 2 "run: --root: dataset 'ama' given twice" "$TCBENCH" run x.json --root ama=a --root ama=b
[ ! -e s ] && [ ! -e a ] || { echo "FAIL: a refused command wrote something"; ls; exit 1; }

# ---- datasets and methods
expect 0 "quadruped_walk" "$TCBENCH" datasets list
expect 2 "datasets: unknown action 'frob'" "$TCBENCH" datasets frob
expect 2 "--out applies to 'datasets synth' only" "$TCBENCH" datasets list --out x
expect 2 "datasets synth: --out DIR is required" "$TCBENCH" datasets synth
expect 2 "datasets: --frames: expected an integer from 1 to 100000, got 'x'" \
    "$TCBENCH" datasets synth --out synth --frames x
expect 2 "no synthetic sequence named 'nope'" "$TCBENCH" datasets synth --out synth --sequence nope
expect 0 "synth/quadruped_walk" "$TCBENCH" datasets synth --out synth --sequence quadruped_walk --frames 3
[ "$(ls synth)" = "quadruped_walk" ] || { echo "FAIL: --sequence wrote $(ls synth)"; exit 1; }
[ "$(ls synth/quadruped_walk | grep -c '^mesh_[0-9]*\.obj$')" -eq 3 ] ||
    { echo "FAIL: expected 3 OBJ frames"; ls synth/quadruped_walk; exit 1; }
expect 0 "quadruped_collapse: 6 frames" "$TCBENCH" datasets distortion quadruped_collapse --frames 6
# The collapse's last frame is far from isometric; the walk's is not.
awk '$1 == 5 { exit !($4 + 0 > 5) }' out.txt || { echo "FAIL: collapse distortion"; cat out.txt; exit 1; }
expect 0 "quadruped_walk" "$TCBENCH" datasets distortion synth/quadruped_walk
awk '$1 == 2 { exit !($4 + 0 < 5) }' out.txt || { echo "FAIL: walk distortion"; cat out.txt; exit 1; }
expect 2 "nope: neither a synthetic sequence" "$TCBENCH" datasets distortion nope
expect 2 "datasets distortion: --out does not apply" "$TCBENCH" datasets distortion quadruped_walk --out x
expect 2 "datasets distortion: missing NAME|DIR" "$TCBENCH" datasets distortion
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

# ---- report: the tables on stdout and nothing else; the status line on
# stderr, after the tables when both go to one file
expect 0 "| oracle" "$TCBENCH" report runs/tiny
grep -qF "runs/tiny/report/" err.txt || { echo "FAIL: report location"; cat err.txt; exit 1; }
[ -s runs/tiny/report/tables.md ] || { echo "FAIL: no tables.md"; exit 1; }
cmp out.txt runs/tiny/report/tables.md || { echo "FAIL: report's stdout is not tables.md"; exit 1; }
"$TCBENCH" report runs/tiny > both.txt 2>&1
n=$(wc -l < runs/tiny/report/tables.md) # (a sanitizer's summary may follow)
head -n "$n" both.txt | cmp - runs/tiny/report/tables.md && [ "$(sed -n "$((n + 1))p" both.txt)" = "report: runs/tiny/report/" ] ||
    { echo "FAIL: report > file 2>&1 is not the tables, then the status line"; cat both.txt; exit 1; }
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

#!/usr/bin/env bash
# The dry run kept honest (issue 29): `tcbench calibrate` on this machine,
# then a small real config's dry run priced by that calibration (the run
# directory's, which wins over the others), then the run itself. Each
# trained cell's measured fit and evaluation seconds must be within a factor
# 2 of the estimate: asserted on the ratio, which a calibration and a run
# made one right after the other on one machine share the load of, not on
# seconds.
# A load that changes between the two can still move one; an attempt whose
# ratios miss is made again from a fresh calibration, and the test fails
# when three attempts in a row miss. Also: --tasks, the thread
# extrapolation's note, bad usage, the built-in calibration's coverage.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export XDG_CONFIG_HOME="$tmp/config" # no calibration of the user's is read

cat > small.json <<'JSON'
{ "name": "small", "output": "run", "seeds": [0], "threads": 1, "evaluation": { "pairs": 24, "surface_samples": 500 },
  "datasets": [ { "name": "s", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "atlasnet", "params": { "preset": "tiny", "iterations": 80 } },
               { "name": "cc", "params": { "preset": "tiny", "iterations": 80 } },
               { "name": "nricp", "params": { "strategy": "propagate_simple" } } ] }
JSON

attempt() {
    rm -rf run && mkdir run
    # each method calibrated right before its cell runs, into one file: the
    # later calls keep the earlier's costs (same machine); the reconstruction
    # metrics at the config's 500 samples; nricp has units, no presets
    for m in atlasnet cc nricp; do
        preset=(--preset tiny)
        [ $m = nricp ] && preset=()
        expect 0 "wrote run/calibration.json" "$TCBENCH" calibrate --only $m "${preset[@]}" --threads 1 --budget 4 \
            --samples 500 --out run/calibration.json
        expect 0 "costs from (first match wins): run/calibration.json" "$TCBENCH" run small.json --dry-run --only $m
        cp out.txt dry_$m.txt
        "$TCBENCH" run small.json --only $m --quiet 2> /dev/null
    done
    /usr/bin/python3 - <<'PY'
import json, re
units = {"s": 1, "min": 60, "h": 3600}
def seconds(text):
    v, u = text.split()
    return float(v) * units[u]
row = re.compile(r"^\s+\d+\s+(\S+)\s+0\s+missing\s+([\d.]+ (?:s|min|h))\s+([\d.]+ (?:s|min|h))\s+(.*)$")
est = {}
for name in ("atlasnet", "cc", "nricp"):
    for line in open(f"dry_{name}.txt"):
        m = row.match(line)
        if m:
            est[m.group(1)] = (seconds(m.group(2)), seconds(m.group(3)), m.group(4))
assert set(est) == {"atlasnet", "cc", "nricp"}, est
# the maps of 10 frames: 18 registrations of consecutive frames
assert est["nricp"][2].startswith("propagate_simple: 18 register_neighbor x"), est["nricp"]
assert "reconstruction metrics not measured" not in est["atlasnet"][2], est["atlasnet"]
ok = True
for method, (fit, ev, basis) in est.items():
    assert ("80 steps x" in basis or method == "nricp") and "1 thread" in basis, basis
    cell = json.load(open(f"run/cells/s/quadruped_walk/{method}/seed_0.json"))
    # nricp's evaluation composes the maps: the scoring only, too short to time
    parts = (("fit", fit, cell["timings"]["fit_s"]),) + ((("eval", ev, cell["timings"]["eval_s"]),)
                                                           if method != "nricp" else ())
    for part, e, m in parts:
        r = e / m
        print(f"{method} {part}: estimated {e:.2f} s, measured {m:.2f} s, ratio {r:.2f}")
        ok &= 0.5 <= r <= 2
open("verdict", "w").write("ok" if ok else "miss")
PY
}

for k in 1 2 3; do
    attempt
    [ "$(cat verdict)" = ok ] && break
    echo "attempt $k: a ratio outside [0.5, 2]; the load may have changed; again from a fresh calibration"
done
[ "$(cat verdict)" = ok ] || { echo "FAIL: three attempts outside a factor 2"; exit 1; }

# The run directory's file kept both methods' costs, with the machine.
/usr/bin/python3 - <<'PY'
import json
c = json.load(open("run/calibration.json"))
kinds = {(e["kind"], e["method"], e["preset"], e["threads"]) for e in c["costs"]}
assert {("step", "atlasnet", "tiny", 1), ("step", "cc", "tiny", 1), ("eval_pair", "cc", "tiny", 1),
        ("surface_frame", "atlasnet", "tiny", 1), ("surface_mesh", "atlasnet", "tiny", 1), ("unit", "nricp", "", 1),
        ("score_pair", "", "", 1)} <= kinds, kinds
units = {e["unit"] for e in c["costs"] if e["kind"] == "unit"}
assert units == {"register_random", "register_neighbor", "assign"}, units
assert all(e["size"] == 500 for e in c["costs"] if e["kind"] == "surface_frame"), c["costs"]
assert c["machine"]["cores"] >= 1 and c["machine"]["cpu"] and c["machine"]["openblas"], c["machine"]
PY

# 4 threads from a calibration of 1 thread only: said to be extrapolated;
# --tasks: two concurrent tasks of three cells a, b, c in id order: c
# starts when the shorter of a and b ends.
expect 0 "4 threads extrapolated: only 1 measured" "$TCBENCH" run small.json --dry-run --threads 4 --out run --force
expect 0 "as 2 concurrent one-cell tasks" "$TCBENCH" run small.json --dry-run --tasks 2 --force
/usr/bin/python3 - <<'PY'
import re
text = open("out.txt").read()
units = {"s": 1, "min": 60, "h": 3600}
sec = lambda v, u: float(v) * units[u]
# a printed duration is rounded: to the tenth below 10 s, else to its unit
slack = lambda v, u: 0.05 if float(v) < 10 and u == "s" else 0.5 * units[u]
cells = [sec(a, b) + sec(c, d) for a, b, c, d in
         re.findall(r"(?m)^\s+\d+\s+\S+\s+0\s+done\s+([\d.]+) (s|min|h)\s+([\d.]+) (s|min|h)", text)]
total = re.search(r"about ([\d.]+) (s|min|h) of wall time one after another", text)
wall = re.search(r"concurrent one-cell tasks.*?about ([\d.]+) (s|min|h)", text)
assert len(cells) == 3 and total and wall, text
a, b, c = cells
# the rows are rounded too: 3 s of slack for theirs
assert abs(sec(*total.groups()) - sum(cells)) <= slack(*total.groups()) + 3, text
assert abs(sec(*wall.groups()) - max(a, b, min(a, b) + c)) <= slack(*wall.groups()) + 3, text
PY

# A finished cell prices the same method's other seeds on the sequence:
# seed 1's fit is seed 0's measured fit, its evaluation seed 0's per pair
# times its pairs (the same 24 here), over what the calibration says; a
# cell measured by another revision of tcbench does not.
sed 's/"seeds": \[0\]/"seeds": [0, 1]/' small.json > seeds.json
expect 0 "measured: seed 0's cell" "$TCBENCH" run seeds.json --dry-run
/usr/bin/python3 - <<'PY'
import json, re
units = {"s": 1, "min": 60, "h": 3600}
sec = lambda v, u: float(v) * units[u]
text = open("out.txt").read()
rows = re.findall(r"(?m)^\s+\d+\s+(\S+)\s+1\s+missing\s+([\d.]+) (s|min|h)\s+([\d.]+) (s|min|h)\s+(.*)$", text)
assert len(rows) == 3, text
for method, fv, fu, ev, eu, basis in rows:
    t = json.load(open(f"run/cells/s/quadruped_walk/{method}/seed_0.json"))["timings"]
    assert basis.startswith("measured: seed 0's cell (fit ") and basis.endswith(" for 24 pairs)"), basis
    for v, u, m in ((fv, fu, t["fit_s"]), (ev, eu, t["eval_s"])):
        assert abs(sec(v, u) - m) <= (0.05 if m < 10 else 0.5), (method, v, u, m)
PY
/usr/bin/python3 - <<'PY'
import glob, json
for p in glob.glob("run/cells/s/quadruped_walk/*/seed_0.json"):
    c = json.load(open(p))
    c["git_revision"] = "0000000"
    json.dump(c, open(p, "w"))
PY
"$TCBENCH" run seeds.json --dry-run > other.txt
! grep -q "measured:" other.txt && grep -qE "^ +[0-9]+ +cc +1 +missing .* steps x" other.txt ||
    { echo "FAIL: cells of another revision priced the others"; cat other.txt; exit 1; }

# Bad usage and bad files: one line naming what, exit 2.
expect 2 "--tasks applies to --dry-run only" "$TCBENCH" run small.json --tasks 2
expect 2 "--only nearest: no method of that name has costs to measure" "$TCBENCH" calibrate --only nearest --out x.json
expect 2 "--preset huge: no preset of that name in cc" "$TCBENCH" calibrate --only cc --preset huge --out x.json
expect 2 "--threads: expected thread counts" "$TCBENCH" calibrate --threads 1,,2 --out x.json
echo '{"format": "tcbench-calibration 1", "machine": {"summary": "m"}, "sequence": {"vertices": 5},
       "costs": [{"kind": "step", "method": "cc", "preset": "tiny", "threads": 0, "seconds": 1, "samples": 1}]}' \
    > run/calibration.json
expect 2 "run/calibration.json: costs[0].threads" "$TCBENCH" run small.json --dry-run
[ ! -e x.json ]

# The built-in calibration prices every trained method's every preset at 1
# and 2 threads (the issue's evidence shows the paper table's trained cells
# priced; here every preset of the built-in trained methods, neupig's fast
# by paper's step, dynosurf's by its step and units), the atlas family's
# reconstruction metrics, and nricp's four strategies from its units.
rm run/calibration.json
/usr/bin/python3 - <<'PY'
import json
methods = [{"name": f"{m}_{p}", "method": m, "params": {"preset": p}}
           for m, presets in (("atlasnet", "paper cpu tiny"), ("dsr", "paper cpu tiny"), ("mca", "paper cpu tiny"),
                              ("cc", "paper cpu short tiny"), ("neupig", "paper fast cpu tiny"),
                              ("dynosurf", "paper cpu tiny"))
           for p in presets.split()]
methods += [{"name": f"nricp_{s}", "method": "nricp", "params": {"strategy": s}}
            for s in ("random", "propagate_simple", "propagate_bijective", "propagate_deform")]
for t in (1, 2):
    json.dump({"name": "b", "output": "brun", "seeds": [0], "threads": t,
               "datasets": [{"name": "s", "source": "synthetic", "frames": 6,
                             "sequences": [{"name": "quadruped_walk", "role": "test"}]}],
               "methods": methods}, open(f"b{t}.json", "w"))
PY
for t in 1 2; do
    expect 0 "cells: 24, 0 finished, 24 to run" "$TCBENCH" run b$t.json --dry-run
    [ "$(grep -cE "^ +[0-9]+ .* steps x [0-9.]+ ms( at its frames)? \($t threads?, " out.txt)" -eq 20 ] &&
        [ "$(grep -cE "^ +[0-9]+ +nricp_.* (register_[a-z]+|assign) x [0-9.e+-]+ s \(1 thread, " out.txt)" -eq 4 ] &&
        ! grep -qE " \? |not measured" out.txt ||
        { echo "FAIL: a cost the built-in calibration does not price at $t threads (calibration/default.json made"
          echo "before neupig's, nricp's and the reconstruction metrics' rows? docs/cluster.md, 'The built-in costs')"
          cat out.txt; exit 1; }
done
echo "ok"

# A config's sequences (`calibrate CONFIG`): the units of its methods and
# the scoring of a pair measured on each of its sequences, written as costs
# of that sequence, price that sequence's cells over the calibration
# sequence's, and no other sequence's.
cat > walk.json <<'JSON'
{ "name": "walk", "output": "seq", "seeds": [0], "threads": 1, "evaluation": { "pairs": 24 },
  "datasets": [ { "name": "s", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nricp", "params": { "strategy": "random" } }, { "name": "nearest" } ] }
JSON
sed 's/"quadruped_walk", "role": "test" }/&, { "name": "quadruped_trot", "role": "test" }/' walk.json > both.json
expect 0 "nricp             1 thread  register_random" "$TCBENCH" calibrate --quick --threads 1 --budget 4 \
    --out seq/calibration.json walk.json
grep -q "units, and the scoring of pairs, on s/quadruped_walk (10 frames" out.txt || { cat out.txt; exit 1; }
expect 0 "costs from (first match wins): seq/calibration.json" "$TCBENCH" run both.json --dry-run
/usr/bin/python3 - <<'PY'
import json, re
c = json.load(open("seq/calibration.json"))
on = {(e["kind"], e.get("unit", "")) for e in c["costs"] if e.get("sequence") == "s/quadruped_walk"}
assert on == {("unit", "register_random"), ("unit", "register_neighbor"), ("unit", "assign"), ("score_pair", "")}, on
assert all(e["vertices"] > 0 for e in c["costs"] if "sequence" in e), c["costs"]
text = open("out.txt").read()
rows = dict(re.findall(r"(?m)^\s+(\d+)\s+\S+\s+0\s+missing\s+.*?  (\S.*)$", text))
assert len(rows) == 4, text
# walk: nricp 0, nearest 1; trot: nricp 2, nearest 3
assert "register_random x" in rows["0"] and "measured on s/quadruped_walk" in rows["0"], rows["0"]
assert rows["1"].endswith("scoring measured on s/quadruped_walk"), rows["1"]
assert "measured on" not in rows["2"] + rows["3"], (rows["2"], rows["3"])
PY
expect 2 "calibrate: --only atlasnet: not a method of the config with units to measure on its sequences" \
    "$TCBENCH" calibrate --quick --threads 1 --only atlasnet --out seq/other.json walk.json

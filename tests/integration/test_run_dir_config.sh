#!/usr/bin/env bash
# One run directory, one config (issue 18) that may grow (issue 26): a run
# of a config whose shared settings (evaluation, a dataset's) differ from
# those the directory holds is refused before it writes anything, naming
# both configs and the key path; the same config still runs there from
# another data root, under another name or thread count, by cells or
# shards; added methods, seeds, sequences and datasets run there with no
# flag and the record becomes the union; a method whose params changed
# under its label is refused alone (key path, both values, the command
# that recomputes it; exit 2) while the others run; `score` gets a hint of
# its own; --force hands the directory over; of two configs started at
# once on a new directory, exactly one runs.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
"$TCBENCH" datasets synth --out data --sequence quadruped_walk --frames 4 2> /dev/null
cp -a data moved

config() { # NAME THREADS PAIRS FRAMES [MORE KEYS]
    cat <<JSON
{ "name": "$1", "splits_dir": "splits_$3", "cache_dir": "", "seeds": [0, 1], "threads": $2,
  "evaluation": { "pairs": $3, "pool_size": 200, "input_points": 100 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": $4,
                  "sequences": [ { "name": "quadruped_trot", "role": "test" } ] },
                { "name": "files", "source": "objdir", "root": "data",
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ]${5:-} }
JSON
}
config a 1 3 4 > a.json
config b 1 2 4 > b.json
config c 1 3 5 > c.json
config renamed 2 3 4 > renamed.json
config v 1 3 4 ', "variants": { "one": { "seeds": [0] }, "two": { "seeds": [0, 1] } }' > v.json
"$TCBENCH" run a.json --out run --quiet 2> /dev/null
cp run/config.json a.saved

expect 2 "run/config.json: the run directory holds the cells of another config than b.json (evaluation.pairs: 3 there, 2 here); cells of different settings are not mixed: give this config another --out (or 'tcbench run --force' to recompute" \
    "$TCBENCH" run b.json --out run --quiet
expect 2 "(datasets[synth].frames: 4 there, 5 here)" "$TCBENCH" run c.json --out run --cell 0 --quiet
cmp -s run/config.json a.saved || { echo "FAIL: a refused run changed config.json"; exit 1; }
[ "$(find run -newer a.saved -type f | wc -l)" -eq 0 ] || { echo "FAIL: a refused run wrote"; find run -newer a.saved; exit 1; }

# The same cells: another root, name and thread count; cells, shards.
expect 0 "0 computed, 8 already done" "$TCBENCH" run renamed.json --out run --root files=moved --quiet
expect 0 "0 computed, 1 already done" "$TCBENCH" run a.json --out run --cell 3 --quiet
expect 0 "0 computed, 4 already done" "$TCBENCH" run a.json --out run --shard 1/2 --quiet

# Variants are configs of their own.
expect 0 "" "$TCBENCH" run v.json --variant one --out variants --quiet
expect 0 "2 in all, 1 computed, 1 already done" "$TCBENCH" run v.json --variant two --out variants --cell 2,3 --quiet

# The grid grows: a method, a seed, a sequence, a dataset; no flag.
grown() { # SEEDS METHODS [DATASET]
    cat <<JSON
{ "name": "grown", "splits_dir": "splits_3", "cache_dir": "", "seeds": $1, "threads": 1,
  "evaluation": { "pairs": 3, "pool_size": 200, "input_points": 100 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 4,
                  "sequences": [ { "name": "quadruped_trot", "role": "test" },
                                 { "name": "quadruped_walk", "role": "test" } ] }${3:-} ],
  "methods": $2 }
JSON
}
cp -a run grow
grown '[0, 1]' '[ { "name": "oracle" }, { "name": "nearest" }, { "name": "nricp", "params": { "rounds": 2 } } ]' \
    > more.json
expect 0 "cells: 12 in all, 8 computed, 4 already done, 0 failed" "$TCBENCH" run more.json --out grow --quiet
grown '[2]' '[ { "name": "nricp", "params": { "rounds": 2 } } ]' \
    ', { "name": "synth2", "source": "synthetic", "frames": 4, "sequences": [ { "name": "quadruped_walk", "role": "test" } ] }' \
    > seed.json
expect 0 "cells: 3 in all, 3 computed, 0 already done" "$TCBENCH" run seed.json --out grow --quiet
# The record is the union: the cells of the methods, sequences and datasets
# a config leaves out stay recorded; status reads it.
# (the union's grid: cells neither config asked for are missing)
expect 0 "grow: 28 cells: 19 done, 0 diverged, 0 failed, 0 running, 0 stale, 9 missing" "$TCBENCH" status grow
/usr/bin/python3 - <<'PY'
import json
r = json.load(open("grow/config.json"))
assert r["seeds"] == [2, 0, 1], r["seeds"]
assert [m["name"] for m in r["methods"]] == ["nricp", "oracle", "nearest"], r["methods"]
assert [m.get("seeds") for m in r["methods"]] == [None, [0, 1], [0, 1]], r["methods"]
assert [d["name"] for d in r["datasets"]] == ["synth", "synth2", "files"], r["datasets"]
assert [s["name"] for s in r["datasets"][0]["sequences"]] == ["quadruped_trot", "quadruped_walk"]
PY

# One method's params changed: that method alone is refused, with the
# exact key and both values and the command that recomputes it; the other
# methods' new cells are computed; the record keeps the old params.
grown '[0, 1, 3]' '[ { "name": "oracle" }, { "name": "nricp", "params": { "rounds": 5 } } ]' > changed.json
cp grow/config.json grow.saved
expect 2 "tcbench: grow/config.json: the run directory holds nricp's cells with other settings (methods[nricp].params.rounds: 2 there, 5 here), so this run left them alone; recompute them here with 'tcbench run changed.json --force --only nricp', or give the changed method a new label" \
    "$TCBENCH" run changed.json --out grow --quiet
grep -qF "cells: 6 in all, 2 computed, 4 already done, 0 failed" err.txt || { cat err.txt; exit 1; }
ls grow/cells/synth/quadruped_walk/oracle/seed_3.json > /dev/null
[ ! -e grow/cells/synth/quadruped_walk/nricp/seed_3.json ] || { echo "FAIL: a refused method ran"; exit 1; }
/usr/bin/python3 - <<'PY'
import json
m = {m["name"]: m for m in json.load(open("grow/config.json"))["methods"]}
assert m["nricp"]["params"] == {"rounds": 2} and m["nricp"].get("seeds") == [2, 0, 1], m["nricp"]
PY
# --force --only recomputes it; the record then holds the new params.
expect 0 "cells: 6 in all, 6 computed, 0 already done" "$TCBENCH" run changed.json --out grow --force --only nricp --quiet
grep -qF '"rounds":	5' grow/config.json || { cat grow/config.json; exit 1; }
# A value cut short shows where the two differ.
long=$(printf 'x%.0s' $(seq 120))
grown '[0]' "[ { \"name\": \"oracle\", \"method\": \"external\", \"params\": { \"command\": [\"/$long/a.sh\"] } } ]" > long.json
expect 2 "(methods[oracle].method: \"oracle\" there, \"external\" here)" "$TCBENCH" run long.json --out grow --quiet
expect 1 "2 failed" "$TCBENCH" run long.json --out grow_ext --quiet
grown '[0]' "[ { \"name\": \"oracle\", \"method\": \"external\", \"params\": { \"command\": [\"/$long/b.sh\"] } } ]" > long2.json
expect 2 "(methods[oracle].params.command[0]: ...xxxxxxxxxxxxxxxx" "$TCBENCH" run long2.json --out grow_ext --quiet
grep -qF 'xxxxxx/a.sh" there, ...xxxxxx' err.txt && grep -qF 'xxxxxx/b.sh" here)' err.txt || { cat err.txt; exit 1; }

# score's refusal names the command that fits it.
/usr/bin/python3 - <<'PY'
import os, numpy as np
n = sum(1 for l in open("data/quadruped_walk/mesh_0000.obj") if l.startswith("v "))
os.makedirs("preds")
for k in range(2):
    np.save("preds/%d.npy" % k, np.arange(n, dtype=np.int32))
PY
expect 2 "run/config.json: the run directory holds the cells of another config than b.json (evaluation.pairs: 3 there, 2 here); cells of different settings are not mixed: give this config another --out (or score against the directory's own config: 'tcbench score run/config.json …')" \
    "$TCBENCH" score b.json --dataset files --sequence quadruped_walk --pred preds --name scored --out run

# --force hands the directory over; the other config is then refused.
expect 0 "8 computed" "$TCBENCH" run b.json --out run --force --quiet
expect 2 "than a.json (evaluation.pairs: 2 there, 3 here)" "$TCBENCH" run a.json --out run --quiet

# Two configs at once on a new directory: one claims it, the other is refused.
rc_a=0 rc_b=0
"$TCBENCH" run a.json --out race --quiet 2> race_a.log & pa=$!
"$TCBENCH" run b.json --out race --quiet 2> race_b.log & pb=$!
wait $pa || rc_a=$?
wait $pb || rc_b=$?
[ $((rc_a + rc_b)) -eq 2 ] && [ $((rc_a * rc_b)) -eq 0 ] && grep -qF "another config" race_a.log race_b.log ||
    { echo "FAIL: two configs at once exited $rc_a and $rc_b"; cat race_a.log race_b.log; exit 1; }
echo "run directory config test passed"

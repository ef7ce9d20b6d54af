#!/usr/bin/env bash
# "source": "dfaust" end to end: a root in the official layout (written by
# the test helper write_dfaust: subject 50002, 6 frames, in
# registrations_m.hdf5 and 50004, 8 frames, in registrations_f.hdf5) runs
# oracle and nearest through the cache; the oracle scores 0, the split
# records the two blocks and keeps every pair inside one; a rerun reuses the
# cells and the cache; a listed subject without its dataset is an error
# naming the files and the key.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_WRITE_DFAUST:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
mkdir dfaust
"$TCB_WRITE_DFAUST" dfaust

dfaust_config() { # NAME SUBJECTS-KEY
    cat > "$1.json" <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "cache",
  "evaluation": { "pairs": 20, "pool_size": 500, "input_points": 200 },
  "datasets": [ { "name": "dfaust", "source": "dfaust", "root": "dfaust", $2
                  "sequences": [ { "name": "jumping_jacks", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
}
dfaust_config jacks ""
# The dry run sizes the sequence from the registrations' shapes alone.
"$TCBENCH" run jacks.json --dry-run > dry.txt 2>&1 || { cat dry.txt; exit 1; }
grep -qE "^dfaust/jumping_jacks: 14 frames, [0-9]+ vertices, 20 pairs$" dry.txt || { cat dry.txt; exit 1; }
[ ! -d cache ] || { echo "FAIL: the dry run loaded the sequence"; exit 1; }
"$TCBENCH" run jacks.json --quiet 2> run.log || { cat run.log; exit 1; }
grep -qF "cells: 2 in all, 2 computed, 0 already done, 0 failed" run.log || { cat run.log; exit 1; }
[ "$(find cache -name '*.h5' | wc -l)" -eq 1 ] || { echo "FAIL: expected one cache entry"; ls -R cache; exit 1; }
/usr/bin/python3 - <<'PY'
import json
cells = "runs/jacks/cells/dfaust/jumping_jacks/%s/seed_0.json"
oracle, nearest = (json.load(open(cells % m)) for m in ("oracle", "nearest"))
for c in (oracle, nearest):
    assert c["status"] == "ok" and c["summary"]["n_pairs"] == 20, c["message"]
assert oracle["summary"]["sl2"]["mean"] == 0, oracle["summary"]["sl2"]
assert nearest["summary"]["sl2"]["mean"] > 0
split = json.load(open("splits/dfaust/jumping_jacks.json"))
assert split["n_frames"] == 14
assert split["blocks"] == [{"name": "50002", "start": 0, "n_frames": 6},
                           {"name": "50004", "start": 6, "n_frames": 8}], split["blocks"]
for i, j in split["pairs"]:
    assert (i < 6) == (j < 6) and i != j, (i, j)
config = json.load(open("runs/jacks/config.json"))["datasets"][0]
assert config["source"] == "dfaust" and config["normalization"] == "none", config
assert config["sampling"] == "with_replacement", config
PY

# A rerun: the cells are done, the sequence comes from the cache.
"$TCBENCH" run jacks.json --quiet 2> again.log || { cat again.log; exit 1; }
grep -qF "cells: 2 in all, 0 computed, 2 already done, 0 failed" again.log || { cat again.log; exit 1; }
[ "$(find cache -name '*.h5' | wc -l)" -eq 1 ] || { echo "FAIL: the rerun did not reuse the cache"; exit 1; }

# Another subject list is another sequence: its split would differ, so the
# existing one is refused, naming the file and the field.
dfaust_config one '"subjects": ["50004"],'
rc=0
"$TCBENCH" run one.json --quiet 2> one.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "splits/dfaust/jumping_jacks.json: n_frames is 14 in the split file but 8" one.log ||
    { echo "FAIL: a split of other blocks (exit $rc)"; cat one.log; exit 1; }

dfaust_config missing '"subjects": ["50002", "50099"],'
rc=0
"$TCBENCH" run missing.json --quiet 2> missing.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "dfaust/registrations_m.hdf5 and dfaust/registrations_f.hdf5: no dataset 50099_jumping_jacks" missing.log ||
    { echo "FAIL: missing subject (exit $rc)"; cat missing.log; exit 1; }
echo "dfaust test passed"

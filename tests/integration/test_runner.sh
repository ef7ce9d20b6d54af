#!/usr/bin/env bash
# Runner behaviour beyond the happy path: a method failing in fit or
# transfer yields a failed cell (a diverged one for TCB_ERR_NUMERIC, a
# training that diverged), and the run goes on (exit 1 for the failed ones,
# listed at the end); a transfer's bad points (NaN, beyond the k-NN range,
# vertex ids as coordinates) fail their own cell, naming pair and vertex;
# the cell's thread count holds in its evaluation too;
# optional objdir datasets are skipped when absent, required ones are an
# error naming the path; an objdir sequence loads through the cache.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/harness_methods.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
build_harness_methods "$tmp/libharness_methods.so"
plugin="$tmp/libharness_methods.so"

# ---- method failures are results, not crashes
cat > faults.json <<'JSON'
{ "name": "faults", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 10, "pool_size": 1000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 8,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "fit_fails", "method": "faulty", "params": { "mode": "fit" } },
               { "name": "numeric", "method": "faulty", "params": { "mode": "numeric", "at": 3 } },
               { "name": "nan", "method": "faulty", "params": { "mode": "nan", "at": 0 } },
               { "name": "huge", "method": "faulty", "params": { "mode": "huge", "at": 2 } },
               { "name": "ids", "method": "faulty", "params": { "mode": "ids", "at": 1 } },
               { "name": "nearest" } ] }
JSON
rc=0
"$TCBENCH" run faults.json --plugin "$plugin" --quiet 2> faults.log || rc=$?
[ "$rc" -eq 1 ] || { echo "FAIL: a run with a failed cell exited $rc"; cat faults.log; exit 1; }
grep -qF "cells: 6 in all, 6 computed, 0 already done, 4 failed, 1 diverged" faults.log || { cat faults.log; exit 1; }
grep -qxF "synth/quadruped_walk/fit_fails/seed 0: fit: faulty: refusing to fit" faults.log || { cat faults.log; exit 1; }
grep -qF "warning: synth/quadruped_walk/numeric/seed 0 diverged" faults.log || { cat faults.log; exit 1; }
/usr/bin/python3 - <<'PY'
import json
def cell(m):
    return json.load(open("runs/faults/cells/synth/quadruped_walk/%s/seed_0.json" % m))
expect = {
    "fit_fails": ("failed", "fit: faulty: refusing to fit"),
    "numeric": ("diverged", "(pair 3): faulty: loss is NaN"),
    "nan": ("failed", "(pair 0): returned a non-finite point (vertex "),
    "huge": ("failed", "(pair 2): returned a point beyond ±1e+18 (vertex "),
    "ids": ("failed", "(pair 1): returned points off the shape: the points lie a median "),
    "nearest": ("ok", ""),
}
for m, (status, text) in expect.items():
    c = cell(m)
    assert c["status"] == status, (m, c["status"], c["message"])
    assert text in c["message"], (m, c["message"])
    assert (c["summary"]["n_pairs"] == 10) == (status == "ok"), (m, c["summary"]["n_pairs"])
PY
"$TCBENCH" report runs/faults --quiet
grep -q "diverged" runs/faults/report/tables.md || { cat runs/faults/report/tables.md; exit 1; }

# ---- a cell's thread count covers its evaluation, not only its fit (two
# --threads 1 processes on two cores must not each evaluate with two)
cat > threads.json <<'JSON'
{ "name": "threads", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 10, "pool_size": 1000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 8,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "thread_probe", "method": "thread_probe" } ] }
JSON
for t in 1 3; do
    OMP_NUM_THREADS=2 "$TCBENCH" run threads.json --plugin "$plugin" --threads $t --out runs/threads-$t --quiet \
        &> threads.log || true
    grep -qF "cells: 1 in all, 1 computed, 0 already done, 0 failed" threads.log ||
        { echo "FAIL: --threads $t"; cat threads.log runs/threads-$t/cells/*/*/*/seed_0.json; exit 1; }
done

# Bad params are caught before any cell runs.
sed 's/"mode": "fit"/"mode": "bogus"/' faults.json > badparams.json
rc=0
"$TCBENCH" --plugin "$plugin" run badparams.json --out runs/bad 2> bad.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "badparams.json: methods[0].params: faulty.params.mode: unknown mode 'bogus'" bad.log ||
    { echo "FAIL: bad params (exit $rc)"; cat bad.log; exit 1; }
[ ! -d runs/bad/cells ] || { echo "FAIL: cells written despite bad params"; exit 1; }

# ---- objdir datasets: optional and required roots, cached loading
"$TCBENCH" datasets synth --out data --sequence quadruped_walk --frames 8 2> /dev/null
objdir_config() { # NAME ROOT OPTIONAL
    cat > "$1.json" <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "cache",
  "evaluation": { "pairs": 10, "pool_size": 1000 },
  "datasets": [ { "name": "objs", "source": "objdir", "root": "$2", "optional": $3,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" } ] }
JSON
}
objdir_config absent nowhere true
"$TCBENCH" run absent.json 2> absent.log
grep -qF "dataset objs skipped: nowhere not found (optional)" absent.log || { cat absent.log; exit 1; }
grep -qF "cells: 0 in all" absent.log || { cat absent.log; exit 1; }
objdir_config required nowhere false
rc=0
"$TCBENCH" run required.json 2> required.log || rc=$?
[ "$rc" -eq 2 ] && grep -qF "required.json: datasets[0].root: nowhere: no such directory" required.log ||
    { echo "FAIL: missing required root (exit $rc)"; cat required.log; exit 1; }
objdir_config objs data false
"$TCBENCH" run objs.json --quiet
[ -n "$(find cache -type f)" ] || { echo "FAIL: nothing cached"; exit 1; }
"$TCBENCH" run objs.json --out runs/objs-again --quiet   # from the cache
/usr/bin/python3 - <<'PY'
import json
a, b = (json.load(open(r + "/cells/objs/quadruped_walk/nearest/seed_0.json"))
        for r in ("runs/objs", "runs/objs-again"))
assert a["status"] == "ok" and a["summary"]["n_pairs"] == 10, a["message"]
assert a["summary"] == b["summary"] and a["pairs"] == b["pairs"]
PY
echo "runner test passed"

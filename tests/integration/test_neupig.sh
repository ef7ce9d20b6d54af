#!/usr/bin/env bash
# neupig end to end at its tiny preset on a short synthetic walk: the cell
# is ok with every metric and a CD; `inspect` rebuilds the model from its
# file (parameters and seed; the template from the sequence) and recomputes
# the pair exactly; the ground-truth normals variant runs; a training killed
# after a checkpoint resumes and ends with the same cell; bad params are
# refused naming the key.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

enter_temp_dir

cat > np.json <<'JSON'
{ "name": "np", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 6, "pool_size": 1000, "input_points": 300 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "neupig", "params": { "preset": "tiny", "epochs": 40, "checkpoint_every": 4 } },
               { "name": "neupig_gt", "method": "neupig", "params": { "preset": "tiny", "normals": "gt" } } ] }
JSON
cell=cells/synth/quadruped_walk/neupig/seed_0.json
work=work/synth/quadruped_walk/neupig/seed_0

"$TCBENCH" run np.json --out full --quiet
/usr/bin/python3 - full/$cell full/cells/synth/quadruped_walk/neupig_gt/seed_0.json <<'PY'
import json, math, sys
for path in sys.argv[1:]:
    c = json.load(open(path))
    assert c["status"] == "ok", (path, c["status"], c["message"])
    s = c["summary"]
    assert s["n_pairs"] == 6 and s["cd"] is not None and s["cd"]["n"] == 6, path
    for key in ("sl2", "rank", "auc", "cd", "geo"):
        assert math.isfinite(s[key]["mean"]), (path, key)
PY

"$TCBENCH" inspect full neupig 0 --out insp > inspect.txt
grep -q "agree: largest relative difference 0.0e+00" inspect.txt || { cat inspect.txt; exit 1; }

"$TCBENCH" run np.json --out killed --only neupig --quiet &
pid=$!
kill_when "$pid" test -s "killed/$work/train.ckpt"
pid=""
[ ! -e "killed/$cell" ] || { echo "FAIL: the kill did not land before the end of the training"; exit 1; }
CI= "$TCBENCH" run np.json --out killed --only neupig 2> resume.log
grep -q "resuming training at iteration [1-9]" resume.log || { echo "FAIL: did not resume"; cat resume.log; exit 1; }
"$TCBENCH" run np.json --out killed --only neupig_gt --quiet
same_cells full killed

bad() { sed "s/\"preset\": \"tiny\", \"normals\": \"gt\"/$1/" np.json > bad.json; expect 2 "$2" "$TCBENCH" run bad.json --out bad --quiet; }
bad '"preset": "tiny", "normals": "both"' "neupig.params.normals"
bad '"preset": "huge"' "neupig.params.preset"
bad '"preset": "tiny", "poisson_depth": 1' "neupig.params.poisson_depth"
echo "neupig test passed"

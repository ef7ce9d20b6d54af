#!/usr/bin/env bash
# dynosurf end to end at its tiny preset on a short synthetic walk: the
# cell is ok with every metric, a CD and the reconstruction metrics of its
# surface (the extracted template carried into every frame) on every frame
# of its pairs, the template written for people to open; `inspect` rebuilds
# the model from its file (the parameters; the grid and template from the
# sequence and the seed) and recomputes the pair exactly; a training killed
# after a checkpoint resumes and ends with the same cell; bad params are
# refused naming the key; calibrate and the dry run price it.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

enter_temp_dir

cat > dynosurf.json <<'JSON'
{ "name": "dynosurf", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 6, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "dynosurf", "params": { "preset": "tiny", "checkpoint_every": 20 } } ] }
JSON
cell=cells/synth/quadruped_walk/dynosurf/seed_0.json
work=work/synth/quadruped_walk/dynosurf/seed_0

"$TCBENCH" run dynosurf.json --out full --quiet
ls full/$work/template_keyframe_*.obj > /dev/null || { echo "FAIL: no template written"; exit 1; }
check_carried_cell full/$cell

"$TCBENCH" inspect full dynosurf 0 --out insp > inspect.txt
grep -q "agree: largest relative difference 0.0e+00" inspect.txt || { cat inspect.txt; exit 1; }

kill_mid_fit dynosurf.json "$work" "$cell"
same_cells full killed

# The dry run's price: calibrate times stage 2's step (train_steps), the
# grid and the other phases' steps as units (stage 1's after readying a
# surface) and a frame's share of a stage-2 step, and the estimate counts
# each phase's steps and stage 2's frames.
mkdir -p priced
expect 0 "wrote priced/calibration.json" "$TCBENCH" calibrate --only dynosurf --preset tiny --threads 1 --budget 4 \
    --quick --samples 500 --out priced/calibration.json
/usr/bin/python3 - <<'PY'
import json
c = json.load(open("priced/calibration.json"))
got = {(e["kind"], e.get("unit", "")) for e in c["costs"] if e["method"] == "dynosurf"}
want = {("step", ""), ("eval_pair", ""), ("unit", "grid"), ("unit", "pretrain"), ("unit", "template"), ("unit", "blend"),
        ("unit", "frame")}
assert want <= got, got
assert all(e["seconds"] > 0 for e in c["costs"]), c["costs"]
PY
expect 0 "15 steps x" "$TCBENCH" run dynosurf.json --dry-run --out priced
grep -qE "^ +0 +dynosurf .* 15 steps x [0-9.]+ ms \(1 thread, .*\) \+ [0-9]+ [a-z]+ x " out.txt ||
    { echo "FAIL: the dry run does not price stage 2's steps and the units"; cat out.txt; exit 1; }
sed 's/"checkpoint_every": 20/"checkpoint_every": 20, "samples": 401/' dynosurf.json > unpriced.json
expect 0 "a size differs from every preset" "$TCBENCH" run unpriced.json --dry-run --out priced

bad() { sed "s/\"preset\": \"tiny\", \"checkpoint_every\": 20/$1/" dynosurf.json > bad.json; expect 2 "$2" "$TCBENCH" run bad.json --out bad --quiet; }
bad '"preset": "huge"' "dynosurf.params.preset"
bad '"preset": "tiny", "tet_volume": 0' "dynosurf.params.tet_volume"
bad '"preset": "tiny", "layers": 3' "dynosurf.params.layers: unknown key"
bad '"preset": "tiny", "pretrain_steps": 0, "template_steps": 0, "blend_steps": 0, "motion_steps": 0' "dynosurf.params: no steps to take"
echo "dynosurf test passed"

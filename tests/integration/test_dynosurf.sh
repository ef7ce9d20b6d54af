#!/usr/bin/env bash
# dynosurf end to end at its tiny preset on a short synthetic walk: the
# cell is ok with every metric, a CD and the reconstruction metrics of its
# surface (the extracted template carried into every frame) on every frame
# of its pairs, the template written for people to open; `inspect` rebuilds
# the model from its file (the parameters; the grid and template from the
# sequence and the seed) and recomputes the pair exactly; a training killed
# after a checkpoint resumes and ends with the same cell; bad params are
# refused naming the key.
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

bad() { sed "s/\"preset\": \"tiny\", \"checkpoint_every\": 20/$1/" dynosurf.json > bad.json; expect 2 "$2" "$TCBENCH" run bad.json --out bad --quiet; }
bad '"preset": "huge"' "dynosurf.params.preset"
bad '"preset": "tiny", "tet_volume": 0' "dynosurf.params.tet_volume"
bad '"preset": "tiny", "layers": 3' "dynosurf.params.layers: unknown key"
bad '"preset": "tiny", "pretrain_steps": 0, "template_steps": 0, "blend_steps": 0, "motion_steps": 0' "dynosurf.params: no steps to take"
echo "dynosurf test passed"

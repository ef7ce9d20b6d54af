#!/usr/bin/env bash
# pdg end to end at its tiny preset on a short synthetic walk (the chains
# train after a 10-epoch warm-up): the cell is ok with every metric, a CD
# and the reconstruction metrics of its surface (the template carried into
# every frame) on every frame of its pairs, the keyframe's template written
# for people to open; `inspect` rebuilds the model from its file (the
# parameters, the template from the sequence and the seed) and recomputes
# the pair exactly; a training killed after a checkpoint resumes and ends
# with the same cell; bad params are refused naming the key.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

enter_temp_dir

cat > pdg.json <<'JSON'
{ "name": "pdg", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 6, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "pdg", "params": { "preset": "tiny", "checkpoint_every": 4 } } ] }
JSON
cell=cells/synth/quadruped_walk/pdg/seed_0.json
work=work/synth/quadruped_walk/pdg/seed_0

"$TCBENCH" run pdg.json --out full --quiet
ls full/$work/template_keyframe_*.obj > /dev/null || { echo "FAIL: no template written"; exit 1; }
check_carried_cell full/$cell

"$TCBENCH" inspect full pdg 0 --out insp > inspect.txt
grep -q "agree: largest relative difference 0.0e+00" inspect.txt || { cat inspect.txt; exit 1; }

kill_mid_fit pdg.json "$work" "$cell"
same_cells full killed

sed 's/"checkpoint_every": 4/"checkpoint_every": 4, "rotation": "cayley"/' pdg.json > cayley.json
"$TCBENCH" run cayley.json --out cayley --quiet
check_carried_cell cayley/$cell
# the cayley model under the released cell's record (its params made the
# released ones): the model file's manifest refuses it
cp -r full swapped
cp cayley/$work/model.ckpt cayley/$work/model.ckpt.fit.json swapped/$work/
sed -i 's/,\\"rotation\\":\\"cayley\\"//' swapped/$work/model.ckpt.fit.json
expect 2 'model.ckpt.rotation: expected "released" for this model' "$TCBENCH" inspect swapped pdg 0 --out insp2

bad() { sed "s/\"preset\": \"tiny\", \"checkpoint_every\": 4/$1/" pdg.json > bad.json; expect 2 "$2" "$TCBENCH" run bad.json --out bad --quiet; }
bad '"preset": "huge"' "pdg.params.preset"
bad '"preset": "tiny", "levels": 0' "pdg.params.levels"
bad '"preset": "tiny", "layers": 3' "pdg.params.layers: unknown key"
bad '"preset": "tiny", "rotation": "euler"' "pdg.params.rotation"
echo "pdg test passed"

#!/usr/bin/env bash
# A training killed (SIGKILL) after its first checkpoint resumes from it and
# ends with the same cell as an uninterrupted run; no training state or
# temporary is left; --force starts from scratch (a stale training state in
# the cell's work directory is not even looked at).
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

enter_temp_dir

cat > train.json <<'JSON'
{ "name": "train", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "mca", "params": { "preset": "tiny", "iterations": 400, "checkpoint_every": 40 } } ] }
JSON
work=work/synth/quadruped_walk/mca/seed_0

"$TCBENCH" run train.json --out full --quiet
[ ! -e "full/$work/train.ckpt" ] || { echo "FAIL: training state left after a finished fit"; exit 1; }

kill_mid_fit train.json "$work" cells/synth/quadruped_walk/mca/seed_0.json
same_cells full killed
leftovers=$(find killed -name '*.tmp-*' -o -name train.ckpt)
[ -z "$leftovers" ] || { echo "FAIL: left behind: $leftovers"; exit 1; }

echo "not a checkpoint" > "killed/$work/train.ckpt"
"$TCBENCH" run train.json --out killed --force 2> force.log
if grep -q "not resumed" force.log; then echo "FAIL: --force looked at the old training state"; cat force.log; exit 1; fi
same_cells full killed
echo "atlas training resume test passed"

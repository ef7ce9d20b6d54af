#!/usr/bin/env bash
# neupig's fit writes its keyframe template (template_keyframe_<K>.obj, in
# the sequence's coordinates) and scripts/keyframe_template.py measures it
# against frame K's GT mesh: the counts are the OBJ's, the face budget
# holds, the surface lies on the GT one (sqrt(CD)/diag small; GT normals,
# as the reference: estimated ones fold the synthetic legs, docs/meshing.md),
# a face cut out shows as three more boundary edges, a shifted copy as a
# large Chamfer, and a directory without a template is refused.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"
. "$(dirname "${BASH_SOURCE[0]}")/python_env.sh"
/usr/bin/python3 -c "import scipy" 2>/dev/null || { echo "skipped: /usr/bin/python3 cannot import scipy"; exit 77; }

enter_temp_dir

cat > np.json <<'JSON'
{ "name": "np", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 2, "pool_size": 3000, "input_points": 2000, "surface_samples": 200 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 4,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "neupig", "params": { "preset": "tiny", "epochs": 2, "template_faces": 3000, "poisson_depth": 7, "normals": "gt" } } ] }
JSON
work=run/work/synth/quadruped_walk/neupig/seed_0
"$TCBENCH" run np.json --out run --quiet
ls $work/template_keyframe_*.obj > /dev/null

check() { py "$TCB_SOURCE_DIR/scripts/keyframe_template.py" np.json synth/quadruped_walk "$1" --samples 20000; }
check $work > good.txt
cat good.txt
py - good.txt $work <<'PY'
import glob, sys
out = dict(l.split(None, 1) for l in open(sys.argv[1]).read().splitlines() if not l.startswith("edges"))
obj = open(glob.glob(sys.argv[2] + "/template_keyframe_*.obj")[0]).read().splitlines()
nv, nf = sum(l.startswith("v ") for l in obj), sum(l.startswith("f ") for l in obj)
assert int(out["vertices"]) == nv and int(out["faces"].split()[0]) == nf <= 3000, (out, nv, nf)
cd = float(out["sqrt(CD)/diag"].split()[0])
assert 0 < cd < 0.03, cd
PY

mkdir cut shifted
sed '0,/^f /{/^f /d}' $work/template_keyframe_*.obj > cut/template_keyframe_0.obj
awk '$1 == "v" { printf "v %s %s %s\n", $2 + 0.3, $3, $4; next } { print }' $work/template_keyframe_*.obj \
    > shifted/template_keyframe_0.obj
key=$(ls $work | sed -n 's/template_keyframe_\([0-9]*\)\.obj/\1/p')
for d in cut shifted; do mv $d/template_keyframe_0.obj $d/template_keyframe_$key.obj; done
holes() { sed -n 's/^boundary edges  //p' "$1"; }
check cut > cut.txt
[ "$(holes cut.txt)" = "$(( $(holes good.txt) + 3 ))" ] || { cat cut.txt; echo "FAIL: a removed face is not 3 more boundary edges"; exit 1; }
check shifted | py -c '
import sys
cd = float([l for l in sys.stdin if l.startswith("sqrt")][0].split()[1])
assert cd > 0.1, cd'
expect 2 "expected one template_keyframe_<K>.obj" check .
echo "neupig template test passed"

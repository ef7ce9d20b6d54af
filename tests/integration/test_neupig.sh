#!/usr/bin/env bash
# neupig end to end at its tiny preset on a short synthetic walk: the cell
# is ok with every metric, a CD and the reconstruction metrics of its
# surface (the deformed template, a mesh without charts) on every frame of
# its pairs; `tcbench frames` draws that surface, one colour per template
# vertex in every frame (PLYs of one topology, a strip); `inspect` rebuilds the model from its
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
  "evaluation": { "pairs": 6, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
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
    frames = sorted({f for p in c["pairs"] for f in p[:2]})
    surf = c["surface"]
    assert surf["samples"] == 500 and [r[0] for r in surf["rows"]] == frames, (path, surf)
    for key in ("cdl2", "nc", "fscore05", "fscore1"):
        assert s[key]["n"] == len(frames), (path, key, s[key])
    assert all(r[1] > 0 and 0 <= min(r[2:]) and max(r[2:]) <= 1 for r in surf["rows"]), (path, surf["rows"])
PY

"$TCBENCH" frames full neupig --frames 0,2,5 --out frames --quiet > frames.txt
grep -q "textured surface, frames 0, 2, 5" frames.txt || { cat frames.txt; exit 1; }
/usr/bin/python3 - frames <<'PY'
import os, sys
d = sys.argv[1]
assert sorted(os.listdir(d)) == ["frame_0.ply", "frame_2.ply", "frame_5.ply", "strip.png"], os.listdir(d)

def ply(path):
    lines = open(path).read().split("\n")
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    body = lines[lines.index("end_header") + 1:]
    verts = [l.split() for l in body[:nv]]
    return [v[:3] for v in verts], [v[3:] for v in verts], body[nv:]

meshes = [ply(f"{d}/frame_{f}.ply") for f in (0, 2, 5)]
(v0, rgb0, faces0) = meshes[0]
assert len(v0) > 10 and len(faces0) > 10 and len({tuple(c) for c in rgb0}) > len(v0) // 4, (len(v0), len(faces0))
for v, rgb, faces in meshes[1:]:
    assert rgb == rgb0 and faces == faces0, "a template vertex changed colour or the faces changed"
    assert v != v0, "the template did not move between frames"
png = open(f"{d}/strip.png", "rb").read()
assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000, len(png)
PY

"$TCBENCH" inspect full neupig 0 --out insp > inspect.txt
grep -q "agree: largest relative difference 0.0e+00" inspect.txt || { cat inspect.txt; exit 1; }

kill_mid_fit np.json "$work" "$cell" --only neupig
"$TCBENCH" run np.json --out killed --only neupig_gt --quiet
same_cells full killed

bad() { sed "s/\"preset\": \"tiny\", \"normals\": \"gt\"/$1/" np.json > bad.json; expect 2 "$2" "$TCBENCH" run bad.json --out bad --quiet; }
bad '"preset": "tiny", "normals": "both"' "neupig.params.normals"
bad '"preset": "huge"' "neupig.params.preset"
bad '"preset": "tiny", "poisson_depth": 1' "neupig.params.poisson_depth"
echo "neupig test passed"

#!/usr/bin/env bash
# The authors' clip folders ("source": "clipdir", docs/datasets.md): per
# clip gt/NNNN.obj and pcl_seqs/NNNN.npy, written here as DynoSurf's
# preprocessed data lays them out. Fitted per clip, each folder is a cell;
# the tracked points are what DynoSurf's Corr matches against (numpy from
# the files, 1e-9); a bad folder — a missing frame, frames of another
# topology, a truncated or NaN pcl_seqs frame, one of another point count
# or a missing one — is one error naming the file, exit 2.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_CLIP_DUMP:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
enter_temp_dir

/usr/bin/python3 - <<'PY'
import os
import numpy as np
# two clips of a bending, moving tube (8 x 12 grid), 17 frames each; pcl_seqs:
# 400 points drawn once on frame 0's faces (face, barycentrics), the same
# material points in every frame, as Occupancy Flow and DynoSurf make them
rng = np.random.default_rng(7)
nu, nv = 8, 12
u, v = np.meshgrid(np.linspace(0, 2 * np.pi, nu, endpoint=False), np.linspace(0, 1, nv), indexing="ij")
base = np.stack([0.3 * np.cos(u), 0.3 * np.sin(u), 2 * v], -1).reshape(-1, 3)
idx = lambda i, j: (i % nu) * nv + j
faces = np.array([f for i in range(nu) for j in range(nv - 1)
                  for f in ((idx(i, j), idx(i + 1, j), idx(i, j + 1)), (idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)))])
pick = rng.integers(0, len(faces), 400)
bary = rng.dirichlet((1, 1, 1), 400)
for clip, phase in (("tube_0000", 0.0), ("tube_0030", 1.0)):
    os.makedirs("clips/%s/gt" % clip)
    os.makedirs("clips/%s/pcl_seqs" % clip)
    for t in range(17):
        a = 0.05 * (t + 10 * phase)
        z = base[:, 2:3]
        w = base + np.hstack([np.sin(a) * z ** 2, 0 * z, 0 * z]) + np.array([1.5, 0.2 * t / 16, -0.4])
        with open("clips/%s/gt/%04d.obj" % (clip, t), "w") as out:
            out.writelines("v %.6f %.6f %.6f\n" % tuple(p) for p in w)
            out.writelines("f %d %d %d\n" % (i + 1, j + 1, k + 1) for i, j, k in faces)
        w32 = np.loadtxt(["%.6f %.6f %.6f" % tuple(p) for p in w])   # the coordinates as the OBJ holds them
        pts = (bary[:, :, None] * w32[faces[pick]]).sum(1)
        np.save("clips/%s/pcl_seqs/%04d.npy" % (clip, t), pts.astype(np.float32))
PY

cat > clips.json <<'JSON'
{ "name": "clips", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "protocol": "clips", "fit": "per_clip", "pool_size": 1000, "input_points": 300,
                  "input_normals": "gt", "surface_samples": 2000 },
  "datasets": [ { "name": "toy", "source": "clipdir", "root": "clips",
                  "sequences": [ { "name": "tube_0000", "role": "test" }, { "name": "tube_0030", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" }, { "name": "neupig", "params": { "preset": "tiny", "epochs": 20 } } ] }
JSON
"$TCBENCH" run clips.json --dry-run > dry.txt
grep -q '^toy/tube_0000: 17 frames, 96 vertices, 16 pairs$' dry.txt || { echo "FAIL: dry run"; cat dry.txt; exit 1; }
"$TCBENCH" run clips.json --out run --quiet
for clip in tube_0000 tube_0030; do "$TCB_CLIP_DUMP" run "toy/$clip" neupig "dump_$clip"; done
/usr/bin/python3 - <<'PY'
import json
import numpy as np
from scipy.spatial import cKDTree
rec = json.load(open("run/config.json"))["datasets"][0]
assert rec["source"] == "clipdir" and rec["normalization"] == "none", rec   # their coordinates by default
for clip in ("tube_0000", "tube_0030"):
    d = "dump_" + clip
    meta = json.load(open(d + "/meta.json"))
    F, sv = meta["frames"], meta["sv"]
    surf = np.fromfile(d + "/surf_verts.bin", dtype="<f4").reshape(F, sv, 3).astype(np.float64)
    track = np.stack([np.load("clips/%s/pcl_seqs/%04d.npy" % (clip, t)) for t in range(F)]).astype(np.float64)
    # DynoSurf's eval_correspondences_mesh against the pcl_seqs points
    ind = cKDTree(track[0]).query(surf[0])[1]
    corr = np.mean([np.linalg.norm(surf[t] - track[t][ind], axis=-1).mean() for t in range(1, F)])
    cell = json.load(open("run/cells/toy/%s/neupig/seed_0.json" % clip))
    got = cell["clips"]["rows"][0][3]
    assert abs(got - corr) <= 1e-9 * corr, (clip, got, corr)
    # and not against the vertices (the points matter)
    gt = np.fromfile(d + "/gt_verts.bin", dtype="<f4").reshape(F, -1, 3).astype(np.float64)
    ind_v = cKDTree(gt[0]).query(surf[0])[1]
    corr_v = np.mean([np.linalg.norm(surf[t] - gt[t][ind_v], axis=-1).mean() for t in range(1, F)])
    assert abs(got - corr_v) > 1e-6 * corr, (got, corr_v)
    assert json.load(open("run/cells/toy/%s/nearest/seed_0.json" % clip))["status"] == "ok"
print("clip folders: Corr-mesh tracks the pcl_seqs points (numpy, 1e-9)")
PY

# Bad folders: each one error naming the file, exit 2.
bad() { rm -rf bad && cp -r clips/tube_0000 bad; }
one() { sed 's/"sequences": \[.*\] } \]/"sequences": [ { "name": "bad", "role": "test" } ] } ]/; s/"root": "clips"/"root": "."/' \
        clips.json > badrun.json; }
one
bad; rm bad/gt/0005.obj
expect 2 'bad/gt: frame 0005 is missing (the next is 0006.obj' "$TCBENCH" run badrun.json --out b1
bad; sed -i '$d' bad/gt/0007.obj
expect 2 '0007.obj' "$TCBENCH" run badrun.json --out b2
grep -q 'faces' err.txt || { echo "FAIL: topology message"; cat err.txt; exit 1; }
bad; head -c 100 clips/tube_0000/pcl_seqs/0003.npy > bad/pcl_seqs/0003.npy
expect 2 'bad/pcl_seqs/0003.npy: ' "$TCBENCH" run badrun.json --out b3
bad; /usr/bin/python3 -c "
import numpy as np; p = np.load('bad/pcl_seqs/0004.npy'); p[17, 1] = np.nan; np.save('bad/pcl_seqs/0004.npy', p)"
expect 2 'bad/pcl_seqs/0004.npy: point 17 has coordinate nan' "$TCBENCH" run badrun.json --out b4
bad; /usr/bin/python3 -c "
import numpy as np; p = np.load('bad/pcl_seqs/0009.npy'); np.save('bad/pcl_seqs/0009.npy', p[:-1])"
expect 2 'bad/pcl_seqs/0009.npy: (399, 3) points, but the first frame has 400' "$TCBENCH" run badrun.json --out b5
bad; rm bad/pcl_seqs/0016.npy
expect 2 'bad/pcl_seqs/0016.npy: no such file (gt/0016.obj has no tracked points)' "$TCBENCH" run badrun.json --out b6
bad; rm -r bad/gt
expect 2 'bad/gt: no such directory (a clip folder holds its GT meshes in gt/)' "$TCBENCH" run badrun.json --out b7
for r in b1 b2 b3 b4 b5 b6 b7; do
    [ -z "$(find "$r" -name 'seed_*.json' 2>/dev/null)" ] || { echo "FAIL: $r wrote a cell"; exit 1; }
done
echo "ok"

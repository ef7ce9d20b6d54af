#!/usr/bin/env bash
# Clips fitted on their own ("evaluation.fit": "per_clip", docs/protocol.md,
# "Per-clip fitting"), on an OBJ sequence this test writes (a deforming
# blob away from the origin, so every normalization moves it):
# 1. each clip is a sequence and a cell (crane_0003-style names), the dry
#    run prices every clip's fit (no "?"), the record keeps each clip, the
#    report says which method took the input normals;
# 2. the clip-frame metrics equal numpy following DynoSurf's evaluation/
#    on the same meshes and points: the clip's normalization (clip_bbox,
#    first_frame_diag) recomputed from the raw OBJ files, the frame box
#    of recon_frame "frame_box", CD-L2 / NC / F-score at the absolute
#    thresholds linspace(0.001, 1, 1000)[4] and [9] on the samples scored
#    (1e-6 relative), and DynoSurf's Corr (eval_correspondences_mesh) on
#    the method's surfaces (1e-9 relative);
# 3. a per-clip cell killed mid-fit resumes bit-identically;
# 4. bad per-clip configs and clips are refused in one line, exit 2.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_CLIP_DUMP:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
enter_temp_dir

/usr/bin/python3 - <<'PY'
import os
import numpy as np
# a UV sphere of 12 x 16, moving and bending over 30 frames, centred at
# (5, -2, 1) with radius 3: every normalization moves and scales it
rings, segs = 12, 16
th = np.linspace(0, np.pi, rings + 1)[1:-1]
ph = np.linspace(0, 2 * np.pi, segs, endpoint=False)
v = [(0, 0, 1)] + [(np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)) for t in th for p in ph] + [(0, 0, -1)]
v = np.array(v)
f = []
ring = lambda r, s: 1 + r * segs + s % segs
for s in range(segs):
    f.append((0, ring(0, s), ring(0, s + 1)))
    f.append((len(v) - 1, ring(rings - 2, s + 1), ring(rings - 2, s)))
for r in range(rings - 2):
    for s in range(segs):
        a, b, c, d = ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1)
        f += [(a, c, b), (b, c, d)]
os.makedirs("data/blob", exist_ok=True)
for t in range(30):
    a = 0.15 * t
    rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    w = v * np.array([1 + 0.3 * np.sin(0.4 * t), 1, 1 - 0.2 * np.sin(0.3 * t)])
    w = 3 * w @ rot.T + np.array([5 + 0.1 * t, -2, 1 + 0.05 * t * t / 30])
    with open("data/blob/mesh_%04d.obj" % t, "w") as out:
        out.writelines("v %.6f %.6f %.6f\n" % tuple(p) for p in w)
        out.writelines("f %d %d %d\n" % (i + 1, j + 1, k + 1) for i, j, k in f)
PY

# config NAME NORMALIZATION RECON_FRAME STARTS [METHODS]
three='[ { "name": "oracle" }, { "name": "nearest" },
         { "name": "neupig", "params": { "preset": "tiny", "epochs": 20 } } ]'
config() {
    local methods=${5:-$three}
    cat > "$1.json" <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "protocol": "clips", "fit": "per_clip", "pool_size": 1000, "input_points": 300,
                  "input_normals": "gt", "recon_frame": "$3", "surface_samples": 3000 },
  "datasets": [ { "name": "toy", "source": "objdir", "root": "data", "normalization": "$2",
                  "sequences": [ { "name": "blob", "role": "test", "clip_starts": $4 } ] } ],
  "methods": $methods }
JSON
}
config box clip_bbox frame_box '[3, 11]'
config diag first_frame_diag sequence '[0]'

# 1. The grid: one cell per clip and method, priced, recorded clip by clip.
"$TCBENCH" run box.json --dry-run > dry.txt
grep -q '^toy/blob_0003: 17 frames, 178 vertices, 16 pairs$' dry.txt && grep -q '^toy/blob_0011: 17 frames' dry.txt ||
    { echo "FAIL: dry run"; cat dry.txt; exit 1; }
! grep -E '^ +[0-9]+ ' dry.txt | grep -q '?' || { echo "FAIL: an unpriced clip"; cat dry.txt; exit 1; }
"$TCBENCH" run box.json --out box --quiet
"$TCBENCH" run diag.json --out diag --quiet
/usr/bin/python3 - <<'PY'
import json
rec = json.load(open("box/config.json"))
seqs = rec["datasets"][0]["sequences"]
assert [(s["name"], s["clip_of"], s["start"]) for s in seqs] == [("blob_0003", "blob", 3), ("blob_0011", "blob", 11)], seqs
assert rec["evaluation"]["fit"] == "per_clip" and rec["evaluation"]["recon_frame"] == "frame_box", rec["evaluation"]
for clip in ("blob_0003", "blob_0011"):
    for m in ("oracle", "nearest", "neupig"):
        c = json.load(open("box/cells/toy/%s/%s/seed_0.json" % (clip, m)))
        assert c["status"] == "ok" and c["clips"]["n_clips"] == 1 and c["clips"]["rows"][0][0] == 0, c["clips"]
        assert c.get("normals") == ("gt" if m == "neupig" else None), (m, c.get("normals"))
    assert c["surface"]["frame"] == "frame_box" and len(c["surface"]["rows"]) == 17, c["surface"]
print("per-clip grid: 2 clips x 3 methods, each a 17-frame sequence")
PY
"$TCBENCH" report box --quiet
grep -q '^### toy / MEAN' box/report/tables.md && grep -q 'Corr-mesh ↓' box/report/tables.md &&
    grep -qxF 'Normals with the input points: neupig (gt); the other methods took points only.' box/report/tables.md ||
    { echo "FAIL: report"; cat box/report/tables.md; exit 1; }

# 2. Against numpy, following DynoSurf's evaluation/ (utils.py:
# eval_pointcloud, distance_p2p, eval_correspondences_mesh).
for run in box diag; do
    for clip in $(ls "$run/cells/toy"); do
        "$TCB_CLIP_DUMP" "$run" "toy/$clip" neupig "dump_${run}_$clip"
    done
done
/usr/bin/python3 - <<'PY'
import glob, json
import numpy as np
from scipy.spatial import cKDTree

def obj(path):
    return np.array([[float(x) for x in l.split()[1:4]] for l in open(path) if l.startswith("v ")])

raw = np.stack([obj("data/blob/mesh_%04d.obj" % t) for t in range(30)])

def their_frame(clip, mode):
    """The clip's normalization as Neu-PiG/PDG's and DynoSurf's code write it,
    on the GT vertices (docs/protocol.md, F1)."""
    if mode == "clip_bbox":      # src/utilities/util.py, scale_points
        lo, hi = clip.reshape(-1, 3).min(0), clip.reshape(-1, 3).max(0)
        return (clip - (hi + lo) / 2) / ((hi - lo).max() / 2) * 0.95
    lo, hi = clip[0].min(0), clip[0].max(0)       # code/dataset.py, normalize_seq
    return (clip - clip[0].mean(0)) / np.linalg.norm(hi - lo)

def distance_p2p(src, n_src, tgt, n_tgt):
    d, idx = cKDTree(tgt).query(src)
    n_src = n_src / np.linalg.norm(n_src, axis=-1, keepdims=True)
    n_tgt = n_tgt / np.linalg.norm(n_tgt, axis=-1, keepdims=True)
    return d, np.abs((n_tgt[idx] * n_src).sum(-1))

def eval_pointcloud(pred, gt, n_pred, n_gt):
    comp, comp_n = distance_p2p(gt, n_gt, pred, n_pred)
    acc, acc_n = distance_p2p(pred, n_pred, gt, n_gt)
    t = np.linspace(1.0 / 1000, 1, 1000)
    rec = np.array([(comp <= x).mean() for x in t[[4, 9]]])
    prec = np.array([(acc <= x).mean() for x in t[[4, 9]]])
    f = np.where(prec + rec > 0, 2 * prec * rec / np.maximum(prec + rec, 1e-300), 0.0)
    return {"cdl2": 0.5 * ((comp ** 2).mean() + (acc ** 2).mean()),
            "nc": 0.5 * comp_n.mean() + 0.5 * acc_n.mean(), "fscore05": f[0], "fscore1": f[1]}

def on_faces(pts, verts, faces, tol):
    """Every point lies on some face of the mesh (its nearest face's plane,
    within its triangle): the samples are of this surface in this frame."""
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    cen = (a + b + c) / 3
    _, near = cKDTree(cen).query(pts, k=min(12, len(faces)))
    best = np.full(len(pts), np.inf)
    for k in range(near.shape[1]):
        fa, fb, fc = a[near[:, k]], b[near[:, k]], c[near[:, k]]
        n = np.cross(fb - fa, fc - fa)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        best = np.minimum(best, np.abs(((pts - fa) * n).sum(1)))
    assert best.max() < tol, best.max()

checked = 0
for d in sorted(glob.glob("dump_*")):
    run, clip = d.split("_", 2)[1], d.split("_", 2)[2]
    mode = {"box": "clip_bbox", "diag": "first_frame_diag"}[run]
    meta = json.load(open(d + "/meta.json"))
    F, nv, n, sv = meta["frames"], meta["nv"], meta["n"], meta["sv"]
    f32 = lambda name, shape: np.fromfile(d + "/" + name, dtype="<f4").reshape(shape).astype(np.float64)
    faces = np.fromfile(d + "/faces.bin", dtype="<i4").reshape(-1, 3)
    sfaces = np.fromfile(d + "/surf_faces.bin", dtype="<i4").reshape(-1, 3)
    gt = f32("gt_verts.bin", (F, nv, 3))
    start = int(clip.split("_")[1])
    want = their_frame(raw[start:start + 17], mode)
    assert np.abs(gt - want).max() < 1e-5, ("normalization", d, np.abs(gt - want).max())
    cell = json.load(open("%s/cells/toy/%s/neupig/seed_0.json" % (run, clip)))
    rows = {r[0]: r[1:] for r in cell["surface"]["rows"]}
    keys = cell["surface"]["columns"][1:]
    surf = f32("surf_verts.bin", (F, sv, 3))
    pred, pred_n = f32("pred.bin", (F, n, 3)), f32("pred_n.bin", (F, n, 3))
    gts, gts_n = f32("gt.bin", (F, n, 3)), f32("gt_n.bin", (F, n, 3))
    box = np.fromfile(d + "/box.bin", dtype="<f8").reshape(F, 4)
    for t in range(F):
        g = gt[t]
        if meta["recon_frame"] == "frame_box":
            # Neu-PiG's eval_utils.py: get_loc_scale of the frame's GT mesh, (v - loc) / scale
            lo, hi = g.min(0), g.max(0)
            loc, scale = (lo + hi) / 2, (hi - lo).max()
            assert np.allclose(box[t, :3], loc, rtol=0, atol=1e-12) and abs(box[t, 3] * scale - 1) < 1e-12, box[t]
            g, s = (g - loc) / scale, (surf[t] - loc) / scale
        else:
            assert (box[t] == [0, 0, 0, 1]).all(), box[t]
            s = surf[t]
        on_faces(gts[t], g, faces, 1e-5)
        on_faces(pred[t], s, sfaces, 1e-5)
        got = eval_pointcloud(pred[t], gts[t], pred_n[t], gts_n[t])
        for k, v in zip(keys, rows[t]):
            assert abs(v - got[k]) <= 1e-6 * max(abs(got[k]), 1e-12), (d, t, k, v, got[k])
        checked += 1
    # eval_correspondences_mesh: frame-0 vertices to their nearest GT point,
    # followed through frames 1-16, mean un-squared distance, mean over frames
    ind = cKDTree(gt[0]).query(surf[0])[1]
    corr = np.mean([np.linalg.norm(surf[t] - gt[t][ind], axis=-1).mean() for t in range(1, F)])
    got = cell["clips"]["rows"][0][3]
    assert cell["clips"]["columns"] == ["start", "corr", "err", "corr_mesh"], cell["clips"]["columns"]
    assert abs(got - corr) <= 1e-9 * corr, (d, got, corr)
print("clip metrics equal numpy following DynoSurf on %d frames (clip_bbox and first_frame_diag, "
      "frame_box and sequence frames), Corr-mesh on %d clips" % (checked, len(glob.glob("dump_*"))))
PY

# 3. A per-clip cell killed mid-fit resumes bit-identically.
config long clip_bbox frame_box '[3]' \
    '[ { "name": "neupig", "params": { "preset": "tiny", "epochs": 80, "checkpoint_every": 2 } } ]'
"$TCBENCH" run long.json --out whole --quiet
kill_mid_fit long.json work/toy/blob_0003/neupig/seed_0 cells/toy/blob_0003/neupig/seed_0.json
same_cells whole killed

# 4. Refusals: one line naming the key or the clip, exit 2.
sed 's/"fit": "per_clip"/"fit": "per_clip", "pairs": 10/; s/"protocol": "clips"/"protocol": ["pairs", "clips"]/' \
    box.json > bad.json
expect 2 'bad.json: evaluation.fit: per_clip needs "protocol": "clips" alone' "$TCBENCH" run bad.json
sed 's/"fit": "per_clip", //' box.json > bad.json
expect 2 'bad.json: datasets[0].sequences[0].clip_starts: clips of a sequence are fitted on their own only under' \
    "$TCBENCH" run bad.json
config bad clip_bbox frame_box '[3, 3]'
expect 2 "bad.json: datasets[0].sequences[0].clip_starts: duplicate sequence 'blob_0003'" "$TCBENCH" run bad.json
config bad clip_bbox frame_box '[20]'
expect 2 'dataset toy, sequence blob_0020: sequence blob has 30 frames: no frames 20-36 to cut blob_0020 from' \
    "$TCBENCH" run bad.json --out bad
config bad clip_bbox frame_box '[3]'
sed -i 's/, "clip_starts": \[3\]//' bad.json
expect 2 'dataset toy, sequence blob: fitted per clip, a sequence is one clip of 17 frames, this one has 30' \
    "$TCBENCH" run bad.json --out bad
sed 's/"normalization": "clip_bbox"/"normalization": "unit"/' box.json > bad.json
expect 2 'bad.json: datasets[0].normalization' "$TCBENCH" run bad.json
sed 's/"recon_frame": "frame_box"/"recon_frame": "box"/' box.json > bad.json
expect 2 'bad.json: evaluation.recon_frame' "$TCBENCH" run bad.json
sed 's/"input_normals": "gt"/"input_normals": "yes"/' box.json > bad.json
expect 2 'bad.json: evaluation.input_normals' "$TCBENCH" run bad.json
echo "ok"

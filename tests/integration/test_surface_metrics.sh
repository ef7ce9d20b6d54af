#!/usr/bin/env bash
# The reconstruction metrics (CD-L2, NC, F-score at 0.5 % and 1 %;
# docs/protocol.md, "Reconstruction metrics"):
# 1. on 30 000 samples of two frames of a synthetic sequence they equal
#    numpy/scipy's computation (cKDTree, float64) on the same samples to
#    1e-6 relative, every sample lies on the face it was drawn from with
#    that face's unit normal, and faces are drawn by area;
# 2. two identical meshes sampled from the same stream: CD-L2 0, NC 1, F 1;
# 3. in a run, a method with surfaces (mca) has one row per frame of its
#    pairs, a summary that is their mean, the same numbers when run again,
#    and results.csv columns in table units; `nearest` (no surface) has none
#    and "-"; compare pairs them over the frames; a bad
#    evaluation.surface_samples is refused in one line naming the key.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SURFACE_DUMP:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

"$TCB_SURFACE_DUMP" 30000 7 0 3 two
"$TCB_SURFACE_DUMP" 2000 7 3 3 same
/usr/bin/python3 - two same <<'PY'
import json, sys
import numpy as np
from scipy.spatial import cKDTree

def load(d):
    m = json.load(open(d + "/metrics.json"))
    n, nv, nf, nfr = m["n"], m["nv"], m["nf"], m["frames"]
    f32 = lambda name, shape: np.fromfile(d + "/" + name, dtype="<f4").reshape(shape)
    i32 = lambda name, shape: np.fromfile(d + "/" + name, dtype="<i4").reshape(shape)
    s = {k: f32(k + ".bin", (n, 3)).astype(np.float64) for k in ("pred", "pred_n", "gt", "gt_n")}
    s.update(pred_face=i32("pred_face.bin", (n,)), gt_face=i32("gt_face.bin", (n,)))
    return m, s, f32("verts.bin", (nfr, nv, 3)).astype(np.float64), i32("faces.bin", (nf, 3))

def metrics(p, pn, g, gn):
    # DynoSurf's eval_pointcloud: completeness from GT, accuracy from the prediction
    comp, ci = cKDTree(p).query(g)
    acc, ai = cKDTree(g).query(p)
    unit = lambda x: x / np.linalg.norm(x, axis=1, keepdims=True)
    pn, gn = unit(pn), unit(gn)
    comp_nc = np.abs((gn * pn[ci]).sum(1)).mean()
    acc_nc = np.abs((pn * gn[ai]).sum(1)).mean()
    out = {"cdl2": 0.5 * ((comp ** 2).mean() + (acc ** 2).mean()), "nc": 0.5 * (comp_nc + acc_nc)}
    for key, t in (("fscore05", 0.005), ("fscore1", 0.01)):
        P, R = (acc <= t).mean(), (comp <= t).mean()
        out[key] = 2 * P * R / (P + R) if P + R > 0 else 0.0
    return out

def check_samples(pts, nrm, face, verts, faces):
    a, b, c = (verts[faces[face, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    # on the face's plane and inside it (barycentrics of the point)
    assert np.abs(((pts - a) * cross).sum(1)).max() < 1e-6 * np.abs(cross).max(), "off the plane"
    v0, v1, v2 = b - a, c - a, pts - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
    den = d00 * d11 - d01 * d01
    u, v = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    assert (u > -1e-4).all() and (v > -1e-4).all() and (u + v < 1 + 1e-4).all(), "outside its face"
    want = cross / np.linalg.norm(cross, axis=1, keepdims=True)
    assert np.abs(nrm - want).max() < 1e-6, np.abs(nrm - want).max()
    # faces drawn by area: each tenth of the faces gets its share of the area
    area = 0.5 * np.linalg.norm(np.cross(verts[faces[:, 1]] - verts[faces[:, 0]],
                                         verts[faces[:, 2]] - verts[faces[:, 0]]), axis=1)
    groups = np.arange(len(faces)) * 10 // len(faces)
    got = np.bincount(groups[face], minlength=10) / len(face)
    share = np.bincount(groups, weights=area, minlength=10) / area.sum()
    assert np.abs(got - share).max() < 0.01, (got, share)

m, s, verts, faces = load(sys.argv[1])
check_samples(s["pred"], s["pred_n"], s["pred_face"], verts[0], faces)
check_samples(s["gt"], s["gt_n"], s["gt_face"], verts[3], faces)
want = metrics(s["pred"], s["pred_n"], s["gt"], s["gt_n"])
for k, v in want.items():
    assert abs(m[k] - v) <= 1e-6 * abs(v), (k, m[k], v)
assert 0 < want["fscore05"] < want["fscore1"] < 1, want   # the thresholds are not trivial here
print("surface metrics equal scipy on %d samples: %s" % (m["n"], {k: "%.6g" % v for k, v in want.items()}))

m, s, _, _ = load(sys.argv[2])
assert (s["pred"] == s["gt"]).all()
assert m["cdl2"] == 0 and abs(m["nc"] - 1) < 1e-7 and m["fscore05"] == 1 and m["fscore1"] == 1, m
print("identical meshes: CD-L2 0, NC 1, F-score 1")
PY

write_config() {  # NAME SURFACE_SAMPLES
    cat > "$1.json" <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 1000, "input_points": 300, "surface_samples": $2 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 8,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 60 } },
               { "name": "mca_short", "method": "mca", "params": { "preset": "tiny", "iterations": 20 } } ] }
JSON
}

write_config bad 0
if "$TCBENCH" run bad.json --out bad --quiet 2> bad.log; then echo "FAIL: surface_samples 0 accepted"; exit 1; else rc=$?; fi
[ "$rc" -eq 2 ] && [ "$(wc -l < bad.log)" -eq 1 ] && grep -q "evaluation.surface_samples" bad.log && [ ! -e bad ] ||
    { echo "FAIL: rc $rc, or not one line naming the key:"; cat bad.log; exit 1; }

write_config s 1500
"$TCBENCH" run s.json --out run --quiet --report 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" run s.json --out again --quiet 2> /dev/null
"$TCBENCH" compare run mca mca_short > compare.txt
/usr/bin/python3 - <<'PY'
import csv, json
import numpy as np
cell = lambda run, m: json.load(open("%s/cells/synth/quadruped_walk/%s/seed_0.json" % (run, m)))
keys = ["cdl2", "nc", "fscore05", "fscore1"]
c = cell("run", "mca")
frames = sorted({f for p in c["pairs"] for f in p[:2]})
surf = c["surface"]
assert surf["samples"] == 1500 and surf["columns"] == ["frame"] + keys, surf
rows = np.array(surf["rows"], dtype=float)
assert rows[:, 0].tolist() == frames, (rows[:, 0], frames)
for k, key in enumerate(keys, 1):
    st = c["summary"][key]
    x = rows[:, k]
    assert st["n"] == len(frames) and abs(st["mean"] - x.mean()) <= 1e-12 * abs(x.mean()) + 1e-300, (key, st)
    assert abs(st["m2"] - ((x - x.mean()) ** 2).sum()) <= 1e-9 * max(st["m2"], 1e-30), (key, st)
assert (rows[:, 1] > 0).all() and (rows[:, 2:] >= 0).all() and (rows[:, 2:] <= 1).all(), rows
assert cell("again", "mca")["surface"] == surf, "not reproducible"
assert "faces" not in c, "a sequence with faces said to have none"
n = cell("run", "nearest")
assert "surface" not in n and not any(k in n["summary"] for k in keys), n["summary"].keys()
table = {r["method"]: r for r in csv.DictReader(open("run/report/results.csv")) if r["sequence"] != "MEAN"}
scale = {"cdl2": (1e5, 2), "nc": (1e2, 2), "fscore05": (1e2, 2), "fscore1": (1e2, 2)}
for key, (f, d) in scale.items():
    col = "%s_%s_mean" % (key, "x1e5" if f == 1e5 else "pct")
    assert table["mca"][col] == "%.*f" % (d, c["summary"][key]["mean"] * f), (col, table["mca"][col])
    assert table["nearest"][col] == "", (col, table["nearest"][col])
# compare: the frames are the units, A - B is the difference of their means
short = np.array(cell("run", "mca_short")["surface"]["rows"], dtype=float)
text = open("compare.txt").read()
assert "paired over the %d evaluated frames" % len(frames) in text, text
line = next(l for l in text.splitlines() if l.startswith("CD-L2 ×1e5"))
diff = float(line.split()[4])
assert abs(diff - (rows[:, 1] - short[:, 1]).mean() * 1e5) < 1e-3, (line, (rows[:, 1] - short[:, 1]).mean() * 1e5)
print("run: %d frames scored for mca, none for nearest; reproducible; results.csv and compare agree" % len(frames))
PY
grep -E '^\| nearest \|' run/report/tables.md | grep -qE '\| - \| - \| - \| - \|$' ||
    { echo "FAIL: nearest's reconstruction columns are not -"; cat run/report/tables.md; exit 1; }
! grep -q "Not applicable" run/report/tables.md || { echo "FAIL: metrics of a mesh called not applicable"; exit 1; }
echo "surface metrics test passed"

#!/usr/bin/env bash
# Occupancy Flow's point-cloud sequences ("source": "pcl_seq",
# docs/datasets.md): frames this test writes as Occupancy Flow's
# scripts/sample_mesh.py does (points float16 normalised by the frame's
# box, loc, scale) read back in world coordinates — nearest's Corr equals
# numpy's from the files — with the metrics that need faces left out
# (no m_geo, no CD-L2 rows) and nricp, neupig and mca running on points
# alone, inspect and frames drawing the points; bad folders (a missing
# frame, a truncated npz, NaN points,
# another point count, a missing array) are one error naming the file,
# exit 2. With ../shared/data, the real D-FAUST clip the same way.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"
enter_temp_dir

/usr/bin/python3 - <<'PY'
import os
import numpy as np
# 600 points on a wobbling, drifting ellipsoid, 20 frames numbered from 40
rng = np.random.default_rng(3)
d = rng.normal(size=(600, 3))
d /= np.linalg.norm(d, axis=1, keepdims=True)
os.makedirs("pts/blob/pcl_seq")
for t in range(20):
    w = d * np.array([1 + 0.2 * np.sin(0.3 * t), 0.6, 0.4]) + np.array([0.05 * t, 1.0, -0.3])
    lo, hi = w.min(0), w.max(0)
    loc, scale = (lo + hi) / 2, (hi - lo).max()
    np.savez("pts/blob/pcl_seq/%08d.npz" % (40 + t), points=((w - loc) / scale).astype(np.float16),
             loc=loc.astype(np.float16), scale=np.float64(scale))
PY

cat > pts.json <<'JSON'
{ "name": "pts", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "protocol": ["pairs", "clips"], "pairs": 12, "clips": 2, "pool_size": 500, "input_points": 200,
                  "surface_samples": 1000 },
  "datasets": [ { "name": "toy", "source": "pcl_seq", "root": "pts", "points": 0,
                  "sequences": [ { "name": "blob", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" }, { "name": "nricp", "params": { "strategy": "random" } },
               { "name": "neupig", "params": { "preset": "tiny", "epochs": 10 } },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 60 } } ] }
JSON
"$TCBENCH" run pts.json --dry-run > dry.txt
grep -q '^toy/blob: 20 frames, 600 vertices' dry.txt || { echo "FAIL: dry run"; cat dry.txt; exit 1; }
"$TCBENCH" run pts.json --out run --quiet
"$TCBENCH" report run --quiet
/usr/bin/python3 - <<'PY'
import glob, json
import numpy as np
def world(path):
    z = np.load(path)
    return z["loc"].astype(np.float64) + z["scale"] * z["points"].astype(np.float64)
frames = np.stack([world(p) for p in sorted(glob.glob("pts/blob/pcl_seq/*.npz"))])
for m in ("nearest", "nricp", "neupig", "mca"):
    c = json.load(open("run/cells/toy/blob/%s/seed_0.json" % m))
    assert c["status"] == "ok", (m, c["message"])
    assert c["summary"]["geo"]["n"] == 0 and "surface" not in c, (m, "a metric that needs faces")
    assert c["faces"] is False, (m, "a faceless sequence not said so")
    assert all(p[11] is None for p in c["pairs"]), (m, "a geodesic error per pair")
    assert c["summary"]["sl2"]["n"] > 0 and c["summary"]["corr"]["n"] == 2, m
c = json.load(open("run/cells/toy/blob/nearest/seed_0.json"))
for start, corr, err in (r[:3] for r in c["clips"]["rows"]):
    # nearest carries each point unmoved: its error is how far the point moves
    want = [np.linalg.norm(frames[start + t] - frames[start], axis=1).mean() for t in range(1, 17)]
    assert np.allclose(err, want, rtol=1e-6, atol=0), (start, err[:3], want[:3])
    assert abs(corr - np.mean(want)) <= 1e-6 * np.mean(want)
head = [l for l in open("run/report/tables.md") if l.startswith("| method |")][0]
assert "m_geo" not in head and "CD-L2" not in head and "Corr ↓" in head, head
md = open("run/report/tables.md").read()
na = "Not applicable: the geodesic error (m_geo, AUC_geo) and the reconstruction metrics (CD-L2, NC, F-score): "
assert md.count(na + "the sequence has no faces") == 1 and md.count(na + "the test sequences have no faces") == 1, md
print("pcl_seq: world coordinates as numpy reads them; no metric that needs faces")
PY

# Pictures of points alone: dots instead of faces.
"$TCBENCH" inspect run nricp 0 --out insp --quiet > /dev/null
"$TCBENCH" frames run nearest --frames 0,5 --out strip --quiet > /dev/null
[ -s insp/pair.png ] && [ -s strip/strip.png ] || { echo "FAIL: no pictures"; exit 1; }

# Bad folders: one error naming the file, exit 2.
one() { sed 's/"root": "pts"/"root": "bad"/' pts.json > bad.json; rm -rf bad && cp -r pts bad; }
one; rm bad/blob/pcl_seq/00000045.npz
expect 2 'bad/blob/pcl_seq: frame 00000045 is missing (between 00000044.npz and 00000046.npz)' "$TCBENCH" run bad.json --out b1
one; truncate -s 300 bad/blob/pcl_seq/00000043.npz
expect 2 'bad/blob/pcl_seq/00000043.npz: ' "$TCBENCH" run bad.json --out b2
one; /usr/bin/python3 -c "
import numpy as np
z = dict(np.load('bad/blob/pcl_seq/00000050.npz')); z['points'][7, 2] = np.nan
np.savez('bad/blob/pcl_seq/00000050.npz', **z)"
expect 2 'bad/blob/pcl_seq/00000050.npz: points: point 7 has coordinate nan' "$TCBENCH" run bad.json --out b3
one; /usr/bin/python3 -c "
import numpy as np
z = dict(np.load('bad/blob/pcl_seq/00000052.npz')); z['points'] = z['points'][:-1]
np.savez('bad/blob/pcl_seq/00000052.npz', **z)"
expect 2 'bad/blob/pcl_seq/00000052.npz: points: (599, 3), but the first frame has 600 points' "$TCBENCH" run bad.json --out b4
one; /usr/bin/python3 -c "
import numpy as np
z = dict(np.load('bad/blob/pcl_seq/00000041.npz')); del z['scale']
np.savez('bad/blob/pcl_seq/00000041.npz', **z)"
expect 2 "bad/blob/pcl_seq/00000041.npz: no array 'scale'" "$TCBENCH" run bad.json --out b5
for r in b1 b2 b3 b4 b5; do
    [ -z "$(find "$r" -name 'seed_*.json' 2>/dev/null)" ] || { echo "FAIL: $r wrote a cell"; exit 1; }
done

# The real D-FAUST clip (../shared/data/oflow_dfaust): every one of its
# 100 000 points, clips alone (no rank metric over 10^10 distances).
real=$TCB_SOURCE_DIR/../shared/data/oflow_dfaust
if [ -d "$real/50002_light_hopping_loose/pcl_seq" ]; then
    cat > real.json <<JSON
{ "name": "real", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "protocol": "clips", "pool_size": 5000, "input_points": 2500 },
  "datasets": [ { "name": "dfaust", "source": "pcl_seq", "root": "$real", "points": 0,
                  "sequences": [ { "name": "50002_light_hopping_loose", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" } ] }
JSON
    "$TCBENCH" run real.json --out real --quiet
    /usr/bin/python3 - "$real" <<'PY'
import glob, json, sys
import numpy as np
def world(path):
    z = np.load(path)
    return z["loc"].astype(np.float64) + z["scale"] * z["points"].astype(np.float64)
frames = np.stack([world(p) for p in sorted(glob.glob(sys.argv[1] + "/50002_light_hopping_loose/pcl_seq/*.npz"))])
c = json.load(open("real/cells/dfaust/50002_light_hopping_loose/nearest/seed_0.json"))
(start, corr, err), = (r[:3] for r in c["clips"]["rows"])
want = [np.linalg.norm(frames[start + t] - frames[start], axis=1).mean() for t in range(1, 17)]
assert np.allclose(err, want, rtol=1e-6, atol=0), (err[:3], want[:3])
print("the real D-FAUST clip: 17 frames of %d points, nearest's Corr %.4f as numpy's" % (frames.shape[1], corr))
PY
else
    echo "SKIP (part): $real absent"
fi
echo "ok"

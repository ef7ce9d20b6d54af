#!/usr/bin/env bash
# tcbench.Evaluator (python/tcbench/evaluate.py) against `tcbench score` and
# a method's own cell, to the last bit: nearest computed in numpy (ids by
# argmin, as python/README.md shows, and its points: frame i's vertices),
# given as a dict, a list, an .npz and a directory, scores exactly as
# nearest's cell, geodesic metrics included, and as `tcbench score` on the
# same .npz; write_cell writes the cell report and check read. The wrong
# frame: raw coordinates (the split's normalisation undone) are refused by
# both, saying the normalisation and how to apply it, and scored with
# any_frame / --any-frame; normalised but bad points (a diverged method's
# shape, every point collapsed to the centroid) are not refused. The cat
# (centimetres) too, when ../shared/data has it. Skipped when
# /usr/bin/python3 has no numpy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"
. "$(dirname "${BASH_SOURCE[0]}")/python_env.sh"
cat_data=${TCB_SHARED_DATA:-$TCB_SOURCE_DIR/../shared/data}/anim

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# The synthetic sequence normalised as configs/quick.json normalises it (a
# test sequence there); the cat when its data is here.
cat_dataset=""
if [ -d "$cat_data/cat_walk" ]; then
    cat_dataset=', { "name": "anim", "source": "objdir", "root": "'"$cat_data"'", "normalization": "first_frame",
                    "sequences": [ { "name": "cat_walk", "role": "validation" } ] }'
fi
cat > ev.json <<JSON
{ "name": "ev", "output": "runs/ev", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 12, "pool_size": 500, "input_points": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12, "normalization": "first_frame",
                  "sequences": [ { "name": "quadruped_trot", "role": "test" } ] }$cat_dataset ],
  "methods": [ { "name": "nearest" } ] }
JSON
"$TCBENCH" run ev.json --quiet 2> run.log || { cat run.log; exit 1; }

py - <<'PY'
import os
import numpy as np
import tcbench
from pychecks import raises, same

ev = tcbench.Evaluator("ev.json", "synth", "quadruped_trot")
assert ev.pairs.shape == (12, 2) and ev.pairs.dtype == np.int32
assert ev.split["path"] == "splits/synth/quadruped_trot.json" and ev.split["role"] == "test"
assert np.array_equal(ev.pairs, tcbench.load_split("splits/synth/quadruped_trot.json")["pairs"])
verts = ev.sequence["verts"]
assert ev.sequence["normalization"] == "first_frame" and verts.shape[0] == 12
same(verts, tcbench.load_sequence("ev.json", "synth", "quadruped_trot")["verts"])

# nearest in numpy as python/README.md has it: frame i's vertices, and the
# nearest vertex of frame j to each, in float32 as the C search measures
# (float64 distances break a few near-ties the other way)
def nearest_ids(a, b):
    return np.concatenate([((a[s:s + 512, None, :] - b[None]) ** 2).sum(-1).argmin(1)
                           for s in range(0, len(a), 512)])
ids = {k: nearest_ids(verts[i], verts[j]) for k, (i, j) in enumerate(ev.pairs)}
points = [verts[i] for i, j in ev.pairs]

ref = tcbench.read_cell("runs/ev/cells/synth/quadruped_trot/nearest/seed_0.json")
for how, pred in [("ids dict", ids), ("points list", points),
                  ("str keys", {str(k): v for k, v in ids.items()}), ("array", np.stack(points))]:
    r = ev.evaluate(pred)
    same(r["summary"], ref["summary"], how)
    same(r["pairs"], ref["pairs"], how)
    assert r["pair_columns"] == ref["pair_columns"] and r["params"] == {"pred": "memory"}, how
    assert r["summary"]["geo"]["n"] == 12 * verts.shape[1] and r["summary"]["geo_auc"]["n"] == 12, how
assert np.array_equal(r["rows"]["sl2"], r["pairs"][:, r["pair_columns"].index("sl2")])
assert r["rows"]["geo_auc"].shape == (12,) and (r["rows"]["geo"] > 0).all()

# one results file: the .npz tcbench score reads, and its directory
np.savez("nearest.npz", **{str(k): v.astype(np.int32) for k, v in ids.items()})
os.makedirs("nearest_dir")
for k, p in enumerate(points):
    np.save(f"nearest_dir/{k}.npy", p)
for path in ("nearest.npz", "nearest_dir"):
    r = ev.evaluate(path)
    same(r["summary"], ref["summary"], path)
    same(r["pairs"], ref["pairs"], path)

# the cell, as tcbench score writes it: the last evaluation's
ev.evaluate(ids)
path = ev.write_cell("py_nearest")
assert path == "runs/ev/cells/synth/quadruped_trot/py_nearest/seed_0.json", path
cell = tcbench.read_cell(path)
same(cell["summary"], ref["summary"])
assert (cell["method"], cell["method_impl"], cell["seed"], cell["status"]) == ("py_nearest", "scored", 0, "ok")
raises(tcbench.TcbError, "py_nearest/seed_0.json exists: --force replaces it", ev.write_cell, "py_nearest")
raises(tcbench.TcbError, "has a method labelled 'nearest'", ev.write_cell, "nearest")
assert ev.write_cell("py_nearest", seed=1).endswith("py_nearest/seed_1.json")

# ---- the wrong frame: raw coordinates refused, with the way to normalise
shift, scale = ev.sequence["norm_shift"], ev.sequence["norm_scale"]
raw = [verts[i].astype(np.float64) * scale + shift[j] for i, j in ev.pairs]
np.savez_compressed("raw.npz", **{str(k): p for k, p in enumerate(raw)})
msg = str(raises(tcbench.TcbError, 'Its frames are normalised (normalization "first_frame"): x = (x_raw - norm_shift[j]) / norm_scale',
             ev.evaluate, raw))
assert msg.startswith("predictions[0]: pair 0, target frame %d: " % ev.pairs[0][1]), msg
assert "norm_scale = %.9g" % scale in msg and "any_frame=True" in msg, msg
raises(RuntimeError, "write_cell: nothing evaluated yet", ev.write_cell, "after_refusal")
bad = ev.evaluate(raw, any_frame=True)["summary"]["sl2"]["mean"]
assert bad > 5 * ref["summary"]["sl2"]["mean"], bad
# undone as the message says, they are nearest's points again (to float32 rounding)
back = [((p - shift[j]) / scale).astype(np.float32) for p, (i, j) in zip(raw, ev.pairs)]
assert ev.evaluate(back)["summary"]["sl2"]["mean"] < 1.01 * ref["summary"]["sl2"]["mean"]

# normalised but bad: blown up threefold with noise, or every point at frame j's centroid
rng = np.random.default_rng(3)
blown = [3 * verts[i] + rng.normal(0, 0.05, verts[i].shape).astype(np.float32) for i, j in ev.pairs]
assert ev.evaluate(blown)["summary"]["sl2"]["mean"] > 2 * ref["summary"]["sl2"]["mean"]
centre = [np.repeat(verts[j].mean(0, keepdims=True), len(verts[j]), 0) for i, j in ev.pairs]
assert ev.evaluate(centre)["summary"]["sl2"]["mean"] > 2 * ref["summary"]["sl2"]["mean"]

# ---- errors before the library is called
raises(ValueError, "predictions: 3 arrays for the 12 pairs of the split", ev.evaluate, points[:3])
raises(ValueError, "predictions: no prediction for pair 5 (of 0 to 11)", ev.evaluate,
       {k: v for k, v in ids.items() if k != 5})
raises(ValueError, "predictions: key 12: the split has 12 pairs (0 to 11)", ev.evaluate, {**ids, 12: ids[0]})
raises(ValueError, "predictions: key '05': keys are pair indices", ev.evaluate, {**ids, "05": ids[5]})
raises(ValueError, "predictions: keys 5 and '5' name the same pair", ev.evaluate, {**ids, "5": ids[5]})
raises(ValueError, "predictions[2]: Object arrays cannot be saved", ev.evaluate,
       [p if k != 2 else np.array([None] * 3) for k, p in enumerate(points)])
raises(tcbench.TcbError, "predictions[4]: dtype <f8: vertex ids (shape (", ev.evaluate,
       [p if k != 4 else np.zeros(len(p)) for k, p in enumerate(points)])
raises(tcbench.TcbError, "predictions[1]: element 0: vertex id -1 out of range", ev.evaluate,
       [v if k != 1 else -np.ones_like(v) for k, v in ids.items()])
raises(tcbench.TcbError, "nowhere.npz: no such file or directory", ev.evaluate, "nowhere.npz")
raises(tcbench.TcbError, "ev.json has no dataset named 'nope'", tcbench.Evaluator, "ev.json", "nope", "x")
e = tcbench.Evaluator("ev.json", "synth", "quadruped_trot")
raises(RuntimeError, "write_cell: nothing evaluated yet", e.write_cell, "x")
e.close()

# ---- the cat, in centimetres
if os.path.isdir("runs/ev/cells/anim"):
    cat = tcbench.Evaluator("ev.json", "anim", "cat_walk")
    v, sh, sc = cat.sequence["verts"], cat.sequence["norm_shift"], cat.sequence["norm_scale"]
    ok = cat.evaluate([v[i] for i, j in cat.pairs])
    same(ok["summary"], tcbench.read_cell("runs/ev/cells/anim/cat_walk/nearest/seed_0.json")["summary"], "cat")
    raises(tcbench.TcbError, "norm_scale = %.9g" % sc, cat.evaluate, [v[i] * sc + sh[j] for i, j in cat.pairs])
    np.savez("cat_raw.npz", **{str(k): v[i] * sc + sh[j] for k, (i, j) in enumerate(cat.pairs)})
    print("cat checked")
print("evaluator checks out")
PY

# ---- the CLI on the same files: the same numbers, the same refusal
score() { "$TCBENCH" score ev.json --dataset synth --sequence quadruped_trot "$@"; }
expect 0 "synth/quadruped_trot cli_nearest: 12 pairs" score --pred nearest.npz --name cli_nearest
expect 2 'raw.npz: 0.npy: pair 0, target frame' score --pred raw.npz --name cli_raw
grep -qF "the dataset's raw coordinates, not the split's frame. Its frames are normalised (normalization \"first_frame\")" err.txt ||
    { cat err.txt; exit 1; }
[ ! -e runs/ev/cells/synth/quadruped_trot/cli_raw ] || { echo "FAIL: a cell of raw points was written"; exit 1; }
expect 0 "cli_raw: 12 pairs" score --pred raw.npz --name cli_raw --any-frame
if [ -e cat_raw.npz ]; then
    expect 2 'cat_raw.npz: 0.npy: pair 0, target frame' \
        "$TCBENCH" score ev.json --dataset anim --sequence cat_walk --pred cat_raw.npz --name cli_raw
fi

py - <<'PY'
import numpy as np
import tcbench
cells = "runs/ev/cells/synth/quadruped_trot/"
a, b = tcbench.read_cell(cells + "cli_nearest/seed_0.json"), tcbench.read_cell(cells + "py_nearest/seed_0.json")
for c in (a, b):
    assert c["summary"] == tcbench.read_cell(cells + "nearest/seed_0.json")["summary"]
assert np.array_equal(a["pairs"].view(np.uint64), b["pairs"].view(np.uint64))
assert (a["params"], b["params"]) == ({"pred_file": "nearest.npz"}, {"pred": "memory"})
assert (a["message"], b["message"]) == ("scored from files", "scored from memory")
PY

# report and check see the Python row
expect 0 "" "$TCBENCH" report runs/ev --quiet
grep -q '^| py_nearest |' runs/ev/report/tables.md || { cat runs/ev/report/tables.md; exit 1; }
expect 0 "baseline written" "$TCBENCH" check runs/ev base.json --update
expect 0 "py_nearest" "$TCBENCH" check runs/ev base.json
echo "evaluator test passed"

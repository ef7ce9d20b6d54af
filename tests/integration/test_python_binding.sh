#!/usr/bin/env bash
# The Python binding (python/tcbench) against the CLI on the same inputs, to
# the last bit: read_cell gives every cell file's JSON (float bits compared);
# load_split the split files'; load_sequence the frames `tcbench datasets
# synth` writes, raw and normalized as the config says (the normalization
# repeated in numpy); pair_metrics, fed the predictions a cell was scored
# from (random ids through `tcbench score`, nearest's through `tcbench
# inspect`), each pair's row of the cell, the cell's mean PCK curve and
# inspect's per-vertex errors. Errors are the C library's messages. The
# package also imports from a fresh `cmake --install` prefix in an empty
# environment and from a source tree's build/, finding its library alone.
# Skipped when /usr/bin/python3 has no numpy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"
. "$(dirname "${BASH_SOURCE[0]}")/python_env.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# synth: the default normalization (first frame); raw: none, the OBJ files'
# coordinates as they are.
cat > py.json <<'JSON'
{ "name": "py", "output": "runs/py", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 10, "pool_size": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] },
                { "name": "raw", "source": "synthetic", "frames": 10, "normalization": "none",
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
"$TCBENCH" run py.json --quiet 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" datasets synth --out objs --sequence quadruped_walk --frames 10 2> /dev/null

# Predictions of every kind of error, scored by the CLI.
py - <<'PY'
import json, os
import numpy as np
pairs = json.load(open("splits/synth/quadruped_walk.json"))["pairs"]
rng = np.random.default_rng(7)
os.makedirs("rnd")
for k, (i, j) in enumerate(pairs):
    K = 2688
    ids = np.arange(K)
    kind = rng.integers(0, 3, K)
    ids = np.where(kind == 1, np.clip(ids + rng.integers(-30, 31, K), 0, K - 1), ids)
    ids = np.where(kind == 2, rng.integers(0, K, K), ids)
    np.save(f"rnd/{k}.npy", ids.astype(np.int64))
PY
expect 0 "rnd: 10 pairs" "$TCBENCH" score py.json --dataset synth --sequence quadruped_walk --pred rnd --name rnd
for k in 0 7; do
    "$TCBENCH" inspect runs/py nearest $k --sequence synth/quadruped_walk --out "inspect_$k" --quiet > /dev/null 2>> inspect.log
done

py - "$lib" <<'PY'
import csv, glob, json, math, os, sys
import numpy as np
import tcbench
from pychecks import raises, same

assert tcbench.library_path() == sys.argv[1], tcbench.library_path()

# ---- read_cell: the file's JSON, the pairs as a float array
cells = sorted(glob.glob("runs/py/cells/*/*/*/seed_0.json"))
assert len(cells) == 5, cells
for path in cells:
    cell, want = tcbench.read_cell(path), json.load(open(path))
    pairs = cell.pop("pairs")
    assert pairs.dtype == np.float64 and pairs.shape == (10, len(want["pair_columns"])), pairs.shape
    same([[None if math.isnan(x) else x for x in row] for row in pairs.tolist()], want.pop("pairs"), path)
    same(cell, want, path)

# ---- load_split
splits = {}
for path in sorted(glob.glob("splits/*/*.json")):
    split, want = tcbench.load_split(path), json.load(open(path))
    assert split["pairs"].dtype == np.int32 and split["pairs"].shape == (10, 2)
    assert split["pairs"].tolist() == want.pop("pairs"), path
    split.pop("pairs")
    same(split, want, path)
    splits[path.split("/")[1]] = tcbench.load_split(path)["pairs"]
assert len(splits) == 2

# ---- load_sequence: the OBJ frames, normalized as tcbench normalizes
def obj(f):
    lines = open("objs/quadruped_walk/mesh_%04d.obj" % f).read().split("\n")
    v = np.array([l.split()[1:] for l in lines if l.startswith("v ")], dtype=np.float32)
    t = np.array([l.split()[1:] for l in lines if l.startswith("f ")], dtype=np.int32) - 1
    return v, t
frames = np.stack([obj(f)[0] for f in range(10)])
bits = lambda a: a.view(np.uint32 if a.dtype == np.float32 else np.uint64)

raw = tcbench.load_sequence("py.json", "raw", "quadruped_walk")
assert (raw["name"], raw["n_frames"], raw["n_verts"], raw["normalization"]) == ("quadruped_walk", 10, 2688, "none")
assert raw["verts"].dtype == np.float32 and raw["verts"].shape == (10, 2688, 3)
assert np.array_equal(bits(raw["verts"]), bits(frames))
assert np.array_equal(raw["faces"], obj(0)[1]) and raw["faces"].dtype == np.int32
assert raw["norm_scale"] == 1.0 and not raw["norm_shift"].any() and raw["blocks"] == []

seq = tcbench.load_sequence("py.json", "synth", "quadruped_walk")
first = frames[0].astype(np.float64)
centre = np.cumsum(first, axis=0)[-1] / len(first)   # C's sum, in vertex order
scale = (first.max(0) - first.min(0)).max()
want = ((frames.astype(np.float64) - centre) / scale).astype(np.float32)
assert seq["normalization"] == "first_frame" and seq["norm_scale"] == scale
assert np.array_equal(bits(seq["norm_shift"]), bits(np.tile(centre, (10, 1))))
assert np.array_equal(bits(seq["verts"]), bits(want))
assert seq["pools"].shape == (10, 500, 3) and seq["areas"].shape == (10,) and "yaw" not in seq
assert (seq["pool_size"], seq["input_points"], seq["sampling"]) == (500, 2500, "without_replacement")

# ---- pair_metrics: each scored pair's row of its cell, bit for bit
def check_row(m, row, columns, at):
    for c, x in m["summary"].items():
        assert x.hex() == float(row[columns.index(c)]).hex(), (at, c, x, row[columns.index(c)])
    assert set(m["summary"]) == set(columns) - {"i", "j", "cd", "geo", "geo_m2", "geo_auc", "geo_unreachable"}, \
        m["summary"]
    assert m["m_sl2"] == m["summary"]["sl2"] and m["auc"] == m["summary"]["auc"]

cell = tcbench.read_cell("runs/py/cells/synth/quadruped_walk/rnd/seed_0.json")
columns = cell["pair_columns"]
pck_mean = np.zeros(100)
for k, (i, j) in enumerate(splits["synth"]):
    m = tcbench.pair_metrics(seq["verts"][j], np.load(f"rnd/{k}.npy"))
    assert (cell["pairs"][k, 0], cell["pairs"][k, 1]) == (i, j)
    check_row(m, cell["pairs"][k], columns, f"rnd pair {k}")
    e = seq["verts"][j][np.load(f"rnd/{k}.npy")].astype(np.float64) - seq["verts"][j]
    assert np.allclose(m["error"], np.sqrt((e * e).sum(1)), rtol=1e-15, atol=0)
    assert np.array_equal(m["error"], np.sqrt(m["sq_error"])) and m["error"].max() > 0.1
    assert 0 < m["rank"].mean() < 1 and np.array_equal(m["pck"][[0, -1]], [(m["sq_error"] == 0).mean(),
                                                                         (m["sq_error"] <= 0.02).mean()])
    pck_mean += (m["pck"] - pck_mean) * (1.0 / (k + 1))   # tcb_summary_merge, pair by pair
assert np.array_equal(bits(pck_mean), bits(np.array(cell["summary"]["pck"]))), "the cell's PCK curve"
assert m["pck_thresholds"][-1] == 0.02 and m["pck_thresholds"][0] == 0

# nearest's predictions as inspect wrote them: the cell's rows, inspect's errors
cell = tcbench.read_cell("runs/py/cells/synth/quadruped_walk/nearest/seed_0.json")
for k in (0, 7):
    rows = list(csv.DictReader(open(f"inspect_{k}/vertices.csv")))
    j = splits["synth"][k][1]
    m = tcbench.pair_metrics(seq["verts"][j], np.array([int(r["predicted"]) for r in rows]))
    check_row(m, cell["pairs"][k], columns, f"nearest pair {k}")
    assert [r["error"] for r in rows] == ["%.9g" % e for e in m["error"]], f"inspect_{k}/vertices.csv"

oracle = tcbench.pair_metrics(seq["verts"][3], np.arange(2688, dtype=np.uint16))
assert oracle["m_sl2"] == 0 and oracle["auc"] == 1 and not oracle["rank"].any()

# ---- errors: the C library's messages, or ValueError before the call
e = raises(tcbench.TcbError, "metrics: pred[5] = 2688 outside [0, 2688)", tcbench.pair_metrics,
           seq["verts"][0], np.where(np.arange(2688) == 5, 2688, 0))
assert e.code == "input"
raises(ValueError, "pred_ids[1] = 4294967296: outside [0, 2688)", tcbench.pair_metrics,
       seq["verts"][0], np.where(np.arange(2688) == 1, 2 ** 32, 0))
raises(ValueError, "vertex ids must be integers", tcbench.pair_metrics, seq["verts"][0], np.zeros(2688))
raises(ValueError, "expected (2688,)", tcbench.pair_metrics, seq["verts"][0], np.zeros(5, dtype=int))
raises(ValueError, "expected (K, 3)", tcbench.pair_metrics, seq["verts"][0][:, :2], np.zeros(5, dtype=int))
raises(ValueError, "values change as float32", tcbench.pair_metrics,
       seq["verts"][0].astype(np.float64) + 1e-12, np.zeros(2688, dtype=int))
same(tcbench.pair_metrics(seq["verts"][1].astype(np.float64), np.zeros(2688, dtype=int))["summary"],
     tcbench.pair_metrics(seq["verts"][1], np.zeros(2688, dtype=int))["summary"])

json.dump(dict(json.load(open(cells[0])), format="tcbench-cell/9"), open("bad_cell.json", "w"))
raises(tcbench.TcbError, 'bad_cell.json: format: "tcbench-cell/9" is not "tcbench-cell/1"', tcbench.read_cell,
       "bad_cell.json")
e = raises(tcbench.TcbError, "nowhere.json: cannot open", tcbench.load_split, "nowhere.json")
assert e.code == "io"
split = json.load(open("splits/synth/quadruped_walk.json"))
json.dump(dict(split, role="exam"), open("bad_split.json", "w"))
raises(tcbench.TcbError, 'bad_split.json.role: unknown role "exam"', tcbench.load_split, "bad_split.json")
raises(tcbench.TcbError, "py.json has no dataset named 'nope'", tcbench.load_sequence, "py.json", "nope", "x")
raises(tcbench.TcbError, "dataset synth of py.json has no sequence named 'nope'", tcbench.load_sequence,
       "py.json", "synth", "nope")
print("binding checks out")
PY

# The CLI says the same of the bad dataset (the message comes from one place).
expect 2 "--dataset: py.json has no dataset named 'nope'" \
    "$TCBENCH" score py.json --dataset nope --sequence quadruped_walk --pred rnd --name y

# ---- installed: a fresh prefix, an empty environment, the library found beside the package
cmake --install "$TCB_BUILD_DIR" --prefix "$tmp/prefix" > install.log
site="$tmp/prefix/lib/python3/dist-packages"
test -f "$site/tcbench/_installed.py" || { echo "no _installed.py"; cat install.log; exit 1; }
env -i PATH=/usr/bin:/bin "${sanitizer_env[@]}" PYTHONPATH="$site" /usr/bin/python3 - "$tmp/prefix" <<'PY'
import os, sys
import numpy as np
import tcbench
prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(tcbench.library_path()).startswith(prefix + "/lib/"), tcbench.library_path()
assert tcbench.__file__.startswith(prefix), tcbench.__file__
m = tcbench.pair_metrics(np.eye(3, dtype=np.float32), [1, 1, 2])
assert m["summary"]["n"] == 3 and m["rank"].tolist() == [1 / 3, 0.0, 0.0], m["rank"]
assert tcbench.read_cell("runs/py/cells/raw/quadruped_walk/oracle/seed_0.json")["status"] == "ok"
PY

# ---- a source tree: build/ beside python/, no TCBENCH_LIB
mkdir -p tree/python tree/build
cp -r "$TCB_SOURCE_DIR/python/tcbench" tree/python/
ln -s "$lib" tree/build/libtcbench.so
env -i PATH=/usr/bin:/bin "${sanitizer_env[@]}" PYTHONPATH=tree/python /usr/bin/python3 -c '
import os, tcbench
assert tcbench.library_path() == os.path.realpath("tree/build/libtcbench.so") or \
       tcbench.library_path().endswith("tree/build/libtcbench.so"), tcbench.library_path()'
rm tree/build/libtcbench.so
out=$(env -i PATH=/usr/bin:/bin "${sanitizer_env[@]}" PYTHONPATH=tree/python TCBENCH_LIB=/nowhere/libtcbench.so \
      /usr/bin/python3 -c 'import tcbench; tcbench.library_path()' 2>&1) && { echo "FAIL: loaded"; exit 1; }
grep -qF "TCBENCH_LIB: /nowhere/libtcbench.so (no such file)" <<< "$out" || { echo "$out"; exit 1; }
echo "python binding test passed"

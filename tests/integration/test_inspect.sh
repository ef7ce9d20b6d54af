#!/usr/bin/env bash
# `tcbench inspect` recomputes one evaluation pair exactly as the run did
# and writes it as coloured meshes. Checked here against what the files
# must contain, computed independently: the oracle's transfer carries every
# colour unchanged with zero error; `nearest`'s predictions equal a
# brute-force nearest-vertex search; a trained atlas method's recomputed
# pair equals its cell file's row bit for bit (same threads) and its
# reconstructions are written. Bad requests fail with the reason and leave
# no output directory.
set -euo pipefail
: "${TCBENCH:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
cat > inspect.json <<'JSON'
{ "name": "inspect", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1], "threads": 1,
  "evaluation": { "pairs": 6, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 6,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" },
               { "name": "atlasnet", "params": { "preset": "tiny", "iterations": 60 } } ] }
JSON
"$TCBENCH" run inspect.json --out run --quiet 2> run.log || { cat run.log; exit 1; }

"$TCBENCH" inspect run oracle 2 --out oracle --quiet > oracle.txt
"$TCBENCH" inspect run nearest 3 --out nearest --quiet > nearest.txt
"$TCBENCH" inspect run atlasnet worst --seed 1 --quiet > atlas.txt 2> atlas.log
grep -q "(agree: largest relative difference 0.0e+00)" oracle.txt || { cat oracle.txt; exit 1; }
grep -q "(agree: largest relative difference 0.0e+00)" atlas.txt || { cat atlas.txt; exit 1; }
atlas_dir=$(sed -n 's/^files: \(.*\)\/$/\1/p' atlas.log)
case "$atlas_dir" in run/inspect/synth/quadruped_walk/atlasnet/seed_1/pair_*) ;;
  *) echo "unexpected default directory '$atlas_dir'"; exit 1 ;; esac

/usr/bin/python3 - oracle nearest "$atlas_dir" run <<'PY'
import csv, json, sys
oracle, nearest, atlas, run = sys.argv[1:5]

def ply(path):
    """(vertices, colours, faces) of an ASCII PLY as tcbench writes it."""
    lines = open(path).read().split("\n")
    assert lines[0] == "ply" and lines[1] == "format ascii 1.0", path
    end = lines.index("end_header")
    nv = nf = 0
    for l in lines[:end]:
        if l.startswith("element vertex "): nv = int(l.split()[2])
        if l.startswith("element face "): nf = int(l.split()[2])
    rows = [l.split() for l in lines[end + 1:end + 1 + nv]]
    verts = [tuple(map(float, r[:3])) for r in rows]
    cols = [tuple(map(int, r[3:6])) for r in rows]
    faces = [tuple(map(int, l.split()[1:])) for l in lines[end + 1 + nv:end + 1 + nv + nf]]
    assert all(len(f) == 3 and max(f) < nv for f in faces), path
    return verts, cols, faces

def pair(d):
    return json.load(open(f"{d}/pair.json"))

# oracle: every vertex keeps its colour, no error, geodesic or not
p = pair(oracle)
assert p["recomputed"]["sl2"] == 0 and p["max_relative_difference"] == 0, p
assert p["recomputed"]["geo"] == 0 and p["recomputed"]["geo_auc"] == 1, p
assert p["recomputed"]["geo_unreachable"] == 0, p
assert all(float(r["geodesic"]) == 0 for r in csv.DictReader(open(f"{oracle}/vertices.csv")))
_, target, faces = ply(f"{oracle}/target.ply")
_, moved, _ = ply(f"{oracle}/transfer.ply")
assert moved == target and len(faces) > 0
_, err_col, _ = ply(f"{oracle}/error.ply")
assert set(err_col) == {(68, 1, 84)}, set(err_col)  # viridis(0) everywhere
assert not __import__("os").path.exists(f"{oracle}/recon_i.ply")

# nearest: the predictions equal a brute-force nearest-vertex search
p = pair(nearest)
src, _, _ = ply(f"{nearest}/source.ply")
dst, pos, _ = ply(f"{nearest}/target.ply")
rows = list(csv.DictReader(open(f"{nearest}/vertices.csv")))
assert len(rows) == len(src) == len(dst)
d2 = lambda a, b: sum((x - y) ** 2 for x, y in zip(a, b))
worst = 0
for k, (r, q) in enumerate(zip(rows, src)):
    best = min(d2(q, v) for v in dst)
    got = int(r["predicted"])
    assert d2(q, dst[got]) == best, (k, got)
    e = d2(dst[got], dst[k]) ** 0.5
    assert abs(float(r["error"]) - e) <= 1e-6 * max(1, e), (k, r["error"], e)
    worst = max(worst, e)
mean = sum(float(r["error"]) for r in rows) / len(rows)
assert abs(mean - p["recomputed"]["sl2"]) <= 1e-9 * max(mean, 1e-12), (mean, p)
_, moved, _ = ply(f"{nearest}/transfer.ply")
assert all(moved[k] == pos[int(r["predicted"])] for k, r in enumerate(rows))
assert worst > 0, "a nearest-vertex transfer between distinct frames is never exact"
# its geodesic error: 0 exactly where the prediction is right, never below
# the straight line (over the same sqrt(area)), averaging to the pair's m_geo
root = p["target_area"] ** 0.5
for k, r in enumerate(rows):
    g, e = float(r["geodesic"]), float(r["error"])
    assert (g == 0) == (int(r["predicted"]) == k), (k, r)
    assert g >= e / root * (1 - 1e-6), (k, g, e / root)
mean = sum(float(r["geodesic"]) for r in rows) / len(rows)
assert abs(mean - p["recomputed"]["geo"]) <= 1e-7 * mean, (mean, p)

# atlas method: the worst pair of its cell, reconstructions written
p = pair(atlas)
cell = json.load(open(f"{run}/cells/synth/quadruped_walk/atlasnet/seed_1.json"))
cols = cell["pair_columns"]
sl2 = [r[cols.index("sl2")] for r in cell["pairs"]]
assert p["pair"] == sl2.index(max(sl2)), (p["pair"], sl2)
assert p["recomputed"] == p["cell"], p
for f in ("recon_i", "recon_j"):
    pts, _, faces = ply(f"{atlas}/{f}.ply")
    assert len(pts) > 100 and not faces, f
print("inspect files check out")
PY
test -s oracle/pair.png && test -s "$atlas_dir/pair.png"

# bad requests: the reason, a non-zero exit, nothing written
expect_fail() { # expected-message command...
    local want=$1; shift
    if "$@" > out.txt 2> err.txt; then echo "succeeded: $*"; exit 1; fi
    grep -qF -- "$want" err.txt || { echo "no '$want' in:"; cat err.txt; exit 1; }
}
expect_fail "no pair 6 (the split has 6: 0 to 5)" "$TCBENCH" inspect run nearest 6 --out bad --quiet
expect_fail "no method labelled 'mca'" "$TCBENCH" inspect run mca 0 --out bad --quiet
expect_fail "seed 7 is not one of nearest's seeds in this run" "$TCBENCH" inspect run nearest 0 --seed 7 --out bad --quiet
expect_fail "no sequence 'synth/nope' (the run's: synth/quadruped_walk)" "$TCBENCH" inspect run nearest 0 --sequence synth/nope --out bad --quiet
expect_fail "PAIR: expected a pair index or 'worst'" "$TCBENCH" inspect run nearest first --out bad
expect_fail "is not a run directory" "$TCBENCH" inspect nowhere nearest 0 --out bad --quiet
rm run/work/synth/quadruped_walk/atlasnet/seed_0/model.ckpt
expect_fail "the cell has no fitted model yet" "$TCBENCH" inspect run atlasnet 0 --out bad --quiet
test ! -e bad || { echo "a failed inspect left 'bad' behind"; exit 1; }
echo "inspect test passed"

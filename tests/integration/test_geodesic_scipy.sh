#!/usr/bin/env bash
# tcbench's geodesic error against scipy.sparse.csgraph.dijkstra on the real
# walking cat (../shared/data/anim/cat_walk; skipped when absent, or when
# /usr/bin/python3 has no scipy). geodesic_dump writes a pair's normalised
# frame j, its faces, the prediction and tcbench's per-vertex errors; numpy
# builds the same edge graph (every side of every face, once, weighted by
# its length in double from the float vertices) and scipy's Dijkstra from
# every predicted vertex gives the reference: each vertex's error must
# agree to 1e-9 relative (rounding is ~1e-15), and so must the area, m_geo,
# the geodesic PCK curve and its AUC. Pairs: near frames and far ones,
# predictions by nearest vertex (short paths) and uniform random (long
# paths, which build landmarks).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_GEODESIC_DUMP:?}"

cat_dir="$TCB_SOURCE_DIR/../shared/data/anim/cat_walk"
if [ ! -d "$cat_dir" ]; then
  echo "skipped: $cat_dir is absent"
  exit 77
fi
if ! /usr/bin/python3 -c "import numpy, scipy.sparse.csgraph" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cases="0:10:nearest 5:30:nearest 34:1:nearest 0:10:random 12:20:random 33:2:random"
for c in $cases; do
  IFS=: read -r i j mode <<< "$c"
  "$TCB_GEODESIC_DUMP" "$cat_dir" "$i" "$j" "$mode" "$((i + j))" "$tmp/$i-$j-$mode"
done

/usr/bin/python3 - "$tmp" $cases <<'PY'
import json, sys
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

tmp, cases = sys.argv[1], sys.argv[2:]
worst = 0.0
for case in cases:
    d = "%s/%s" % (tmp, case.replace(":", "-"))
    meta = json.load(open(d + "/pair.json"))
    nv, nf = meta["nv"], meta["nf"]
    verts = np.fromfile(d + "/verts.bin", dtype="<f4").reshape(nv, 3).astype(np.float64)
    faces = np.fromfile(d + "/faces.bin", dtype="<i4").reshape(nf, 3)
    pred = np.fromfile(d + "/pred.bin", dtype="<i4")
    ours = np.fromfile(d + "/geo.bin", dtype="<f8")
    assert len(pred) == nv and len(ours) == nv, case

    # the edge graph: each side once (a side two faces share, once)
    sides = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    sides = sides[sides[:, 0] != sides[:, 1]]
    sides = np.unique(np.sort(sides, axis=1), axis=0)
    w = np.sqrt(((verts[sides[:, 0]] - verts[sides[:, 1]]) ** 2).sum(axis=1))
    graph = coo_matrix((w, (sides[:, 0], sides[:, 1])), shape=(nv, nv)).tocsr()

    cross = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    area = 0.5 * np.sqrt((cross ** 2).sum(axis=1)).sum()
    assert abs(area - meta["area"]) <= 1e-12 * area, (case, area, meta["area"])

    sources, at = np.unique(pred, return_inverse=True)
    dist = dijkstra(graph, directed=False, indices=sources)[at, np.arange(nv)]
    apart = np.isinf(dist)  # another piece of the mesh: the straight line
    dist[apart] = np.sqrt(((verts[pred[apart]] - verts[apart]) ** 2).sum(axis=1))
    ref = dist / np.sqrt(area)

    err = np.abs(ours - ref) / np.maximum(ref, 1e-300)
    err[ref == 0] = np.abs(ours[ref == 0])
    assert err.max() <= 1e-9, (case, int(err.argmax()), ours[err.argmax()], ref[err.argmax()])
    worst = max(worst, err.max())
    assert meta["unreachable"] == int(apart.sum()), case

    thresholds = np.linspace(0, 0.25, 100)
    pck = (ref[:, None] <= thresholds[None, :]).mean(axis=0)
    assert np.allclose(meta["geo_pck"], pck, rtol=0, atol=1e-12), case
    assert abs(meta["geo_auc"] - pck.mean()) <= 1e-12, case
    assert abs(meta["m_geo"] - ref.mean()) <= 1e-9 * ref.mean(), (case, meta["m_geo"], ref.mean())
    # the edge graph only lengthens the straight line
    straight = np.sqrt(((verts[pred] - verts) ** 2).sum(axis=1)) / np.sqrt(area)
    assert (ours >= straight * (1 - 1e-12)).all(), case
    print("%-14s m_geo %.6f  AUC_geo %.4f  sources %5d  largest relative difference %.1e"
          % (case, ref.mean(), pck.mean(), len(sources), err.max()))
print("geodesic error vs scipy: %d pairs agree, largest relative difference %.1e" % (len(cases), worst))
PY

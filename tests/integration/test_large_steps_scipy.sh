#!/usr/bin/env bash
# tcb/large_steps.h (CHOLMOD's factor of M = I + λL, L the uniform Laplacian
# of the mesh's edge graph) against scipy: M built here from the faces
# alone (each face's three edges, made unique), then M v against
# tcb_large_steps_apply and scipy.sparse.linalg.spsolve(M, b) against
# tcb_large_steps_solve, on two synthetic shapes and PDG's λ = 16 (and a
# small λ). Float32 arrays: agreement to 1e-5 of the largest value.
# Skipped when /usr/bin/python3 has no scipy.
set -euo pipefail
: "${TCB_LARGE_STEPS_DUMP:?}"
if ! /usr/bin/python3 -c "import numpy, scipy.sparse.linalg" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for run in "quadruped_walk 16 1" "humanoid_jacks 16 2" "quadruped_walk 0.25 3"; do
  set -- $run
  out="$tmp/$1-$2"
  mkdir -p "$out"
  "$TCB_LARGE_STEPS_DUMP" "$1" "$2" "$3" "$out"
  /usr/bin/python3 - "$out" <<'PY'
import json, sys
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
d = sys.argv[1]
meta = json.load(open(d + "/meta.json"))
nv, lam = meta["nv"], meta["lambda"]
faces = np.fromfile(d + "/faces.bin", dtype=np.int32).reshape(-1, 3)
arr = lambda name: np.fromfile(d + "/" + name, dtype=np.float32).reshape(nv, 3).astype(np.float64)
edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
edges = np.unique(edges, axis=0)
assert len(edges) == meta["ne"], (len(edges), meta["ne"])
A = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(nv, nv))
A = (A + A.T).tocsc()
L = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A
M = (sp.identity(nv) + lam * L).tocsc()
v, u, b, x = arr("v.bin"), arr("u.bin"), arr("b.bin"), arr("x.bin")
want_u = M @ v
err_u = np.abs(u - want_u).max() / np.abs(want_u).max()
want_x = spla.spsolve(M, b)
err_x = np.abs(x - want_x).max() / np.abs(want_x).max()
print("%s: %d vertices, %d edges, lambda %g: M v within %.1e, M^-1 b within %.1e of scipy" %
      (d.rsplit("/", 1)[1], nv, len(edges), lam, err_u, err_x))
assert err_u < 1e-5 and err_x < 1e-5, (err_u, err_x)
PY
done
echo "large steps test passed"

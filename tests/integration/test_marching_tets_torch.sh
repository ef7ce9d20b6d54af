#!/usr/bin/env bash
# neural/marching_tets.c against kaolin's marching_tetrahedra redone in
# PyTorch (tests/pytorch/dynosurf_torch.py: the steps of
# kaolin/ops/conversions/tetmesh.py, v0.14), on TetGen's grid of the
# unit cube with a noisy sphere's values: the same vertices (1e-6) in the
# same order, the same faces, and autograd's gradient of Σ g·v in the
# positions and the values against tcb_marching_tets_backward (1e-5).
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_MARCHING_TETS_DUMP:?}"
source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip "marching tetrahedra"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for run in "0.0005 1" "0.002 2"; do
    set -- $run
    out="$tmp/$1"
    mkdir -p "$out"
    "$TCB_MARCHING_TETS_DUMP" "$1" "$2" "$out"
    /usr/bin/python3 - "$out" <<'PY'
import json, os, sys
import numpy as np
import torch

sys.path.insert(0, os.path.join(os.environ["TCB_SOURCE_DIR"], "tests", "pytorch"))
from dynosurf_torch import marching_tetrahedra

d = sys.argv[1]
meta = json.load(open(d + "/meta.json"))
arr = lambda name, dtype, shape: torch.from_numpy(np.fromfile(d + "/" + name, dtype=dtype).reshape(shape))
x = arr("x.bin", np.float32, (meta["nv"], 3)).clone().requires_grad_(True)
s = arr("s.bin", np.float32, (meta["nv"],)).clone().requires_grad_(True)
tets = arr("tets.bin", np.int32, (meta["nt"], 4)).long()

verts, faces = marching_tetrahedra(x, tets, s)
assert verts.shape[0] == meta["n"] and faces.shape[0] == meta["m"], (verts.shape, faces.shape, meta)
c_verts = arr("verts.bin", np.float32, (meta["n"], 3))
c_faces = arr("faces.bin", np.int32, (meta["m"], 3)).long()
assert torch.equal(faces, c_faces), "faces differ"
err = (verts.detach() - c_verts).abs().max().item()
assert err <= 1e-6, err
g = arr("g.bin", np.float32, (meta["n"], 3))
(verts * g).sum().backward()
scale = lambda t: 1e-5 * max(1.0, t.abs().max().item())
dx, ds = arr("dx.bin", np.float32, (meta["nv"], 3)), arr("ds.bin", np.float32, (meta["nv"],))
ex, es = (x.grad - dx).abs().max().item(), (s.grad - ds).abs().max().item()
assert ex <= scale(x.grad) and es <= scale(s.grad), (ex, es)
print("marching tets (%d grid vertices, %d tets): %d vertices, %d faces as kaolin's; |dx| %.1e, |ds| %.1e"
      % (meta["nv"], meta["nt"], meta["n"], meta["m"], ex, es))
PY
done

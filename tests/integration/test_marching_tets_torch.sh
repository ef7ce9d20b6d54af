#!/usr/bin/env bash
# neural/marching_tets.c against kaolin's marching_tetrahedra redone in
# PyTorch (the steps of kaolin/ops/conversions/tetmesh.py, v0.14: torch.unique
# over the valid tets' sorted edges, the crossing ones numbered in that
# order, the interpolation weights flipped over s_a − s_b, faces gathered
# from the 16-case table, one-triangle tets first), on TetGen's grid of the
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
import json, sys
import numpy as np
import torch

d = sys.argv[1]
meta = json.load(open(d + "/meta.json"))
arr = lambda name, dtype, shape: torch.from_numpy(np.fromfile(d + "/" + name, dtype=dtype).reshape(shape))
x = arr("x.bin", np.float32, (meta["nv"], 3)).clone().requires_grad_(True)
s = arr("s.bin", np.float32, (meta["nv"],)).clone().requires_grad_(True)
tets = arr("tets.bin", np.int32, (meta["nt"], 4)).long()

base_tet_edges = torch.tensor([0, 1, 0, 2, 0, 3, 1, 2, 1, 3, 2, 3])
triangle_table = torch.tensor([
    [-1, -1, -1, -1, -1, -1], [1, 0, 2, -1, -1, -1], [4, 0, 3, -1, -1, -1], [1, 4, 2, 1, 3, 4],
    [3, 1, 5, -1, -1, -1], [2, 3, 0, 2, 5, 3], [1, 4, 0, 1, 5, 4], [4, 2, 5, -1, -1, -1],
    [4, 5, 2, -1, -1, -1], [4, 1, 0, 4, 5, 1], [3, 2, 0, 3, 5, 2], [1, 3, 5, -1, -1, -1],
    [4, 1, 2, 4, 3, 1], [3, 0, 4, -1, -1, -1], [2, 0, 1, -1, -1, -1], [-1, -1, -1, -1, -1, -1]])
num_triangles_table = torch.tensor([0, 1, 1, 2, 1, 2, 2, 1, 1, 2, 2, 1, 2, 1, 1, 0])
v_id = torch.pow(2, torch.arange(4))

def marching_tetrahedra(pos, tet, sdf):
    with torch.no_grad():
        occ_n = sdf > 0
        occ_fx4 = occ_n[tet.reshape(-1)].reshape(-1, 4)
        occ_sum = occ_fx4.sum(-1)
        valid_tets = (occ_sum > 0) & (occ_sum < 4)
        all_edges = tet[valid_tets][:, base_tet_edges].reshape(-1, 2)
        all_edges = torch.sort(all_edges, dim=1)[0]
        unique_edges, idx_map = torch.unique(all_edges, dim=0, return_inverse=True)
        mask_edges = occ_n[unique_edges.reshape(-1)].reshape(-1, 2).sum(-1) == 1
        mapping = torch.ones(unique_edges.shape[0], dtype=torch.long) * -1
        mapping[mask_edges] = torch.arange(int(mask_edges.sum()))
        idx_map = mapping[idx_map]
        interp_v = unique_edges[mask_edges]
    edges_to_interp = pos[interp_v.reshape(-1)].reshape(-1, 2, 3)
    edges_to_interp_sdf = sdf[interp_v.reshape(-1)].reshape(-1, 2, 1)
    edges_to_interp_sdf = torch.cat([edges_to_interp_sdf[:, :1], -edges_to_interp_sdf[:, 1:]], 1)
    denominator = edges_to_interp_sdf.sum(1, keepdim=True)
    edges_to_interp_sdf = torch.flip(edges_to_interp_sdf, [1]) / denominator
    verts = (edges_to_interp * edges_to_interp_sdf).sum(1)
    idx_map = idx_map.reshape(-1, 6)
    tetindex = (occ_fx4[valid_tets] * v_id.unsqueeze(0)).sum(-1)
    num_triangles = num_triangles_table[tetindex]
    faces = torch.cat((
        torch.gather(idx_map[num_triangles == 1], 1, triangle_table[tetindex[num_triangles == 1]][:, :3]).reshape(-1, 3),
        torch.gather(idx_map[num_triangles == 2], 1, triangle_table[tetindex[num_triangles == 2]][:, :6]).reshape(-1, 3),
    ), dim=0)
    return verts, faces

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

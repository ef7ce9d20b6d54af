"""DynoSurf's template objectives (methods/dynosurf/template.c) against the
reference's rebuilt in PyTorch (tests/pytorch/dynosurf_torch.py) with the
C side's weights, grid, points and surface draws
(tests/pytorch/dynosurf_template_step.c):
  pretraining  MSELoss(sdf, the hull's signed distance) and its gradient;
  stage 1      the template by marching tetrahedra (the same faces), the
               L1 Chamfer, normal and approximate-SDF terms, their weighted
               sum, autograd's weight gradient (the sum's and each term's),
               and torch.optim.Adam's first step at lr 1e-4.
Passes at 1e-4 relative (each block to its largest entry; the terms to
their value); each term's own gradient at 1e-3 (a wrong formula is off by
its own size; the small terms' float rounding is nearer 1e-4).

usage: dynosurf_template_check.py HELPER_BINARY WORKDIR
"""
import json
import os
import subprocess
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dynosurf_torch import (approx_sdf, chamfer_l1, marching_tetrahedra,  # noqa: E402
                            sample_points, shape_forward, shape_net)

binary, work = sys.argv[1], sys.argv[2]
N, M, PRE, SEED = 1000, 10000, 100, 3
subprocess.run([binary, str(N), str(M), str(PRE), str(SEED), work], check=True)
meta = json.load(open(f"{work}/meta.json"))
nv, nt, P = meta["nv"], meta["nt"], meta["P"]
load = lambda name, shape, dtype=np.float32: torch.from_numpy(np.fromfile(f"{work}/{name}", dtype=dtype).reshape(shape))
x = load("grid_x.bin", (nv, 3))
tets = load("grid_t.bin", (nt, 4), np.int32).long()
pts, nrm = load("pts.bin", (N, 3)), load("nrm.bin", (N, 3))
worst = 0.0


def close(name, ours, theirs, tol=1e-4):
    global worst
    theirs = torch.as_tensor(theirs, dtype=torch.float64)
    ours = torch.as_tensor(ours, dtype=torch.float64)
    err = (ours - theirs).abs().max().item()
    scale = max(theirs.abs().max().item(), 1e-12)
    assert err <= tol * scale, f"{name}: {err:.3e} against {scale:.3e}"
    worst = max(worst, err / scale)


def close_grads(name, ours, linears):
    """Each layer's gradient against its own largest entry."""
    at = 0
    for i, m in enumerate(linears):
        k = m.weight.numel()
        close(f"{name}, layer {i + 1}", ours[at:at + k], m.weight.grad.reshape(-1))
        at += k


# pretraining: MSE to the hull's signed distance
net, linears = shape_net(load("params.bin", (P,)))
_, sdf, _ = shape_forward(net, x, meta["edge"])
loss = torch.nn.functional.mse_loss(sdf, load("target.bin", (nv,)))
loss.backward()
close("pretraining loss", meta["pre_loss"], loss.item())
close_grads("pretraining gradient", load("pre_grad.bin", (P,)), linears)

# stage 1: one step
net, linears = shape_net(load("params.bin", (P,)))
_, sdf, v = shape_forward(net, x, meta["edge"])
verts, faces = marching_tetrahedra(v, tets, sdf)
assert (verts.shape[0], faces.shape[0]) == (meta["n_verts"], meta["n_faces"]), (verts.shape, faces.shape)
samples, normals = sample_points(verts, faces, load("draw_face.bin", (M,), np.int32).long(), load("draw_w.bin", (M, 3)))
cham, normal = chamfer_l1(samples, normals, pts, nrm)
sdf_term = torch.nn.functional.l1_loss(sdf, approx_sdf(v, pts, nrm).float())
terms = {"chamfer": 500 * cham, "normal": 0.001 * normal, "sdf": 50 * sdf_term}
for name, term in terms.items():  # each term's gradient alone: a small term's error would hide in the sum's
    grads = torch.autograd.grad(term, [m.weight for m in linears], retain_graph=True)
    mine, at = load(f"grad_{name}.bin", (P,)), 0
    for i, gr in enumerate(grads):
        close(f"{name} gradient, layer {i + 1}", mine[at:at + gr.numel()], gr.reshape(-1), 1e-3)
        at += gr.numel()
total = sum(terms.values())
total.backward()
for name, value in (("chamfer", cham), ("normal", normal), ("sdf", sdf_term), ("total", total)):
    close(name, meta[name], value.item())
close_grads("stage-1 gradient", load("grad.bin", (P,)), linears)
opt = torch.optim.Adam(net.parameters(), lr=1e-4)
opt.step()
close("stage-1 Adam step", load("after.bin", (P,)), torch.cat([m.weight.detach().reshape(-1) for m in linears]), 1e-5)
print(f"dynosurf template: pretraining and stage-1 losses, gradients and Adam step as PyTorch's on "
      f"{nv} grid vertices, a template of {meta['n_faces']} faces (worst {worst:.1e} relative)")

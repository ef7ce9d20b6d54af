"""PDG's loss and gradients in PyTorch autograd (tests/pytorch/pdg_torch.py,
written from the method's description), on a small random problem, against
one step of methods/pdg/train.c (tests/pytorch/pdg_step.c), for each
rotation (released: translations alone; cayley: the Cayley rotation and
the translation, 6 values a node): the fields' parameters U and the
template's Large-Steps parameters u give V and v by dense solves here;
everything in float64. Passes when, for both, the loss parts and each
parameter block's gradient (every level's U, its rotation and translation
channels apart, the template's u) agree with the C float32 values to 1e-4
relative (to the block's largest entry).

usage: pdg_step_check.py PDG_STEP_BINARY WORKDIR
"""
import subprocess
import sys

import numpy as np
import torch

import neupig_torch as nt
import pdg_torch as pt

torch.set_default_dtype(torch.float64)
binary, work = sys.argv[1], sys.argv[2]

LEVELS, N, KEY, EPOCH, EPOCHS, WARMUP = 3, 5, 2, 150, 400, 101
LAMBDA, GROWTH, TEMPLATE_LAMBDA = 0.25, 1.5, 16.0
rng = np.random.default_rng(2026)

p = (1 + 5 ** 0.5) / 2
unit = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
                 [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], float)
unit /= np.linalg.norm(unit, axis=1, keepdims=True)
faces = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
verts = 0.5 * unit + 0.03 * rng.standard_normal(unit.shape)
points = [0.5 * unit[rng.integers(0, 12, 30)] * (1 + 0.08 * (t - KEY)) + 0.05 * rng.standard_normal((30, 3))
          for t in range(N)]
r = [1 + 2 * l for l in range(LEVELS)]
U = {"released": [0.8 * rng.standard_normal((N - 1, k ** 3, 3)) for k in r]}
L_tpl, edges = pt.uniform_laplacian(faces, len(verts))
M_tpl = torch.eye(len(verts)) + TEMPLATE_LAMBDA * L_tpl
u = (M_tpl @ torch.tensor(verts)).numpy() + 0.01 * rng.standard_normal(verts.shape)
U["cayley"] = [0.8 * rng.standard_normal((N - 1, k ** 3, 6)) for k in r]  # r, then the translation

f32 = lambda name, x: np.save(f"{work}/{name}.npy", np.asarray(x, np.float32))
f32("verts", verts), f32("faces", faces)
for t in range(N):
    f32(f"points_{t}", points[t])
P = [torch.tensor(np.asarray(x, np.float32), dtype=torch.float64) for x in points]


def check(rotation):
    """The worst relative difference of the C step from the reference."""
    params = np.concatenate([x.ravel() for x in U[rotation]] + [u.ravel()]).astype(np.float32)
    f32("params", params)
    subprocess.run([binary, work, str(LEVELS), str(N), str(KEY), str(EPOCH), str(EPOCHS), str(WARMUP), rotation],
                   check=True)
    c_loss = np.load(f"{work}/c_loss.npy")
    c_grads = np.load(f"{work}/c_grads.npy").astype(np.float64)

    # the reference on the float32 inputs the C code read
    C = U[rotation][0].shape[2]
    U_t, off = [], 0
    for k in r:
        n = (N - 1) * k ** 3 * C
        U_t.append(torch.tensor(params[off:off + n].reshape(N - 1, k ** 3, C), dtype=torch.float64,
                                requires_grad=True))
        off += n
    u_t = torch.tensor(params[off:].reshape(-1, 3), dtype=torch.float64, requires_grad=True)
    total, L_in, pred, edge, template = pt.step_loss(U_t, u_t, P, KEY, torch.tensor(edges), EPOCH, EPOCHS, WARMUP,
                                                     pt.field_solvers(LEVELS, nt.dense_solver, LAMBDA, GROWTH),
                                                     lambda u: torch.linalg.solve(M_tpl, u))
    (total + template).backward()
    ref_loss = np.array([total.item(), L_in.item(), pred.item(), edge.item(), template.item()])
    rel = np.abs(c_loss - ref_loss) / np.abs(ref_loss)
    print(f"{rotation}: loss [total, input, pred, edge, template]: C", c_loss, "reference", ref_loss,
          "(max relative %.2e)" % rel.max())
    assert rel.max() <= 1e-4, rel
    worst, off, blocks = rel.max(), 0, []
    for l, k in enumerate(r):  # each level's channels by kind: the rotation's and the translation's apart
        n = (N - 1) * k ** 3 * C
        c = c_grads[off:off + n].reshape(N - 1, k ** 3, C)
        g = U_t[l].grad.numpy()
        off += n
        kinds = [("", slice(0, C))] if C == 3 else [(" r", slice(0, 3)), (" t", slice(3, 6))]
        blocks += [(f"level {l}{kind}", c[..., ch], g[..., ch]) for kind, ch in kinds]
    blocks.append(("template u", c_grads[off:], u_t.grad.numpy().ravel()))
    assert off + u_t.numel() == c_grads.size
    for name, c, ref in blocks:
        err = np.abs(c - ref).max() / np.abs(ref).max()
        worst = max(worst, err)
        print(f"{rotation}: gradient {name:10s}: max |C - ref| / max |ref| = {err:.2e} "
              f"(max |ref| {np.abs(ref).max():.3e})")
    assert worst <= 1e-4, f"PDG step ({rotation}) differs from the PyTorch reference by {worst:.2e} (> 1e-4)"
    return worst


worst = max(check(rotation) for rotation in ("released", "cayley"))
print(f"OK: loss and every gradient, both rotations, within {worst:.2e} of PyTorch")

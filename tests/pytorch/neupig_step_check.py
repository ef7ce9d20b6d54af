"""Neu-PiG's loss and gradients in PyTorch autograd (tests/pytorch/
neupig_torch.py, written from the method's description), on a small
random problem, against methods/neupig/model.c (tests/pytorch/neupig_step.c).

The grids' preconditioned parameters u give the values v = M^-1 u, solved
densely here (small grids); everything in float64. The eigenbasis solve and the
GEMM-form nearest neighbours the bench's peer uses are checked against the
dense solve and the brute-force search on the same problem.
Passes when the loss and each parameter block's gradient agree with the C
float32 values to 1e-4 relative (to the block's largest entry).

usage: neupig_step_check.py NEUPIG_STEP_BINARY WORKDIR
"""
import subprocess
import sys

import numpy as np
import torch

import neupig_torch as nt

torch.set_default_dtype(torch.float64)
binary, work = sys.argv[1], sys.argv[2]

LEVELS, BASE, STEP, F, NRES, FN, J, H = 3, 2, 3, 4, 3, 2, 2, 16
T, KEY, EPOCH, EPOCHS = 4, 1, 3, 10
LAMBDA, GROWTH, NLAMBDA, EDGE_W, ALPHA = 0.4, 1.5, 0.4, 100.0, 0.3
rng = np.random.default_rng(2026)


def icosahedron():
    p = (1 + 5 ** 0.5) / 2
    v = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
                  [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], float)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    return v / np.linalg.norm(v, axis=1, keepdims=True), f


unit, faces = icosahedron()
verts = 0.6 * unit + 0.05 * rng.standard_normal(unit.shape)
normals = unit
edges = np.array(sorted({tuple(sorted((int(f[a]), int(f[(a + 1) % 3])))) for f in faces for a in range(3)}))
edge_len = 0.9 * np.linalg.norm(verts[edges[:, 0]] - verts[edges[:, 1]], axis=1)
points = [verts[rng.integers(0, 12, 30)] * (1 + 0.1 * t) + 0.08 * rng.standard_normal((30, 3))
          for t in range(T)]

arch = nt.Arch(LEVELS, BASE, STEP, F, NRES, FN, J, H, LAMBDA, GROWTH, NLAMBDA, EDGE_W, ALPHA)
sizes = [r ** 3 * w for r, w in zip(nt.resolutions(arch), nt.widths(arch))]
mlp_shapes = nt.mlp_shapes(arch)
n_params = sum(sizes) + sum(int(np.prod(s)) for s in mlp_shapes)
params = np.concatenate([0.3 * rng.standard_normal(n) for n in sizes] +
                        [rng.uniform(-1, 1, s).ravel() / np.sqrt(s[-1] if len(s) > 1 else H)
                         for s in mlp_shapes]).astype(np.float32)
params[sum(sizes) + H * (F + FN + 2 * J) + H + H * H + H:] *= 0.5  # a non-zero head: every block gets a gradient

f32 = lambda name, x: np.save(f"{work}/{name}.npy", np.asarray(x, np.float32))
f32("verts", verts), f32("normals", normals), f32("edge_len", edge_len), f32("params", params)
np.save(f"{work}/edges.npy", edges.astype(np.int32))
for t in range(T):
    f32(f"points_{t}", points[t])
subprocess.run([binary, work] + [str(x) for x in (LEVELS, BASE, STEP, F, NRES, FN, J, H, T, KEY, EPOCH, EPOCHS)],
               check=True)

# ---- the reference (tests/pytorch/neupig_torch.py), from the same float32 inputs
as64 = lambda x: torch.tensor(np.float32(x).astype(float))
prob = nt.Problem(as64(verts), as64(normals), [as64(p) for p in points], torch.tensor(edges, dtype=torch.long),
                  as64(edge_len), KEY)
theta = torch.tensor(params.astype(float), requires_grad=True)
offs = np.cumsum([0] + sizes)
grids = [theta[offs[g]:offs[g + 1]] for g in range(LEVELS + 1)]
k = offs[-1]
mlp = []
for s in mlp_shapes:
    n = int(np.prod(s))
    mlp.append(theta[k:k + n].reshape(s))
    k += n
total, chamfer, edge, cdd = nt.loss(arch, grids, mlp, prob, nt.solvers(arch, nt.dense_solver), EPOCH, EPOCHS)
total.backward()

c_loss = np.load(f"{work}/c_loss.npy")
c_cd = np.load(f"{work}/c_cd.npy")
c_grads = np.load(f"{work}/c_grads.npy").astype(float)
ref = [total.item(), chamfer.item(), edge.item()]
worst = 0.0
for name, a, b in (("loss", c_loss, np.array(ref)), ("CD per frame", c_cd, cdd.numpy())):
    err = np.max(np.abs(a - b) / np.abs(b))
    print(f"{name}: C {a} reference {b} (max relative {err:.2e})")
    worst = max(worst, err)
g = theta.grad.numpy()
bounds = list(offs)
k = offs[-1]
for s in mlp_shapes:
    k += int(np.prod(s))
    bounds.append(k)
names = [f"grid level {l}" for l in range(LEVELS)] + ["normal grid", "W1", "b1", "W2", "b2", "W3", "b3"]
for name, lo, hi in zip(names, bounds[:-1], bounds[1:]):
    scale = np.max(np.abs(g[lo:hi]))
    err = np.max(np.abs(c_grads[lo:hi] - g[lo:hi])) / scale
    print(f"gradient {name:12s}: max |C - ref| / max |ref| = {err:.2e} (max |ref| {scale:.3e})")
    assert scale > 0, f"{name}: the reference gradient is zero: the check would prove nothing"
    worst = max(worst, err)
# the bench's nearest neighbours and solve (bench/train_step_neupig_torch.py)
# against the brute-force search and the dense solve
with torch.no_grad():
    gemm = nt.loss(arch, grids, mlp, prob, nt.solvers(arch, nt.dense_solver), EPOCH, EPOCHS, nt.nearest_sq_gemm)[0]
err = abs(gemm.item() - total.item()) / abs(total.item())
print(f"loss with the GEMM-form search: {err:.1e} from the brute-force one")
assert err <= 1e-12, f"the GEMM-form nearest neighbours change the loss by {err:.1e}"
for g, (dense, basis) in enumerate(zip(nt.solvers(arch, nt.dense_solver), nt.solvers(arch, nt.basis_solver))):
    u = grids[g].detach().reshape(-1, nt.widths(arch)[g])
    err = (torch.max(torch.abs(basis(u) - dense(u))) / torch.max(torch.abs(dense(u)))).item()
    print(f"grid {g}: the eigenbasis solve against the dense one: {err:.1e} of the largest value")
    assert err <= 1e-12, f"grid {g}: the eigenbasis solve differs from the dense one by {err:.1e}"
assert worst <= 1e-4, f"Neu-PiG step differs from the PyTorch reference by {worst:.2e} (> 1e-4)"
print(f"OK: loss and every gradient within {worst:.2e} of PyTorch")

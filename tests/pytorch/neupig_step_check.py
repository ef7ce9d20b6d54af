"""Neu-PiG's loss and gradients in PyTorch autograd, written from the
method's description (github vc-bonn/neu-pig: src/optimization.py,
src/utilities/loss_f.py, src/loss_time_smoothing.py, src/rotation.py,
src/network/*; grids from vc-bonn/pcgrid src/pcgrid/grid.py), on a small
random problem, against methods/neupig/model.c (tests/pytorch/neupig_step.c).

The grids' preconditioned parameters u give the values v = M^-1 u, solved
densely here (small grids); everything else is the reference's operations
(grid_sample with align_corners=True and border padding, tanh, the Fourier
time features, Linear + LeakyReLU, the quaternion rotation as PyTorch3D's
quaternion_to_matrix, tanh(0.1 d), the Welsch-weighted two-way Chamfer with
the weights detached, the pdg confidence, the edge-length L1), in float64.
Passes when the loss and each parameter block's gradient agree with the C
float32 values to 1e-4 relative (to the block's largest entry).

usage: neupig_step_check.py NEUPIG_STEP_BINARY WORKDIR
"""
import subprocess
import sys

import numpy as np
import torch

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

res = [BASE + STEP * l for l in range(LEVELS)] + [NRES]
width = [F] * LEVELS + [FN]
lam = [LAMBDA * GROWTH ** l for l in range(LEVELS)] + [NLAMBDA]
sizes = [r ** 3 * w for r, w in zip(res, width)]
mlp_shapes = [(H, F + FN + 2 * J), (H,), (H, H), (H,), (7, H), (7,)]
n_params = sum(sizes) + sum(int(np.prod(s)) for s in mlp_shapes)
params = np.concatenate([0.3 * rng.standard_normal(n) for n in sizes] +
                        [rng.uniform(-1, 1, s).ravel() / np.sqrt(s[-1] if len(s) > 1 else H)
                         for s in mlp_shapes]).astype(np.float32)
params[sum(sizes) + H * (F + FN + 2 * J) + H + H * H + H:] *= 0.5  # a non-zero head: every block gets a gradient

f32 = lambda name, a: np.save(f"{work}/{name}.npy", np.asarray(a, np.float32))
f32("verts", verts), f32("normals", normals), f32("edge_len", edge_len), f32("params", params)
np.save(f"{work}/edges.npy", edges.astype(np.int32))
for t in range(T):
    f32(f"points_{t}", points[t])
subprocess.run([binary, work] + [str(x) for x in (LEVELS, BASE, STEP, F, NRES, FN, J, H, T, KEY, EPOCH, EPOCHS)],
               check=True)

# ---- the reference, from the same float32 inputs
V = torch.tensor(np.float32(verts).astype(float))
N = torch.tensor(np.float32(normals).astype(float))
P = [torch.tensor(np.float32(p).astype(float)) for p in points]
base_len = torch.tensor(np.float32(edge_len).astype(float))
E = torch.tensor(edges, dtype=torch.long)
theta = torch.tensor(params.astype(float), requires_grad=True)


def laplacian(r):
    n = r ** 3
    L = np.zeros((n, n))
    for z in range(r):
        for y in range(r):
            for x in range(r):
                i = (z * r + y) * r + x
                for dz, dy, dx in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
                    zz, yy, xx = z + dz, y + dy, x + dx
                    if zz < r and yy < r and xx < r:
                        j = (zz * r + yy) * r + xx
                        L[i, j] = L[j, i] = -1
                        L[i, i] += 1
                        L[j, j] += 1
    return torch.tensor(L)


def sample(values, r, w, pts):
    grid = values.reshape(r, r, r, w).permute(3, 0, 1, 2)[None]  # (1, w, z, y, x)
    out = torch.nn.functional.grid_sample(grid, pts[None, None, None], mode="bilinear",
                                          padding_mode="border", align_corners=True)
    return out[0, :, 0, 0].T  # (n, w)


offs = np.cumsum([0] + sizes)
grid_vals = []
for g in range(LEVELS + 1):
    M = torch.eye(res[g] ** 3) + lam[g] * laplacian(res[g])
    u = theta[offs[g]:offs[g + 1]].reshape(res[g] ** 3, width[g])
    grid_vals.append(torch.linalg.solve(M, u))
feat_p = torch.tanh(sum(sample(grid_vals[l], res[l], F, V) for l in range(LEVELS)) / LEVELS)
feat_n = torch.tanh(sample(grid_vals[LEVELS], NRES, FN, N))

k = offs[-1]
mlp = []
for s in mlp_shapes:
    n = int(np.prod(s))
    mlp.append(theta[k:k + n].reshape(s))
    k += n
W1, b1, W2, b2, W3, b3 = mlp

tt = torch.arange(T, dtype=torch.float64) / (T - 1)
freqs = 2.0 ** torch.arange(J)
time = torch.cat([torch.sin(tt[:, None] * freqs * torch.pi), torch.cos(tt[:, None] * freqs * torch.pi)], -1)
x = torch.cat([torch.cat([feat_p, feat_n], -1)[None].expand(T, -1, -1), time[:, None].expand(-1, 12, -1)], -1)
leaky = torch.nn.functional.leaky_relu
o = leaky(leaky(x @ W1.T + b1) @ W2.T + b2) @ W3.T + b3  # (T, nv, 7)


def quaternion_to_matrix(q):  # PyTorch3D's formula, real part first
    r, i, j, kk = q.unbind(-1)
    two_s = 2.0 / (q * q).sum(-1)
    R = torch.stack((1 - two_s * (j * j + kk * kk), two_s * (i * j - kk * r), two_s * (i * kk + j * r),
                     two_s * (i * j + kk * r), 1 - two_s * (i * i + kk * kk), two_s * (j * kk - i * r),
                     two_s * (i * kk - j * r), two_s * (j * kk + i * r), 1 - two_s * (i * i + j * j)), -1)
    return R.reshape(q.shape[:-1] + (3, 3))


q = o[..., :4] + torch.tensor([1.0, 0, 0, 0])
q = q / (torch.norm(q, dim=-1, keepdim=True) + 1e-8)
X = (quaternion_to_matrix(q) @ V[None, ..., None])[..., 0] + torch.tanh(0.1 * o[..., 4:])


def robust_one_way(a, b):
    d2 = ((a[:, None] - b[None]) ** 2).sum(-1).min(1).values
    return (torch.exp(-d2 ** 2 / (2 * ALPHA ** 2)).detach() * d2).sum()


cd = torch.stack([robust_one_way(P[t], X[t]) + robust_one_way(X[t], P[t]) for t in range(T)])
c = torch.ones(T)
cdd, power = cd.detach(), 1 - (EPOCH / EPOCHS) ** 0.5
for direction in (-1, 1):
    acc, t = 1.0, KEY + direction
    while 0 <= t < T:
        acc = acc * (1 / (1 + torch.clamp(cdd[t] - cdd[KEY], min=0))) ** power
        c[t] = acc
        t += direction
chamfer = (c * cd).mean()
lengths = torch.norm(X[:, E[:, 0]] - X[:, E[:, 1]], dim=-1)
edge = EDGE_W * torch.nn.functional.l1_loss(lengths, base_len.expand_as(lengths))
total = chamfer + edge
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
assert worst <= 1e-4, f"Neu-PiG step differs from the PyTorch reference by {worst:.2e} (> 1e-4)"
print(f"OK: loss and every gradient within {worst:.2e} of PyTorch")

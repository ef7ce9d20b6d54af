"""Neu-PiG's deformation and loss in PyTorch autograd, written from the
method's description (github vc-bonn/neu-pig: src/optimization.py,
src/utilities/loss_f.py, src/loss_time_smoothing.py, src/rotation.py,
src/network/*; grids from vc-bonn/pcgrid src/pcgrid/grid.py): the
reference of tests/pytorch/neupig_step_check.py (float64, small grids
solved densely) and of bench/train_step_neupig_torch.py (float32, the
paper's and the cpu preset's sizes, the solve in the eigenbasis).

Every operation is the reference's: grid_sample with align_corners=True
and border padding, levels averaged then tanh, the Fourier time features,
Linear + LeakyReLU(0.01), the quaternion rotation as PyTorch3D's
quaternion_to_matrix, translation tanh(0.1 d), the Welsch-weighted two-way
Chamfer (sums of squared nearest distances, weights detached), the pdg
confidence, 100 x the edge-length L1. Only the grids' solve v = M^-1 u,
M = I + lambda L with L as pcgrid builds it (2D - A: `laplacian`), is
passed in: `dense_solver` (torch.linalg.solve, small grids) or
`basis_solver` (exact in the eigenbasis of the three path matrices, as
tcbench's neural/sobolev.c; the reference's conjugate gradient reaches the
same v to its tolerance: docs/protocol.md, "Neu-PiG").
"""
import math
from collections import namedtuple

import numpy as np
import torch

# levels, base_res, res_step, F; normal_res, Fn; J time frequencies; hidden
# width H; lambda, growth, normal lambda; edge weight; Welsch alpha
Arch = namedtuple("Arch", "levels base step F nres Fn J H lam growth nlam edge_w alpha")
# V, N [nv][3] template and its normals; P [T] clouds [n][3]; E [ne][2]
# long; base_len [ne]; key the keyframe
Problem = namedtuple("Problem", "V N P E base_len key")


def resolutions(a):
    return [a.base + a.step * l for l in range(a.levels)] + [a.nres]


def widths(a):
    return [a.F] * a.levels + [a.Fn]


def lambdas(a):
    return [a.lam * a.growth ** l for l in range(a.levels)] + [a.nlam]


def mlp_shapes(a):
    return [(a.H, a.F + a.Fn + 2 * a.J), (a.H,), (a.H, a.H), (a.H,), (7, a.H), (7,)]


def laplacian(r):
    """The 6-neighbour lattice Laplacian of r^3 nodes, x fastest, as pcgrid
    builds it: -1 per directed edge of a list holding both directions of
    every edge, and on the diagonal each node's count of occurrences in
    that list, both columns together (so twice its neighbours: 2D - A)."""
    edges = []
    for z in range(r):
        for y in range(r):
            for x in range(r):
                for dz, dy, dx in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)):
                    zz, yy, xx = z + dz, y + dy, x + dx
                    if 0 <= zz < r and 0 <= yy < r and 0 <= xx < r:
                        edges.append(((z * r + y) * r + x, (zz * r + yy) * r + xx))
    L = np.zeros((r ** 3, r ** 3))
    if edges:
        e = np.array(edges).T
        L[e[0], e[1]] = -1
        nodes, counts = np.unique(e, return_counts=True)
        L[nodes, nodes] = counts
    return torch.tensor(L, dtype=torch.get_default_dtype())


def dense_solver(r, lam):
    M = torch.eye(r ** 3) + lam * laplacian(r)
    return lambda u: torch.linalg.solve(M, u)


def basis_solver(r, lam):
    """v = (I + lam L)^-1 u exactly: L is the Kronecker sum of three path
    matrices P (tridiagonal: -1 off the diagonal, twice the neighbour count
    on it), so M^-1 is diagonal in the basis of P's eigenvectors."""
    P = torch.zeros((r, r), dtype=torch.float64)
    for i in range(r):
        P[i, i] = 2.0 * ((i > 0) + (i < r - 1))
        if i + 1 < r:
            P[i, i + 1] = P[i + 1, i] = -1.0
    e, Q = torch.linalg.eigh(P)
    C = Q.T  # rows: eigenvectors
    scale = 1 / (1 + lam * (e[:, None, None] + e[None, :, None] + e[None, None, :]))
    dt = torch.get_default_dtype()
    C, scale = C.to(dt), scale.to(dt)

    def along_axes(B, x):  # B applied along z, y and x in turn: three GEMMs
        x = torch.einsum("az,zyxw->ayxw", B, x)
        x = torch.einsum("by,aywx->abwx", B, x.transpose(2, 3))
        return torch.einsum("cx,abwx->abcw", B, x)

    def solve(u):
        w = u.shape[-1]
        x = along_axes(C, u.reshape(r, r, r, w)) * scale[..., None]
        return along_axes(C.T, x).reshape(r ** 3, w)

    return solve


def solvers(a, make):
    return [make(r, lam) for r, lam in zip(resolutions(a), lambdas(a))]


def sample(values, r, w, pts):
    grid = values.reshape(r, r, r, w).permute(3, 0, 1, 2)[None]  # (1, w, z, y, x)
    out = torch.nn.functional.grid_sample(grid, pts[None, None, None], mode="bilinear",
                                          padding_mode="border", align_corners=True)
    return out[0, :, 0, 0].T  # (n, w)


def quaternion_to_matrix(q):  # PyTorch3D's formula, real part first
    r, i, j, kk = q.unbind(-1)
    two_s = 2.0 / (q * q).sum(-1)
    R = torch.stack((1 - two_s * (j * j + kk * kk), two_s * (i * j - kk * r), two_s * (i * kk + j * r),
                     two_s * (i * j + kk * r), 1 - two_s * (i * i + kk * kk), two_s * (j * kk - i * r),
                     two_s * (i * kk - j * r), two_s * (j * kk + i * r), 1 - two_s * (i * i + j * j)), -1)
    return R.reshape(q.shape[:-1] + (3, 3))


def deform(a, grids, mlp, prob, T, solve):
    """X (T, nv, 3): the template moved into every frame; grids the u of
    each level then the normal grid's, mlp W1 b1 W2 b2 W3 b3."""
    res, width = resolutions(a), widths(a)
    vals = [s(u.reshape(r ** 3, w)) for s, u, r, w in zip(solve, grids, res, width)]
    feat_p = torch.tanh(sum(sample(vals[l], res[l], a.F, prob.V) for l in range(a.levels)) / a.levels)
    feat_n = torch.tanh(sample(vals[a.levels], a.nres, a.Fn, prob.N))
    tt = torch.arange(T, dtype=prob.V.dtype) / (T - 1)
    freqs = 2.0 ** torch.arange(a.J, dtype=prob.V.dtype)
    time = torch.cat([torch.sin(tt[:, None] * freqs * torch.pi), torch.cos(tt[:, None] * freqs * torch.pi)], -1)
    nv = prob.V.shape[0]
    x = torch.cat([torch.cat([feat_p, feat_n], -1)[None].expand(T, -1, -1), time[:, None].expand(-1, nv, -1)], -1)
    W1, b1, W2, b2, W3, b3 = mlp
    leaky = torch.nn.functional.leaky_relu
    o = leaky(leaky(x @ W1.T + b1) @ W2.T + b2) @ W3.T + b3  # (T, nv, 7)
    q = o[..., :4] + torch.tensor([1.0, 0, 0, 0], dtype=o.dtype)
    q = q / (torch.norm(q, dim=-1, keepdim=True) + 1e-8)
    return (quaternion_to_matrix(q) @ prob.V[None, ..., None])[..., 0] + torch.tanh(0.1 * o[..., 4:])


def nearest_sq_brute(a, b):
    return ((a[:, None] - b[None]) ** 2).sum(-1).min(1).values


def nearest_sq_gemm(a, b):
    """The same minima for large clouds: the search by the distance
    matrix's GEMM form without autograd, then each match's squared
    distance with it (the gradient of a minimum is its match's). One
    matrix, |b|^2 - 2 a.b by a single addmm (|a|^2 is the same along a
    row)."""
    with torch.no_grad():
        idx = torch.addmm((b * b).sum(-1)[None], a, b.T, alpha=-2).argmin(1)
    return ((a - b[idx]) ** 2).sum(-1)


def loss(a, grids, mlp, prob, solve, epoch, epochs, nearest_sq=nearest_sq_brute):
    """(total, chamfer, edge, per-frame CD detached) at epoch of epochs."""
    T = len(prob.P)
    X = deform(a, grids, mlp, prob, T, solve)

    def robust_one_way(p, q):
        d2 = nearest_sq(p, q)
        return (torch.exp(-d2 ** 2 / (2 * a.alpha ** 2)).detach() * d2).sum()

    cd = torch.stack([robust_one_way(prob.P[t], X[t]) + robust_one_way(X[t], prob.P[t]) for t in range(T)])
    c = torch.ones(T, dtype=cd.dtype)
    cdd, power = cd.detach(), 1 - (epoch / epochs) ** 0.5
    for direction in (-1, 1):
        acc, t = 1.0, prob.key + direction
        while 0 <= t < T:
            acc = acc * (1 / (1 + torch.clamp(cdd[t] - cdd[prob.key], min=0))) ** power
            c[t] = acc
            t += direction
    chamfer = (c * cd).mean()
    lengths = torch.norm(X[:, prob.E[:, 0]] - X[:, prob.E[:, 1]], dim=-1)
    edge = a.edge_w * torch.nn.functional.l1_loss(lengths, prob.base_len.expand_as(lengths))
    return chamfer + edge, chamfer, edge, cdd

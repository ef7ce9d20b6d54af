"""PDG's objective and its template term in PyTorch autograd, written from
the method's description (github vc-bonn/preconditioned-deformation-grids
@ cf21c7d: src/optimization.py, src/geometry/; grids from vc-bonn/pcgrid
@ 28a3b11: src/pcgrid/grid.py, optimization_values.py; the robust Chamfer
from DynoSurf's code/loss.py): the reference of tests/pytorch/
pdg_step_check.py, in float64 with dense solves on small grids.

Every operation is the reference's: per transition and level, the values
V = M^-1 U with M = I + lambda_l L (pcgrid's lattice Laplacian, its
diagonal the occurrences in a both-way edge list: neupig_torch.laplacian);
grid_sample with align_corners=True and border padding, the level mean,
the translation 0.1 tanh; the rotation the identity ("released": the
release's never leaves it) or the Cayley map of the first 3 channels,
R = (I - K)^-1 (I + K) by torch.linalg.solve ("cayley"); each step the
affine [R | t] composed as the release composes its 4x4 transforms
(src/optimization.py:135-143: A <- A [R | t], x = A x0 with x0 the
template), the input term's step applied to the frame's own points
(y = R x + t); the template v = (I + 16 L)^-1 u with L the uniform
Laplacian of its edges;
the robust Chamfer (sums, Welsch weight of the squared distance, detached);
the input term, the chains from the detached template sampled at the moved
points, the catch-up weights (detached), 250 x the edge-length L1 between
consecutive steps.

The solves and the nearest-neighbour search are passed in (`step_loss`):
the check's dense ones on small grids (nt.dense_solver, a dense template
matrix, `nearest_dense`), or bench/train_step_pdg_torch.py's at the
presets' sizes (nt.basis_solver, a sparse factorisation, a GEMM search).
"""
import torch
import torch.nn.functional as F

import neupig_torch as nt


def field_solvers(levels, make, lam=0.25, growth=1.5):
    """Per level l (r = 1 + 2l nodes a side, lambda_l = lam growth^l): U
    [T][r^3][C] -> V = M^-1 U, every transition's values the columns of one
    solve make(r, lambda_l) (nt.dense_solver or nt.basis_solver; level 0,
    one node, has L = 0: M = I)."""
    def level(r, solve):
        return lambda U: (solve(U.transpose(0, 1).reshape(r ** 3, -1))
                          .reshape(r ** 3, U.shape[0], U.shape[2]).transpose(0, 1))

    return [level(1 + 2 * l, make(1 + 2 * l, lam * growth ** l)) for l in range(levels)]


def uniform_laplacian(faces, nv):
    L = torch.zeros((nv, nv))
    edges = {tuple(sorted((int(f[a]), int(f[(a + 1) % 3])))) for f in faces for a in range(3)}
    for a, b in edges:
        L[a, b] = L[b, a] = -1
        L[a, a] += 1
        L[b, b] += 1
    return L, sorted(edges)


def sample(V, x):
    """V [r^3][C] (x fastest) at points x [n][3]: [n][C]."""
    r = round(V.shape[0] ** (1 / 3))
    vol = V.reshape(r, r, r, -1).permute(3, 0, 1, 2)[None]  # [1][C][z][y][x]
    out = F.grid_sample(vol, x[None, None, None], mode="bilinear", padding_mode="border", align_corners=True)
    return out[0, :, 0, 0].T


def cayley(r):
    """R [n][3][3] = (I - K)^-1 (I + K), K = [r]x, of r [n][3]."""
    zero = torch.zeros_like(r[:, 0])
    K = torch.stack([torch.stack([zero, -r[:, 2], r[:, 1]], -1),
                     torch.stack([r[:, 2], zero, -r[:, 0]], -1),
                     torch.stack([-r[:, 1], r[:, 0], zero], -1)], 1)
    eye = torch.eye(3).expand_as(K)
    return torch.linalg.solve(eye - K, eye + K)


def step(V_levels, g, x):
    """Field g's affine step [n][3][4] = [R | 0.1 tanh(s_t)] at points x [n][3]."""
    s = sum(sample(V[g], x) for V in V_levels) / len(V_levels)
    R = cayley(s[:, :3]) if s.shape[1] == 6 else torch.eye(3).expand(len(x), 3, 3)
    return torch.cat([R, 0.1 * torch.tanh(s[:, -3:])[:, :, None]], 2)


def compose(A, S):
    """A [n][3][4] times S [n][3][4], both affine (last row 0 0 0 1)."""
    return torch.cat([A[:, :, :3] @ S[:, :, :3], A[:, :, :3] @ S[:, :, 3:] + A[:, :, 3:]], 2)


def apply(A, x):
    return (A[:, :, :3] @ x[:, :, None])[:, :, 0] + A[:, :, 3]


def nearest_dense(X, P):
    """Squared distances to the nearest point of the other cloud, both ways."""
    d2 = torch.cdist(X, P) ** 2
    return d2.min(dim=1).values, d2.min(dim=0).values


def robust_chamfer(X, P, nearest=nearest_dense, alpha=0.3):
    sx, sp = nearest(X, P)
    w = lambda s: torch.exp(-s * s / (2 * alpha * alpha)).detach()
    return (w(sx) * sx).sum() + (w(sp) * sp).sum()


def edge_l1(x, prev, edges):
    a, b = edges[:, 0], edges[:, 1]
    return (torch.linalg.norm(x[a] - x[b], dim=1) - torch.linalg.norm(prev[a] - prev[b], dim=1)).abs().mean()


def objective(V_levels, v, P, key, edges, epoch, epochs, warmup, nearest=nearest_dense, edge_w=250.0):
    """(total, input, pred, edge) of one epoch; v the template (detached here)."""
    n = len(P)
    T = n - 1
    src = lambda g: P[g + 1 if g < key else g]
    L_in = sum(robust_chamfer(apply(step(V_levels, g, src(g)), src(g)), P[g if g < key else g + 1], nearest)
               for g in range(T)) / T
    zero = torch.zeros(())
    if epoch < warmup:
        return L_in, L_in, zero, zero
    v = v.detach()
    lens = [key, n - 1 - key]
    M = max(lens)
    x = [v, v]
    A = [torch.cat([torch.eye(3), torch.zeros(3, 1)], 1).expand(len(v), 3, 4)] * 2
    e = 1 - (epoch / epochs) ** 0.5
    s, S = 1.0, 0.0
    pred, edge = zero, zero
    for m in range(1, M + 1):
        live = [k for k in range(2) if lens[k] >= m]
        CD, E = zero, zero
        for k in live:
            g, t = (key - m, key - m) if k == 0 else (key + m - 1, key + m)
            A[k] = compose(A[k], step(V_levels, g, x[k]))
            nx = apply(A[k], v)
            CD = CD + robust_chamfer(nx, P[t], nearest) / len(live)
            E = E + edge_l1(nx, x[k], edges) / len(live)
            x[k] = nx
        c = s ** e
        pred = pred + c * CD / M
        edge = edge + edge_w * E / M
        S += c * CD.item()
        s /= max(1.0, 1.0 + S - L_in.item())
    return L_in + pred + edge, L_in, pred, edge


def step_loss(U_levels, u, P, key, edges, epoch, epochs, warmup, field_solve, template_solve, nearest=nearest_dense):
    """One training step's loss parts of the fields' U (per level) and the
    template's Large-Steps u: (total, input, pred, edge) of the objective
    and the template's robust Chamfer to the keyframe's points; the step
    minimises total + template. field_solve: field_solvers' per level;
    template_solve: v = (I + 16 L)^-1 u."""
    V = [solve(U) for solve, U in zip(field_solve, U_levels)]
    v = template_solve(u)
    template = robust_chamfer(v, P[key], nearest)
    return objective(V, v, P, key, edges, epoch, epochs, warmup, nearest) + (template,)

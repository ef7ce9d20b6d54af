"""PyTorch peer of bench_train_step's pdg row: one epoch of PDG's
optimisation after its warm-up (tests/pytorch/pdg_torch.py's step_loss:
the input term over every transition, both chains from the keyframe with
their catch-up weights, 250 x the edge-length L1, the template's robust
Chamfer to the keyframe's points through its Large-Steps parameters;
backward; torch.optim.Adam with a group per level at 0.005 * 1.1^l and
the template's u at 1e-4), float32 on the CPU with
torch.set_num_threads(threads).

The data are the C training's own, written by the bench to DATA_DIR:
every frame's cloud in the fields' cube (points_<t>.npy), the template as
it starts (template_verts.npy, template_faces.npy), and the keyframe. As
in C, the fields start at zero and u = (I + 16 L) v, L the uniform
Laplacian of the template's edges. The grids' solve V = M^-1 U is exact
in the eigenbasis of the path matrices (nt.basis_solver, as tcbench's),
every transition's values in one solve per level; the samples are
grid_sample's. The template's v = (I + 16 L)^-1 u is a sparse LU
factorised once (scipy's splu, in double: the release prefactorises with
cholespy), inside an autograd op whose backward is the same solve (M is
symmetric). The Chamfers' nearest neighbours come from the distance
matrix's GEMM form without autograd, then the matches' distances with it
(nt.nearest_sq_gemm, each way). glibc keeps freed memory for reuse
(torch_peer.keep_freed_memory: else every distance matrix is faulted in
afresh).

The epochs count from 0 with every term active, as the C row's training
(its train_steps' main phase: warm-up 0), the catch-up exponent following epoch / EPOCHS. One warm-up
step, then `iters` timed steps. Prints one line: "<mean ms per step>
<peak RSS of this process in KiB>"; with --losses, the first two steps'
loss parts on stderr. Exit 77 (and a message on stderr) when torch or
scipy cannot be imported.

usage: train_step_pdg_torch.py DATA_DIR FRAMES KEY EPOCHS LEVELS ITERS THREADS [--losses]
"""
import os
import sys

import numpy as np

import torch_peer

torch, pt, nt, sparse, sparse_linalg = torch_peer.import_reference("pdg_torch", "neupig_torch", "scipy.sparse",
                                                                   "scipy.sparse.linalg")


def large_steps(E, v, lam=16.0):
    """(u = (I + lam L) v with gradients, the solve u -> v as an autograd
    op), L the uniform Laplacian of the edges E [ne][2]."""
    nv = v.shape[0]
    a, b = E[:, 0].numpy(), E[:, 1].numpy()
    ones = np.ones(len(a))
    L = sparse.coo_matrix((np.concatenate([-ones, -ones, ones, ones]),
                           (np.concatenate([a, b, a, b]), np.concatenate([b, a, a, b]))), shape=(nv, nv))
    M = (sparse.identity(nv) + lam * L).tocsc()
    lu = sparse_linalg.splu(M)

    def solve(x):
        return torch.from_numpy(lu.solve(x.detach().double().numpy())).float()

    class Solve(torch.autograd.Function):
        @staticmethod
        def forward(ctx, u):
            return solve(u)

        @staticmethod
        def backward(ctx, g):
            return solve(g)

    u = torch.from_numpy(M @ v.double().numpy()).float().requires_grad_()
    return u, Solve.apply


def nearest_gemm(X, P):
    """Squared distances to the nearest point of the other cloud, both ways
    (nt.nearest_sq_gemm each way)."""
    return nt.nearest_sq_gemm(X, P), nt.nearest_sq_gemm(P, X)


def main():
    data = sys.argv[1]
    frames, key, epochs, levels, iters, threads = (int(x) for x in sys.argv[2:8])
    losses = sys.argv[8:] == ["--losses"]
    torch_peer.start(torch, threads)

    def load(name):
        return torch.from_numpy(np.load(os.path.join(data, name)))

    P = [load(f"points_{t}.npy") for t in range(frames)]
    E = torch_peer.edges(load("template_faces.npy").long())
    u, template_solve = large_steps(E, load("template_verts.npy"))
    U = [torch.zeros(frames - 1, (1 + 2 * l) ** 3, 3, requires_grad=True) for l in range(levels)]
    groups = [{"params": [U_l], "lr": 0.005 * 1.1 ** l} for l, U_l in enumerate(U)] + [{"params": [u], "lr": 1e-4}]
    opt = torch.optim.Adam(groups)
    field_solve = pt.field_solvers(levels, nt.basis_solver)
    epoch = [0]

    def step():
        opt.zero_grad()
        parts = pt.step_loss(U, u, P, key, E, epoch[0], epochs, 0, field_solve, template_solve, nearest_gemm)
        (parts[0] + parts[4]).backward()
        opt.step()
        if losses and epoch[0] < 2:
            print("pdg epoch %d, torch: total %.7g input %.7g pred %.7g edge %.7g template %.7g"
                  % ((epoch[0],) + tuple(x.item() for x in parts)), file=sys.stderr)
        epoch[0] += 1

    torch_peer.time_steps(step, 1, iters)


if __name__ == "__main__":
    main()

"""PyTorch peer of bench_train_step's neupig row: one epoch of Neu-PiG's
optimisation (tests/pytorch/neupig_torch.py's reference loss: every frame's
deformation, the robust two-way Chamfer, the pdg confidence, the edge
term; backward; torch.optim.Adam with the reference's rates: 0.005 * 2.5^l
per position level, 0.005 the normal grid, 1e-3 the MLP), float32 on the
CPU with torch.set_num_threads(threads).

The template is the C method's own (TEMPLATE_OBJ, written by the bench:
the Poisson surface of the calibration sequence's keyframe), mapped into
the grids' cube as the method maps it (centred, half its largest side to
0.95); its vertex normals area-weighted, its edges and their lengths as
the C code takes them. The frames' clouds: POINTS points of the template's
faces per frame, turned by 0.1 rad per frame about y and jittered,
drawn once (data loading is not part of the step). The grids start at zero
and the last layer at zero, as in the reference; the solve is exact in the
eigenbasis of the path matrices (as tcbench's). The Chamfer's nearest neighbours come from the
distance matrix's GEMM form, then the distances of the matches with
autograd (pytorch3d's knn_points does the same brute-force search).

One warm-up step, then `iters` timed steps. Prints one line:
"<mean ms per step> <peak RSS of this process in KiB>". Exit 77 (and a
message on stderr) when torch cannot be imported.

usage: train_step_neupig_torch.py TEMPLATE_OBJ FRAMES POINTS LEVELS FEATURES HIDDEN ITERS THREADS
       (the paper's: 8 levels of 30 features, width 512, 5 000 points)
"""
import math
import sys

import torch_peer

torch, nt = torch_peer.import_reference("neupig_torch")


def read_obj(path):
    verts, faces = [], []
    for line in open(path):
        f = line.split()
        if f and f[0] == "v":
            verts.append([float(x) for x in f[1:4]])
        elif f and f[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in f[1:4]])
    return torch.tensor(verts), torch.tensor(faces)


def problem(path, frames, points):
    V, Fc = read_obj(path)
    lo, hi = V.min(0).values, V.max(0).values
    V = (V - (lo + hi) / 2) / ((hi - lo).max() / 2) * 0.95
    a, b, c = V[Fc[:, 0]], V[Fc[:, 1]], V[Fc[:, 2]]
    fn = torch.linalg.cross(b - a, c - a)  # twice the area times the unit normal
    N = torch.zeros_like(V).index_add_(0, Fc.reshape(-1), fn.repeat_interleave(3, 0))
    N = N / N.norm(dim=-1, keepdim=True).clamp_min(1e-12)
    E = torch_peer.edges(Fc)
    area = fn.norm(dim=-1)
    P = []
    for t in range(frames):
        face = torch.multinomial(area, points, replacement=True)
        w = torch.rand(points, 2)
        w = torch.where(w.sum(1, keepdim=True) > 1, 1 - w, w)
        x = a[face] + w[:, :1] * (b[face] - a[face]) + w[:, 1:] * (c[face] - a[face])
        ct, st = math.cos(0.1 * t), math.sin(0.1 * t)
        R = torch.tensor([[ct, 0, st], [0, 1, 0], [-st, 0, ct]])
        P.append(x @ R.T + 0.005 * torch.randn(points, 3))
    base_len = (V[E[:, 0]] - V[E[:, 1]]).norm(dim=-1)
    return nt.Problem(V, N, P, E, base_len, frames // 2)


def main():
    path = sys.argv[1]
    frames, points, levels, features, hidden, iters, threads = (int(x) for x in sys.argv[2:9])
    torch_peer.start(torch, threads, 1)
    a = nt.Arch(levels, 2, 3, features, 4, 2, 4, hidden, 0.4, 1.5, 0.4, 100.0, 0.3)
    prob = problem(path, frames, points)
    grids = [torch.zeros(r ** 3 * w, requires_grad=True) for r, w in zip(nt.resolutions(a), nt.widths(a))]
    layers = [torch.nn.Linear(a.F + a.Fn + 2 * a.J, a.H), torch.nn.Linear(a.H, a.H), torch.nn.Linear(a.H, 7)]
    torch.nn.init.zeros_(layers[2].weight), torch.nn.init.zeros_(layers[2].bias)
    mlp = [p for layer in layers for p in (layer.weight, layer.bias)]
    groups = [{"params": [g], "lr": 0.005 * 2.5 ** l} for l, g in enumerate(grids[:-1])]
    groups += [{"params": [grids[-1]], "lr": 0.005}, {"params": mlp, "lr": 1e-3}]
    opt = torch.optim.Adam(groups)
    solve = nt.solvers(a, nt.basis_solver)
    epoch = [0]  # the confidence's exponent follows the epoch, as in a fit of iters + 1 epochs

    def step():
        opt.zero_grad()
        nt.loss(a, grids, mlp, prob, solve, epoch[0], iters + 1, nt.nearest_sq_gemm)[0].backward()
        opt.step()
        epoch[0] += 1

    torch_peer.time_steps(step, 1, iters)


if __name__ == "__main__":
    main()

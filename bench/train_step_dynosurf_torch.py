"""PyTorch peer of bench_train_step's dynosurf row: one step of DynoSurf's
stage 2 (tests/pytorch/dynosurf_torch.py's pieces, as
tests/pytorch/dynosurf_motion_check.py assembles them; the reference's
code/loss.py calc_joint_loss): every frame's template carried by the
control-point deformer, surface samples of each (pytorch3d's
sample_points_from_meshes: faces by area, uniform barycentrics), the robust
Chamfer and normal terms both ways, the keyframe's identity, the SDF-sign
term on grid picks drawn afresh, the edge smoothness over each frame's two
neighbours; backward; torch.optim.Adam (lr 1e-4) over the control points
and both networks; float32 on the CPU with torch.set_num_threads(threads).

The data are the C training's own, written by the bench to DATA_DIR:
every frame's points and normals in DynoSurf's frame (points_<t>.npy,
normals_<t>.npy), the template (template_verts.npy, template_faces.npy),
the grid and its SDF (grid_verts.npy, grid_sdf.npy) and the deformer's
parameters as the C training started them (deformer.npy). Nearest
neighbours come from torch.cdist without autograd (the reference's
pytorch3d knn_points has no CPU kernel worth timing), the matches'
distances with it. glibc keeps freed memory for reuse
(torch_peer.keep_freed_memory).

One warm-up step, then `iters` timed steps. Prints one line: "<mean ms per
step> <peak RSS of this process in KiB>". Exit 77 (and a message on
stderr) when torch cannot be imported.

usage: train_step_dynosurf_torch.py DATA_DIR FRAMES KEY SAMPLES GRID_SAMPLES BLEND_OFFSET ITERS THREADS
"""
import sys

import numpy as np

import torch_peer

torch, ds = torch_peer.import_reference("dynosurf_torch")

K = 30  # control points (methods/dynosurf/deformer.h)
WEIGHTS = {"chamfer": 500, "normal": 0.001, "identity": 1, "sdf_sign": 100, "smooth": 1000}


def robust_way(a, na, b, nb):
    """calc_robust_chamfer_single_direction: sum of w(d^2) d^2 (w detached) and
    the mean of 1 - |cos| over a's nearest points in b."""
    with torch.no_grad():
        j = torch.cdist(a, b).argmin(1)
    s = ((a - b[j]) ** 2).sum(1)
    w = torch.exp(-s.detach() ** 2 / (2 * 0.3 ** 2))
    cos = torch.nn.functional.cosine_similarity(na, nb[j], dim=1, eps=1e-6)
    return (w * s).sum(), (1 - cos.abs()).mean()


def draw(verts, faces, n):
    """sample_points_from_meshes' draws: faces in proportion to their areas,
    barycentrics (1 - sqrt(u), sqrt(u)(1 - v), sqrt(u) v)."""
    with torch.no_grad():
        a, b, c = (verts[faces[:, k]] for k in range(3))
        area = torch.cross(b - a, c - a, dim=1).norm(dim=1)
        face = torch.multinomial(area, n, replacement=True)
        u, v = torch.rand(n).sqrt(), torch.rand(n)
        w = torch.stack([1 - u, u * (1 - v), u * v], 1)
    return face, w


def main():
    data = sys.argv[1]
    F, key, samples, picks, blend_offset, iters, threads = (int(x) for x in sys.argv[2:9])
    torch_peer.start(torch, threads, 0)
    load = lambda name: torch.from_numpy(np.load(f"{data}/{name}.npy"))
    tv, tf = load("template_verts"), load("template_faces").long()
    grid_v, grid_sdf = load("grid_verts"), load("grid_sdf")[:, 0]
    pts = [load(f"points_{t}") for t in range(F)]
    nrm = [load(f"normals_{t}") for t in range(F)]
    params = load("deformer")[0]
    control = params[:3 * K].reshape(K, 3).clone().requires_grad_(True)
    transform_net, t_lin = ds.mlp(params[3 * K:blend_offset], ds.TRANSFORM_WIDTHS, 0)
    blend_net, b_lin = ds.mlp(params[blend_offset:], ds.BLEND_WIDTHS, 0)
    leaves = [control] + [l.weight for l in t_lin + b_lin]
    opt = torch.optim.Adam(leaves, lr=1e-4)
    nbrs = [sorted([min(t + 1, F - 1), max(t - 1, 0)]) for t in range(F)]

    def step():
        opt.zero_grad()
        pick = torch.randperm(grid_v.shape[0])[:picks]
        y, yhat = grid_v[pick], grid_sdf[pick]
        raw, R = ds.deformer_transforms(control, transform_net, list(range(F)))
        wt, wg = ds.deformer_weights(control, blend_net, tv), ds.deformer_weights(control, blend_net, y)
        X = torch.stack([ds.deform(tv, wt, R[t], raw[t]) for t in range(F)])
        Y = torch.stack([ds.deform(y, wg, R[t], raw[t]) for t in range(F)])
        cham = normal = 0
        for t in range(F):
            xs, nxs = ds.sample_points(X[t], tf, *draw(X[t], tf, samples))
            c1, n1 = robust_way(xs, nxs, pts[t], nrm[t])
            c2, n2 = robust_way(pts[t], nrm[t], xs, nxs)
            cham, normal = cham + (c1 + c2) / F, normal + (n1 + n2) / F
        identity = (raw[key] ** 2).sum()
        s = torch.stack([ds.approx_sdf(Y[t], pts[t], nrm[t], search=torch.float32) for t in range(F)])
        rho = torch.softmax(-s.detach() ** 2 / (2 * 0.1 ** 2), 0)
        sdf_sign = (rho * torch.sigmoid(100 * yhat)[None] - rho * torch.sigmoid(100 * s)).abs().mean()
        D = torch.stack([X[u] - X[t] for t in range(F) for u in nbrs[t]])
        smooth = sum(((D[:, tf[:, a]] - D[:, tf[:, b]]) ** 2).sum() for a, b in ((0, 1), (1, 2), (0, 2))) / (3 * len(tf))
        terms = {"chamfer": cham, "normal": normal, "identity": identity, "sdf_sign": sdf_sign, "smooth": smooth}
        total = sum(WEIGHTS[k] * v for k, v in terms.items())
        total.backward()
        opt.step()

    torch_peer.time_steps(step, 1, iters)


if __name__ == "__main__":
    main()

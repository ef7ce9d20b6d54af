"""PyTorch peer of bench_train_step's dynosurf row: one step of DynoSurf's
stage 2 (tests/pytorch/dynosurf_torch.py's motion_terms, the loss
tests/pytorch/dynosurf_motion_check.py holds the C step to; the
reference's code/loss.py calc_joint_loss): every frame's template carried by the
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
    draws = lambda t, X: draw(X, tf, samples)

    def step():
        opt.zero_grad()
        pick = torch.randperm(grid_v.shape[0])[:picks]
        terms = ds.motion_terms(control, transform_net, blend_net, tv, tf, pts, nrm, grid_v[pick], grid_sdf[pick],
                                key, draws, search=torch.float32)
        sum(ds.MOTION_WEIGHTS[k] * v for k, v in terms.items()).backward()
        opt.step()

    torch_peer.time_steps(step, 1, iters)


if __name__ == "__main__":
    main()

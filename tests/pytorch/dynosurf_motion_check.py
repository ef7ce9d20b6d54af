"""One step of DynoSurf's stage 2 (methods/dynosurf/motion.c) against the
reference's rebuilt in PyTorch in float64 (tests/pytorch/dynosurf_torch.py;
code/loss.py calc_joint_loss and its helpers) with the C side's weights,
template, frames, grid picks and surface draws
(tests/pytorch/dynosurf_motion_step.c): the five terms (robust Chamfer
and normals with the Welsch weights detached, the keyframe's identity,
the SDF sign with ρ detached, the edge smoothness over each frame's two
neighbours), their weighted sum, the gradient in the control points and
both networks — the sum's and each term's alone — and torch.optim.Adam's
first step. 1e-4 relative (each
block to its largest entry; terms to their value); each term's own
gradient to 1e-3, as the normal term's reaches the control points as a
difference of far larger contributions (1e-9 of them in float: 2e-4
measured), and a formula's error is of its own size.

usage: dynosurf_motion_check.py HELPER_BINARY WORKDIR
"""
import json
import os
import subprocess
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dynosurf_torch import (BLEND_WIDTHS, MOTION_WEIGHTS, TRANSFORM_WIDTHS, mlp,  # noqa: E402
                            motion_terms)

binary, work = sys.argv[1], sys.argv[2]
subprocess.run([binary, "5", work], check=True)
meta = json.load(open(f"{work}/meta.json"))
P, K, F, n, m, nf, g, ms, key, B = (meta[k] for k in ("P", "K", "F", "n", "m", "nf", "g", "ms", "key", "blend_offset"))
load = lambda name, shape, dtype=np.float32: torch.from_numpy(np.fromfile(f"{work}/{name}", dtype=dtype).reshape(shape))
f64 = lambda name, shape: load(name, shape).double()
worst = 0.0


def close(name, ours, theirs, tol=1e-4):
    global worst
    theirs = torch.as_tensor(theirs, dtype=torch.float64).detach()
    ours = torch.as_tensor(ours, dtype=torch.float64)
    err = (ours - theirs).abs().max().item()
    scale = max(theirs.abs().max().item(), 1e-12)
    assert err <= tol * scale, f"{name}: {err:.3e} against {scale:.3e}"
    worst = max(worst, err / scale)


params = f64("params.bin", (P,))
control = params[:3 * K].reshape(K, 3).clone().requires_grad_(True)
transform_net, t_lin = mlp(params[3 * K:B], TRANSFORM_WIDTHS, 0, torch.float64)
blend_net, b_lin = mlp(params[B:], BLEND_WIDTHS, 0, torch.float64)
tv, tf = f64("tv.bin", (m, 3)), load("tf.bin", (nf, 3), np.int32).long()
pts, nrm = f64("pts.bin", (F, n, 3)), f64("nrm.bin", (F, n, 3))
y, yhat = f64("y.bin", (g, 3)), f64("yhat.bin", (g,))
draw_face, draw_w = load("draw_face.bin", (F, ms), np.int32).long(), f64("draw_w.bin", (F, ms, 3))

values = motion_terms(control, transform_net, blend_net, tv, tf, pts, nrm, y, yhat, key,
                      lambda t, X: (draw_face[t], draw_w[t]))
terms = {name: MOTION_WEIGHTS[name] * v for name, v in values.items()}
leaves = [control] + [l.weight for l in t_lin + b_lin]
for name, term in terms.items():  # each term's gradient alone: a small term's error would hide in the sum's
    grads = torch.autograd.grad(term, leaves, retain_graph=True, allow_unused=True)
    theirs = torch.cat([(gr if gr is not None else torch.zeros_like(l)).reshape(-1) for gr, l in zip(grads, leaves)])
    mine = f64(f"grad_{name}.bin", (P,))
    for block, lo, hi in (("control points", 0, 3 * K), ("MLP_T", 3 * K, B), ("MLP_W", B, P)):
        if theirs[lo:hi].abs().max() > 0 or mine[lo:hi].abs().max() > 0:
            close(f"{name} gradient, {block}", mine[lo:hi], theirs[lo:hi], 1e-3)
total = sum(terms.values())
total.backward()
for name, value in list(values.items()) + [("total", total)]:
    close(name, meta[name], value.item())
grad = torch.cat([control.grad.reshape(-1)] + [l.weight.grad.reshape(-1) for l in t_lin + b_lin])
ours = f64("grad.bin", (P,))
close("control-point gradient", ours[:3 * K], grad[:3 * K])
close("MLP_T gradient", ours[3 * K:B], grad[3 * K:B])
close("MLP_W gradient", ours[B:], grad[B:])
p = params.clone().float().requires_grad_(True)
p.grad = grad.float()
torch.optim.Adam([p], lr=1e-4).step()
close("Adam step", f64("after.bin", (P,)), p.detach(), 1e-5)
print(f"dynosurf stage 2: five terms, the deformer's gradient and Adam's step as PyTorch's over {F} frames "
      f"(float64; worst {worst:.1e} relative)")

"""DynoSurf's deformer (methods/dynosurf/deformer.c) against the
reference's ControlPts_deformer rebuilt in PyTorch in float64
(tests/pytorch/dynosurf_torch.py) with the C side's weights: the blend
weights, the raw transforms, the deformed points of three frames, and
autograd's gradient of Σ gX·X + Σ graw·raw in the control points, MLP_T
and MLP_W; then the blend pretraining's MSE to the Gaussian weights and
its gradient. float64 on this side makes the comparison one of formulas:
the C side's float rounding is far below the 1e-4 asked (each block to
its largest entry).

usage: dynosurf_deformer_check.py HELPER_BINARY WORKDIR
"""
import json
import os
import subprocess
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dynosurf_torch import (BLEND_WIDTHS, TRANSFORM_WIDTHS, deform, deformer_transforms,  # noqa: E402
                            deformer_weights, gaussian_weights, mlp)

binary, work = sys.argv[1], sys.argv[2]
subprocess.run([binary, "64", "4", work], check=True)
meta = json.load(open(f"{work}/meta.json"))
P, K, N, F, B = meta["P"], meta["K"], meta["N"], meta["F"], meta["blend_offset"]
load = lambda name, shape: torch.from_numpy(np.fromfile(f"{work}/{name}", dtype=np.float32).reshape(shape)).double()
worst = 0.0


def close(name, ours, theirs, tol=1e-4):
    global worst
    err = (ours - theirs.detach()).abs().max().item()
    scale = max(theirs.abs().max().item(), 1e-12)
    assert err <= tol * scale, f"{name}: {err:.3e} against {scale:.3e}"
    worst = max(worst, err / scale)


def build(params):
    control = params[:3 * K].reshape(K, 3).clone().requires_grad_(True)
    transform_net, t_lin = mlp(params[3 * K:B], TRANSFORM_WIDTHS, 0, torch.float64)
    blend_net, b_lin = mlp(params[B:], BLEND_WIDTHS, 0, torch.float64)
    return control, transform_net, blend_net, t_lin + b_lin


def flat_grad(control, linears):
    return torch.cat([control.grad.reshape(-1)] + [m.weight.grad.reshape(-1) for m in linears])


params = load("params.bin", (P,))
control, transform_net, blend_net, linears = build(params)
x = load("x.bin", (N, 3))
w = deformer_weights(control, blend_net, x)
raw, R = deformer_transforms(control, transform_net, meta["frames"])
close("blend weights", load("w.bin", (N, K)), w)
close("raw transforms", load("raw.bin", (F, K, 6)), raw)
X = torch.stack([deform(x, w, R[f], raw[f]) for f in range(F)])
close("deformed points", load("X.bin", (F, N, 3)), X)
((X * load("gX.bin", (F, N, 3))).sum() + (raw * load("graw.bin", (F, K, 6))).sum()).backward()
grad, ours = flat_grad(control, linears), load("grad.bin", (P,))
close("control-point gradient", ours[:3 * K], grad[:3 * K])
close("MLP_T gradient", ours[3 * K:B], grad[3 * K:B])
close("MLP_W gradient", ours[B:], grad[B:])

control, transform_net, blend_net, linears = build(params)
x2 = load("x2.bin", (N, 3))
loss = torch.nn.functional.mse_loss(deformer_weights(control, blend_net, x2), gaussian_weights(control.detach(), x2))
loss.backward()
close("pretraining loss", torch.tensor(meta["pre_loss"]), loss)
close("pretraining MLP_W gradient", load("pre_grad.bin", (P,))[B:],
      torch.cat([m.weight.grad.reshape(-1) for m in linears[len(TRANSFORM_WIDTHS) - 1:]]))
print(f"dynosurf deformer: blend weights, transforms, deformed points and every gradient as PyTorch's "
      f"(float64; worst {worst:.1e} relative)")

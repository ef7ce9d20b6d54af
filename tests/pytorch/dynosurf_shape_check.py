"""DynoSurf's shape network in PyTorch, built as the reference's Decoder
(code/model/dmtet_network.py: the NeRF embedder with 5 log-sampled
frequencies and the input kept, Linear(bias=False) layers 33→128→…→4 with
LeakyReLU between them; trainer.py's sdf = out[:, 0] and
v = x + tanh(out[:, 1:4]) · edge), loaded with the C side's weights
(tests/pytorch/dynosurf_shape.c), against methods/dynosurf/shape.c: the
outputs, the read-out, and autograd's weight gradients for the same
upstream gradients. Passes at 1e-4 relative (to each block's largest entry).

usage: dynosurf_shape_check.py DYNOSURF_SHAPE_BINARY WORKDIR
"""
import os
import subprocess
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dynosurf_torch import SHAPE_WIDTHS as WIDTHS, shape_forward, shape_net  # noqa: E402

binary, work = sys.argv[1], sys.argv[2]
N, EDGE, SEED = 64, 0.02, 5
subprocess.run([binary, str(N), str(EDGE), str(SEED), work], check=True)
load = lambda name, shape: torch.from_numpy(np.fromfile(f"{work}/{name}", dtype=np.float32).reshape(shape))


P = sum(a * b for a, b in zip(WIDTHS[:-1], WIDTHS[1:]))
net, linears = shape_net(load("params.bin", (P,)))
x = load("x.bin", (N, 3))
out, sdf, v = shape_forward(net, x, EDGE)
(sdf * load("dsdf.bin", (N,))).sum().add((v * load("dv.bin", (N, 3))).sum()).backward()


def close(name, ours, theirs):
    err = (ours - theirs).abs().max().item()
    scale = max(theirs.abs().max().item(), 1e-12)
    assert err <= 1e-4 * scale, f"{name}: {err:.3e} against {scale:.3e}"
    return err / scale


worst = max(close("out", load("out.bin", (N, 4)), out.detach()),
            close("sdf", load("sdf.bin", (N,)), sdf.detach()),
            close("v", load("v.bin", (N, 3)), v.detach()))
grad = load("grad.bin", (P,))
at = 0
for i, m in enumerate(linears):
    k = m.weight.numel()
    worst = max(worst, close(f"dW{i + 1}", grad[at:at + k].reshape(m.weight.shape), m.weight.grad))
    at += k
print(f"dynosurf shape network: outputs, read-out and the six weight gradients as PyTorch's "
      f"(worst {worst:.1e} relative)")

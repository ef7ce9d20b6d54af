"""PyTorch peer of bench_train_step: the reference training step of one atlas
method (tests/pytorch/atlas_torch.py: forward, the method's loss with the
UV-Jacobians by autograd for dsr and mca, backward, which is then a double
backward, torch.optim.Adam at lr 1e-3) on a batch of 4 shapes, float32 on
the CPU with torch.set_num_threads(threads); the Chamfer loss's distance
matrix by torch's fast GEMM form.

The batch's clouds are drawn once (data loading is not part of the step, as
in TCSR, whose DataLoader prepares batches aside); the UV samples are fresh
every iteration, as in training. `warmup` steps, then `iters` timed steps.

Prints one line: "<mean ms per step> <peak RSS of this process in KiB>".
Exit 77 (and a message on stderr) when torch cannot be imported.

usage: train_step_torch.py METHOD C P M N ITERS THREADS [WARMUP]
"""
import sys

import torch_peer

torch, atlas_torch = torch_peer.import_reference("atlas_torch")

BATCH = 4


def main():
    method = sys.argv[1]
    c, p, m, n, iters, threads = (int(a) for a in sys.argv[2:8])
    warmup = int(sys.argv[8]) if len(sys.argv) > 8 else 1
    torch_peer.start(torch, threads, 1)
    model = atlas_torch.Atlas(c, p)
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    clouds = torch.rand(BATCH, n, 3) - 0.5
    area = torch.ones(BATCH)

    def step():
        opt.zero_grad()
        atlas_torch.method_loss(method, model, clouds, torch.rand(m, 2), area,
                                exact_nn=False).backward()
        opt.step()

    torch_peer.time_steps(step, warmup, iters)


if __name__ == "__main__":
    main()

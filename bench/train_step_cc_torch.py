"""PyTorch peer of the C CC training step (methods/cycle/train.c
tcb_cc_train_step): the CC code's Trainer.train_iteration in
tests/pytorch/cc_torch.py — six forward_chamfer calls with the CC code's
latent reuse, ASSYM_2 Chamfer, cycle-2 and cycle-3, backward,
torch.optim.Adam at lr 1e-3 — on a fresh network of the given sizes
(the CC code's initialisation), float32 on the CPU with
torch.set_num_threads(threads). The nearest neighbours come from torch's
fast GEMM form of cdist (the benchmark needs no exact tie-breaking).

The batch is B random triplets of N points, uniform in [−1, 1]³, drawn
once (data loading and augmentation are not part of the step; the CC code
prepares them in DataLoader workers). By default the steady state after
the warm-up: six network calls. With --selfrec, the warm-up's step: also
compute_loss_selfReconstruction, P4 = P3 · R_y(θ) anisotropically scaled
by 1 + U(−0.5, 0.5) per shape and axis (θ ∈ U(±20°) per shape, drawn
once, the scales drawn every step as the CC code does), and the two
self-reconstruction calls network(P3, P4), network(P4, P3).

One warm-up step, then `iters` timed steps. Prints one line:
"<mean ms per step> <peak RSS of this process in KiB>". Exit 77 (and a
message on stderr) when torch cannot be imported.

usage: train_step_cc_torch.py C Z H L B N ITERS THREADS [--selfrec]
       (the CC code's sizes: C 1024, Z 512, H 64, L 6, B 16, N 2500)
"""
import math
import sys

import torch_peer

torch, cc_torch = torch_peer.import_reference("cc_torch")


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    selfrec = "--selfrec" in sys.argv[1:]
    if len(args) != 8:
        print("usage: train_step_cc_torch.py C Z H L B N ITERS THREADS [--selfrec]",
              file=sys.stderr)
        sys.exit(2)
    c, z, h, l, b, n, iters, threads = (int(a) for a in args)
    torch_peer.start(torch, threads, 1)
    model = cc_torch.build(c, z, h, l)
    model.train()
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    P1, P2, P3 = (2 * torch.rand(b, n, 3) - 1 for _ in range(3))
    theta = (torch.rand(b) - 0.5) * (math.pi / 4.5)
    cos, sin, zero, one = torch.cos(theta), torch.sin(theta), torch.zeros(b), torch.ones(b)
    # augment.h: rot_matrix = R_y(θ)ᵀ, as the CC code's augmentation returns it
    rot = torch.stack([torch.stack([cos, zero, -sin], 1), torch.stack([zero, one, zero], 1),
                       torch.stack([sin, zero, cos], 1)], 1)

    def step():
        opt.zero_grad()
        P4 = cc_torch.selfrec_target(P3, rot, torch.rand(b, 1, 3) - 0.5) if selfrec else None
        total, _, _ = cc_torch.train_iteration_loss(model, P1, P2, P3, P4, exact_nn=False)
        total.backward()
        opt.step()

    torch_peer.time_steps(step, 1, iters)


if __name__ == "__main__":
    main()

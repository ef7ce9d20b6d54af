"""One training step of each atlas method, tcbench's C against PyTorch.

tests/pytorch/atlas_step_export.c ran ONE tcb_atlas_train_step per method
and wrote the weights before it, the batch (input clouds, UV samples, GT
areas), the total loss, the gradient and the weights after Adam. Here the
network (atlas_torch.py) is rebuilt with those weights and the step redone
from the reference definitions, autograd doing the backward (a double
backward through the Jacobians for dsr and mca):
    atlasnet  L = L_CD
    dsr       L = L_CD + 0.001 · L_sciso
    mca       L = L_CD + 0.1 · L_mc
Compared, with torch in float64 (the exact reference for the float32 C
code) and in float32:
  * the total loss: |C − torch| ≤ 1e-4 · |torch|;
  * the gradient of every parameter tensor: max |C − torch| ≤ 1e-4 ·
    max |torch| over the tensor;
  * the weights after one torch.optim.Adam step (the exported lr, β1, β2,
    eps): max (|θ_C − θ_torch| − ulp) ≤ 1e-4 · max |Δ_torch| over the
    tensor, Δ = θ_after − θ_before. Relative to the update (about lr), not
    to the weights, so that an lr error is not drowned by them; ulp is one
    float32 unit in the last place of θ_torch, the resolution in which both
    sides store the weights (at |θ| ≈ 17, 1e-3 of an update of 1e-3).
    torch's Adam is fed the C gradient, checked above: a first Adam step is
    ≈ −lr · sign(g), so entries whose gradient is within the gradient
    tolerance of zero may legitimately flip, and that would say nothing
    about the optimizer.
Observed: loss ≤ 8e-8, gradients ≤ 2e-6, updates ≤ 2.3e-7 against float64
and 0 (bit-identical) against float32 torch. The check fails when
torch's α_mc, α_sciso or α_Atot is scaled by 1.001 (worst gradient errors
8.7e-4, 1.6e-3, 9.3e-4) or its lr (every update, 9.9e-4).

usage: atlas_step_check.py [-v] DIR     (-v: every tensor's errors;
                                         exit 77 when torch is missing)
"""
import copy
import json
import os
import sys

try:
    import numpy as np
    import torch

    import atlas_torch
except ImportError as exc:  # the integration test maps 77 to "skipped"
    print(f"SKIP: {exc}: the PyTorch cross-check needs python3-torch "
          "(apt-get install -y python3-torch)", file=sys.stderr)
    sys.exit(77)

TOL = 1e-4


class Case:
    """One method's exported step."""

    def __init__(self, directory):
        with open(os.path.join(directory, "case.json")) as f:
            self.meta = json.load(f)
        c, p, b, n, m = (self.meta[k] for k in ("C", "P", "B", "N", "M"))
        self.model = atlas_torch.Atlas(c, p)
        manifest = atlas_torch.load_weights(self.model, directory, "weights")
        flat = {"before": atlas_torch.read_flat(directory, "weights")[1],
                "after": atlas_torch.read_flat(directory, "updated")[1],
                "grads": atlas_torch.read_f32(directory, "grads.f32", (manifest["nparams"],))}
        self.before, self.after, self.grads = (atlas_torch.unflatten(manifest, flat[k])
                                               for k in ("before", "after", "grads"))
        self.clouds = atlas_torch.read_f32(directory, "clouds.f32", (b, n, 3))
        self.uv = atlas_torch.read_f32(directory, "uv.f32", (m, 2))
        self.area = np.array(self.meta["area"])


def torch_step(case, dtype):
    """(loss, {name: gradient}, {name: Adam update fed the C gradient})."""
    model = copy.deepcopy(case.model).to(dtype)
    loss = atlas_torch.method_loss(case.meta["method"], model,
                                   torch.from_numpy(case.clouds).to(dtype),
                                   torch.from_numpy(case.uv).to(dtype),
                                   torch.from_numpy(case.area).to(dtype))
    loss.backward()
    params = dict(model.named_parameters())
    grads = {n: q.grad.detach().double().numpy() for n, q in params.items()}
    opt = torch.optim.Adam(model.parameters(), lr=case.meta["lr"],
                           betas=(case.meta["beta1"], case.meta["beta2"]), eps=case.meta["eps"])
    for name, q in params.items():
        q.grad = torch.from_numpy(case.grads[name]).to(dtype)
    before = {n: q.detach().clone() for n, q in params.items()}
    opt.step()
    updates = {n: (q.detach() - before[n]).double().numpy() for n, q in params.items()}
    return loss.item(), grads, updates


def update_error(before, after_c, update):
    """The Adam measure of the docstring; update is torch's Δ in float64."""
    theta = before.astype(np.float64) + update
    ulp = np.spacing(np.abs(theta).astype(np.float32)).astype(np.float64)
    excess = np.maximum(np.abs(after_c - theta) - ulp, 0.0)
    scale = np.abs(update).max()
    return excess.max() / (scale if scale > 0 else 1.0)


def check(case, dtype, verbose):
    """Prints one row (and with verbose one line per tensor); returns the
    number of failed comparisons."""
    loss, grads, updates = torch_step(case, dtype)
    loss_err = abs(case.meta["loss"] - loss) / abs(loss)
    grad_err = {n: atlas_torch.rel_error(case.grads[n], g) for n, g in grads.items()}
    step_err = {n: update_error(case.before[n], case.after[n], u) for n, u in updates.items()}
    name = str(dtype).split(".")[-1]
    if verbose:
        for n in grads:
            print(f"    {name:8} {n:28} grad {grad_err[n]:.2e}  update {step_err[n]:.2e}")
    worst_g = max(grad_err, key=grad_err.get)
    worst_s = max(step_err, key=step_err.get)
    print(f"{case.meta['method']:9} {name:8} {loss_err:9.2e}  {grad_err[worst_g]:9.2e} "
          f"{worst_g:24} {step_err[worst_s]:9.2e} {worst_s}")
    fails = [f"loss {loss_err:.3g}"] if loss_err > TOL else []
    fails += [f"grad {n} {e:.3g}" for n, e in grad_err.items() if e > TOL]
    fails += [f"update {n} {e:.3g}" for n, e in step_err.items() if e > TOL]
    for f in fails:
        print(f"FAIL {case.meta['method']} torch {name}: {f} > {TOL:g}")
    return len(fails)


def main():
    args = [a for a in sys.argv[1:] if a != "-v"]
    verbose = len(args) < len(sys.argv) - 1
    torch.manual_seed(0)
    print(f"relative errors of C against torch, tolerance {TOL:g} (loss: |Δ|/|torch|; per tensor, "
          "the worst shown: grad max|Δ|/max|torch|, update max(|Δθ| − ulp)/max|Δθ_torch|)")
    print(f"{'method':9} {'torch':8} {'loss':>9}  {'grad':>9} {'(tensor)':24} "
          f"{'update':>9} (tensor)")
    failures = 0
    for method in atlas_torch.METHODS:
        case = Case(os.path.join(args[0], method))
        for dtype in (torch.float64, torch.float32):
            failures += check(case, dtype, verbose)
    if failures:
        sys.exit(1)
    print("one training step of atlasnet, dsr, mca matches PyTorch")


if __name__ == "__main__":
    main()

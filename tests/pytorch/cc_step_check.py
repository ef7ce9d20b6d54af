"""One CC training step, tcbench's C (methods/cycle/train.c) against PyTorch.

tests/pytorch/cc_step_export.c ran ONE tcb_cc_train_step of a small
network in two cases, warmup (eight network calls and the
self-reconstruction term) and steady (the six pair calls), and wrote the
weights before it, the batch the trainer used (the augmented clouds A, B,
C and in the warm-up C'), the loss and its terms, the network outputs D
of every call and the loss gradient w.r.t. them, the parameter gradient,
the weights and running statistics after the step, and the lr and Adam
constants. Here the CC code's network (cc_torch.py) is rebuilt with those
weights in training mode and the step redone as the CC code's
Trainer.train_iteration does it: triplet_chamfer_loss's six
forward_chamfer calls with its latent reuse (encoder on P1, P2, P3,
encoder2 on P2, P1, P3), ASSYM_2 Chamfer, cycle-2 and cycle-3 by
batch_cycle_2/3 with the detached nearest-neighbour indices, L2 with its
1e-8 and, in the
warm-up, compute_loss_selfReconstruction — network(P3, P4) then
network(P4, P3), both encoders afresh — with P4 the exported C' (the C
side drew its scales; the CC code would draw them inside); autograd does
the backward, then one torch.optim.Adam step. The nearest-neighbour
indices are the C side's (the trainer's maps, and the target-to-deformed
maps recomputed by the helper as losses.c does), verified here to be
nearest on the C side's D up to float32 ties: the network outputs of the
two sides differ by up to ~6e-5 of their range, enough to flip a near tie
among the step's 9600 queries (such flips are counted on torch's own D
and must be explainable by that difference), and CC's first meta layer
(ReLU(bn0(·)) on 3 channels) maps every point whose three are dead to one
common point, so exact ties abound.

Compared, with torch in float64 (the exact reference for the float32 C
code) and in float32, tolerance 1e-4 unless said:
  terms    the loss and each term: |C − torch| / |torch|, of the full
           redo and (k@D) of the loss at the C outputs D (below);
  dL/dD    the loss gradient w.r.t. each call's output, torch's autograd
           of the same loss evaluated at the C outputs D (cc_torch.losses_at:
           no network, so no forward rounding): max |C − torch| / max |torch|
           per call;
  J'gD     the parameter gradient that torch's backward of the step gives
           from the C loss gradient gD (the backward wiring: six or eight
           calls, the latents reused across calls, one encoder backward per
           cloud): max |C − torch| / max |torch| per tensor (biases whose
           exact gradient is zero, cc_torch.BEFORE_BN: against the layer
           weight's gradient);
  grad     the full redo's parameter gradient, the same measure, tolerance
           STEP_GRAD_TOL = 1e-3: this step is conditioned so that torch's own
           float32 gradient is 1.7e-4 off its float64 one (printed as
           "torch32"); a 1e-4 tolerance holds for the two halves above;
  update   the weights after Adam (the exported lr, β1, β2, eps, fed the C
           gradient as atlas_step_check.py does): max (|θ_C − θ_torch| − ulp)
           / max |Δθ_torch| per tensor;
  stats    the running statistics after the step: max (|C − torch| − ulp) /
           max |Δ_torch| per tensor, Δ the step's movement (also bounding
           the error by 1e-4 · max |torch|): the count and order of the
           batch-norm updates — encoder on clouds 0, 1, 2 (+ 2 again, 3 in
           the warm-up), encoder2 on 1, 0, 2 (+ 3, 2 again), the decoder once
           per call in call order;
  NN       the C side's indices are nearest neighbours on its D (see above);
  C'       (warm-up) the CC formula P4 = (P3 · rotᵀ)(1 + s) with C's
           rotation: s fitted per shape and axis must fit to float rounding
           and lie in (−0.5, 0.5); rot a rotation about y by ≤ 20°.
Observed (float64 / float32 torch, worst of warmup and steady): terms
4.1e-7 / 8.6e-7; dL/dD 4.6e-8 / 2.1e-7; J'gD 4.1e-5 / 3.0e-5; grad
1.5e-4 / 1.6e-4 (torch32 1.2e-4 warmup, 1.7e-4 steady); update 2.3e-7 / 0
(bit-identical); stats 2.3e-6 / 2.6e-6; every C index nearest; C' fits
to 7.8e-8; 5 of the 9600 indices would flip on torch's own D, all within
the forward's rounding.
Negative controls (--perturb=WHAT makes torch deliberately wrong); each
fails, worst errors: a term × 1.001 — chamfer: terms 3.3e-4, dL/dD
1.0e-3, grad 1.3e-3; cycle2: 3.4e-4, 5.6e-4 (grad 7.8e-4 < 1e-3);
cycle3: 3.4e-4, 7.2e-4 (grad 5.4e-4); selfrec (warmup only): 2.8e-4,
1.0e-3 (grad 6.3e-4); lr × 1.001: update 1.0e-3; order (the two
self-reconstruction calls swapped, warmup): stats 2.2e-2; rerun (the
self-reconstruction calls reuse the latents instead of running the
encoders afresh, warmup): stats 2.0e-1; nolatent (every forward_chamfer
encodes afresh): stats 4.3e-1; detach (the reused latents detached):
J'gD 2.4.

usage: cc_step_check.py [-v] [--perturb=WHAT] DIR
       (-v: every tensor's errors; WHAT ∈ chamfer, cycle2, cycle3, selfrec,
        lr, order, rerun, nolatent, detach; exit 77 when torch is missing)
"""
import copy
import json
import os
import sys

try:
    import numpy as np
    import torch

    import cc_torch
except ImportError as exc:  # the integration test maps 77 to "skipped"
    print(f"SKIP: {exc}: the PyTorch cross-check needs python3-torch "
          "(apt-get install -y python3-torch)", file=sys.stderr)
    sys.exit(77)

TOL = 1e-4
STEP_GRAD_TOL = 1e-3
CASES = ("warmup", "steady")
PERTURB = cc_torch.TERMS + ("lr", "order", "rerun", "nolatent", "detach")
# tcbench's pair k (losses.h tcb_cc_pairs: source → target) as the CC code
# names the deformation: target_source
PAIR_NAMES = ("P2_P1", "P1_P2", "P3_P2", "P2_P3", "P1_P3", "P3_P1")


class Case:
    """One exported step."""

    def __init__(self, directory):
        with open(os.path.join(directory, "case.json")) as f:
            self.meta = json.load(f)
        b, n = self.meta["B"], self.meta["N"]
        manifest, before = cc_torch.read_flat(directory, "weights")
        self.model = cc_torch.from_manifest(manifest)
        cc_torch.load_weights(self.model, directory, "weights")
        self.before = cc_torch.unflatten(manifest, before)
        self.after = cc_torch.unflatten(manifest, cc_torch.read_flat(directory, "updated")[1])
        self.grads = cc_torch.unflatten(manifest, cc_torch.read_f32(
            directory, "grads.f32", (manifest["nparams"],)), params_only=True)
        self.buffers = [t["name"] for t in manifest["tensors"]
                        if t["offset"] >= manifest["nparams"]]
        self.clouds = cc_torch.read_f32(directory, "clouds.f32", (self.meta["n_clouds"], b, n, 3))
        self.rot = cc_torch.read_f32(directory, "rot.f32", (b, 3, 3))
        self.matches = cc_torch.read_i32(directory, "matches.i32", (6, b, n))
        self.backward = cc_torch.read_i32(directory, "backward.i32", (6, b, n))
        self.nn_idx = {name: (self.matches[k], self.backward[k])
                       for k, name in enumerate(PAIR_NAMES)}
        calls = 8 if self.meta["warmup"] else 6
        self.D = cc_torch.read_f32(directory, "D.f32", (calls, b, n, 3))
        self.gD = cc_torch.read_f32(directory, "gD.f32", (calls, b, n, 3))


# ---- the negative controls -------------------------------------------------


def selfrec(order, fresh):
    """compute_loss_selfReconstruction, optionally wrong: the two calls
    swapped (order), or not fresh: the encoders not run again on P3, its
    latents reused."""
    def f(self, network, P4):
        P3t = self.P3.transpose(2, 1).contiguous()
        P4t = P4.transpose(2, 1).contiguous()

        def call(x, y, lx, ly):
            if fresh:
                return network(x, y)
            return network.forward_classic_with_latent(x, y, lx, ly)[0]
        calls = [lambda: call(P3t, P4t, self.latent_P3_1, None),
                 lambda: call(P4t, P3t, None, self.latent_P3_2)]
        out = [calls[1](), calls[0]()][::-1] if order else [calls[0](), calls[1]()]
        self.P4_P3, self.P3_P4 = out
        self.loss_train_selfReconstruction_L2 = (1 / 2.0) * (cc_torch.L2(out[0], P4t) +
                                                             cc_torch.L2(out[1], P3t))
    return f


def patched_forward_chamfer(original, what):
    def f(network, P1, P2, local_fix=None, latent=False, latent_P1=None, latent_P2=None,
          exact_nn=True, nn_idx=None):
        if what == "nolatent":
            latent_P1 = latent_P2 = None
        elif what == "detach":
            latent_P1 = None if latent_P1 is None else latent_P1.detach()
            latent_P2 = None if latent_P2 is None else latent_P2.detach()
        return original(network, P1, P2, local_fix, latent, latent_P1, latent_P2, exact_nn, nn_idx)
    return f


# ---- torch's side ------------------------------------------------------------


def torch_step(case, dtype, what):
    """The step redone in torch: a dict of its results (see the keys)."""
    model = copy.deepcopy(case.model).to(dtype)
    model.train()
    before = cc_torch.named_tensors(model)
    P = [torch.from_numpy(c).to(dtype) for c in case.clouds]
    P4 = P[3] if case.meta["warmup"] else None
    weights = {what: 1.001} if what in cc_torch.TERMS else {}
    saved = (cc_torch.TripletPointCloud.compute_loss_selfReconstruction, cc_torch.forward_chamfer)
    try:
        if what in ("order", "rerun"):
            cc_torch.TripletPointCloud.compute_loss_selfReconstruction = selfrec(
                what == "order", what != "rerun")
        if what in ("nolatent", "detach"):
            cc_torch.forward_chamfer = patched_forward_chamfer(saved[1], what)
        total, terms, trip = cc_torch.train_iteration_loss(model, P[0], P[1], P[2], P4, True,
                                                           weights, case.nn_idx)
    finally:
        cc_torch.TripletPointCloud.compute_loss_selfReconstruction, cc_torch.forward_chamfer = saved
    outs = [getattr(trip, k) for k in PAIR_NAMES]  # [B, N, 3]
    if P4 is not None:
        outs += [trip.P4_P3, trip.P3_P4]  # [B, 3, N]

    def layout(t, k):  # as the C side's D: [B, N, 3]
        return t if k < 6 else t.transpose(2, 1)

    params = dict(model.named_parameters())
    model.zero_grad()
    total.backward(retain_graph=True)
    r = {"terms": terms, "before": before, "grads": cc_torch.named_grads(model),
         "stats": cc_torch.named_tensors(model),
         "D": [layout(o, k).detach().double().numpy() for k, o in enumerate(outs)]}
    # the backward alone, from the C loss gradient
    gD = [layout(torch.from_numpy(g).to(dtype), k) for k, g in enumerate(case.gD)]
    jt = torch.autograd.grad(outs, list(params.values()), gD)
    r["jt_gD"] = {k: g.detach().double().numpy().reshape(case.grads[k].shape)
                  for k, g in zip(params, jt)}
    r["flips"] = nn_flips(case, trip, r["D"])
    r["loss_at_D"] = loss_at_c_outputs(case, dtype, weights)

    lr = case.meta["lr"] * (1.001 if what == "lr" else 1.0)
    opt = torch.optim.Adam(model.parameters(), lr=lr,
                           betas=(case.meta["beta1"], case.meta["beta2"]), eps=case.meta["eps"])
    for name, q in params.items():
        q.grad = torch.from_numpy(case.grads[name].reshape(q.shape)).to(dtype)
    old = {k: q.detach().clone() for k, q in params.items()}
    opt.step()
    r["updates"] = {k: (q.detach() - old[k]).double().numpy().reshape(case.grads[k].shape)
                    for k, q in params.items()}
    return r


def loss_at_c_outputs(case, dtype, weights):
    """({term: float}, [∂L/∂D of each call]) of the loss evaluated by torch
    at the C outputs (cc_torch.losses_at)."""
    D = [torch.from_numpy(d).to(dtype).requires_grad_(True) for d in case.D]
    P = [torch.from_numpy(c).to(dtype) for c in case.clouds]
    warm = case.meta["warmup"]
    total, terms = cc_torch.losses_at(P[0], P[1], P[2], dict(zip(PAIR_NAMES, D[:6])),
                                      P[3] if warm else None, D[6:8] if warm else None, weights,
                                      case.nn_idx)
    grads = torch.autograd.grad(total, D)
    return terms, [g.double().numpy() for g in grads]


def nn_flips(case, trip, D):
    """The step's nearest-neighbour indices are the C side's: here, where
    torch's own D would decide otherwise. Returns (flips, unexplained): the
    count of indices that differ, and of those whose distance gap in
    torch's D exceeds what the forward's difference can explain
    (2·√3·max |D_C − D_torch| of the call, each candidate moving by at most
    √3 of it, plus a float32 tie's 1e-6 of the distances)."""
    flips = unexplained = 0
    b, n = case.meta["B"], case.meta["N"]
    fix = cc_torch.make_fix(b, n).numpy()
    for k, name in enumerate(PAIR_NAMES):
        target = getattr(trip, name.split("_")[0]).detach().double().numpy()
        d = np.sqrt(((target[:, :, None, :] - D[k][:, None, :, :]) ** 2).sum(-1))  # [B, q, m]
        slack = 2 * np.sqrt(3) * np.abs(case.D[k] - D[k]).max() + 1e-6 * d.max()
        # idx1: D → target, idx2: target → D
        for dist, i in ((d.transpose(0, 2, 1), 1), (d, 2)):
            used = (getattr(trip, f"idx{i}_" + name).numpy() - fix).reshape(b, n)
            own = dist.argmin(axis=2)
            gap = np.take_along_axis(dist, used[..., None], 2)[..., 0] - dist.min(axis=2)
            flips += int((own != used).sum())
            unexplained += int(((own != used) & (gap > slack)).sum())
    return flips, unexplained


# ---- the measures ------------------------------------------------------------


def moved_error(got, want, start):
    """max (|got − want| − ulp(want)) / max |want − start|: errors relative
    to a movement, not to the values (the update and running-statistics
    measure of the docstring); all float64 arrays."""
    ulp = np.spacing(np.abs(want).astype(np.float32)).astype(np.float64)
    excess = np.maximum(np.abs(got - want) - ulp, 0.0)
    scale = np.abs(want - start).max()
    return excess.max() / (scale if scale > 0 else 1.0)


def nn_map_errors(case):
    """The C side's indices (matches.i32: deformed point → nearest target,
    backward.i32: target → nearest deformed point) that are not a nearest
    neighbour on the C side's own D and clouds, up to float32 ties
    (distances within 1e-6 relative of the minimum)."""
    bad = 0
    for k, name in enumerate(PAIR_NAMES):
        target = case.clouds[int(name[1]) - 1].astype(np.float64)
        D = case.D[k].astype(np.float64)
        d = np.sqrt(((D[:, :, None, :] - target[:, None, :, :]) ** 2).sum(-1))  # [B, m, q]
        for dist, used in ((d, case.matches[k]), (d.transpose(0, 2, 1), case.backward[k])):
            best = dist.min(axis=2)
            got = np.take_along_axis(dist, used[..., None].astype(np.int64), 2)[..., 0]
            bad += int((got - best > 1e-6 * np.maximum(best, 1e-30)).sum())
    return bad


def check_selfrec_target(case):
    """C' = (C · rotᵀ)(1 + s) with s fitted; prints a line, returns the
    number of failures (0 or 1)."""
    p3, p4 = case.clouds[2].astype(np.float64), case.clouds[3].astype(np.float64)
    rot = case.rot.astype(np.float64)
    q = np.einsum("bnk,bjk->bnj", p3, rot)  # P3 · rotᵀ
    s = (p4 * q).sum(1) / (q * q).sum(1) - 1.0  # [B, 3]
    resid = np.abs(p4 - q * (1.0 + s[:, None, :])).max() / np.abs(p4).max()
    ortho = np.abs(np.einsum("bij,bkj->bik", rot, rot) - np.eye(3)).max()
    about_y = np.abs(rot[:, 1, :] - [0, 1, 0]).max() + np.abs(rot[:, :, 1] - [0, 1, 0]).max()
    angle = np.degrees(np.abs(np.arctan2(rot[:, 0, 2], rot[:, 0, 0]))).max()
    ok = (resid < 1e-6 and np.all(np.abs(s) < 0.5) and ortho < 1e-6 and about_y < 1e-6
          and angle <= 20)
    print(f"  C' = (C·rotᵀ)(1 + s): residual {resid:.1e}, s in [{s.min():.3f}, {s.max():.3f}]; "
          f"rot orthonormal to {ortho:.0e}, about y to {about_y:.0e}, |θ| ≤ {angle:.1f}°"
          + ("" if ok else "  FAIL"))
    return 0 if ok else 1


def check(case, dtype, what, verbose, reference):
    """One row of the table (and with verbose one line per tensor); returns
    (failures, the full redo's gradients)."""
    r = torch_step(case, dtype, what)
    name = str(dtype).split(".")[-1]
    warm = case.meta["warmup"]
    keys = list(cc_torch.TERMS[:3]) + (["selfrec"] if warm else []) + ["total"]
    terms = {k: abs(case.meta[k] - r["terms"][k]) / abs(r["terms"][k]) for k in keys}
    terms["loss"] = abs(case.meta["loss"] - r["terms"]["total"]) / abs(r["terms"]["total"])
    at_terms, at_grads = r["loss_at_D"]
    terms.update({k + "@D": abs(case.meta[k] - at_terms[k]) / abs(at_terms[k]) for k in keys})
    dldd = {f"call {k}": cc_torch.rel_error(case.gD[k], g) for k, g in enumerate(at_grads)}
    jt = {k: cc_torch.grad_error(k, g, r["jt_gD"]) for k, g in case.grads.items()}
    grad = {k: cc_torch.grad_error(k, g, r["grads"]) for k, g in case.grads.items()}
    update = {k: moved_error(case.after[k].astype(np.float64), case.before[k] + u, case.before[k])
              for k, u in r["updates"].items()}
    stats = {k: moved_error(case.after[k].astype(np.float64), r["stats"][k], r["before"][k])
             for k in case.buffers}
    d_err = max(cc_torch.rel_error(case.D[k], d) for k, d in enumerate(r["D"]))
    nn_bad = nn_map_errors(case)
    self32 = (max(cc_torch.grad_error(k, r["grads"][k], reference) for k in reference)
              if reference else None)
    if verbose:
        for k in case.grads:
            print(f"    {name:8} {k:45} J'gD {jt[k]:.2e}  grad {grad[k]:.2e}  "
                  f"update {update[k]:.2e}")
        for k in case.buffers:
            print(f"    {name:8} {k:45} stats {stats[k]:.2e}")
        for k, e in list(terms.items()) + list(dldd.items()):
            print(f"    {name:8} {k:45} {e:.2e}")
    groups = (("terms", terms, TOL), ("dL/dD", dldd, TOL), ("J'gD", jt, TOL),
              ("grad", grad, STEP_GRAD_TOL), ("update", update, TOL), ("stats", stats, TOL))
    cells = []
    fails = []
    for label, errs, tol in groups:
        worst = max(errs, key=errs.get)
        cells.append(f"{label} {errs[worst]:.1e}")
        if verbose or errs[worst] > tol:
            cells[-1] += f" ({worst})"
        fails += [f"{label} {k} {e:.3g} > {tol:g}" for k, e in errs.items() if not e <= tol]
    print(f"  {name:8} " + ", ".join(cells)
          + (f"; torch32 {self32:.1e}" if self32 is not None else ""))
    print(f"  {'':8} C's NN indices not nearest: {nn_bad}; D {d_err:.1e} (diagnostic); "
          f"torch's own D would choose {r['flips'][0]} of them otherwise, {r['flips'][1]} "
          "beyond its rounding")
    if nn_bad:
        fails.append(f"{nn_bad} of the C side's nearest-neighbour indices are not nearest")
    if r["flips"][1]:
        fails.append(f"{r['flips'][1]} nearest-neighbour choices on C's D are not near ties "
                     "on torch's")
    for f in fails:
        print(f"FAIL {case.meta['case']} torch {name}: {f}")
    return len(fails), r["grads"]


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("-")]
    verbose = "-v" in sys.argv[1:]
    what = next((a.split("=", 1)[1] for a in sys.argv[1:] if a.startswith("--perturb=")), "")
    if what and what not in PERTURB:
        raise SystemExit(f"unknown --perturb={what}; one of {', '.join(PERTURB)}")
    torch.manual_seed(0)
    print(f"relative errors of C against torch (see the docstring), tolerance {TOL:g}, grad "
          f"{STEP_GRAD_TOL:g}" + (f"; PERTURBED: {what}" if what else ""))
    failures = 0
    for name in CASES:
        case = Case(os.path.join(args[0], name))
        m = case.meta
        print(f"{name}: C {m['C']}, Z {m['Z']}, H {m['H']}, L {m['L']}, B {m['B']}, N {m['N']}, "
              f"{m['n_clouds']} clouds; C loss {m['loss']:.6g} = chamfer {m['chamfer']:.4g} "
              f"+ cycle2 {m['cycle2']:.4g} + cycle3 {m['cycle3']:.4g} + selfrec {m['selfrec']:.4g}")
        if m["warmup"]:
            failures += check_selfrec_target(case)
        reference = None
        for dtype in (torch.float64, torch.float32):
            n, grads = check(case, dtype, what, verbose, reference)
            failures += n
            reference = grads
    if failures:
        sys.exit(1)
    print("one CC training step (warm-up and steady) matches PyTorch")


if __name__ == "__main__":
    main()

"""Cross-check of tcbench's C atlas network against PyTorch.

Rebuilds the network of reference-protocol §2 in PyTorch (atlas_torch.py:
PointNet encoder without batch norm, P patch decoders on [u, v, z] with
Softplus), loads the weights that tests/pytorch/atlas_export.c wrote with
the C model, and on the same inputs computes
  * φ, and φ_u, φ_v by autograd w.r.t. the UV input (create_graph=True, as
    TCSR computes its Jacobians),
  * the gradient of L = Σ a·φ + Σ b·φ_u + Σ c·φ_v w.r.t. every parameter,
then compares with the C results. Like with like: the check runs twice, with
torch in float64 (the exact reference for the float32 C code) and in float32.
Pass: for every tensor, max |C − torch| ≤ 1e-5 · max |torch| (observed:
≈ 1.6e-6; a 0.1% error in softplus′′'s term of one layer gives 3e-5).

usage: atlas_net_check.py DIR     (exit 77 when torch is missing)
"""
import json
import os
import sys

try:
    import torch

    import atlas_torch
except ImportError as exc:  # the integration test maps 77 to "skipped"
    print(f"SKIP: {exc}: the PyTorch cross-check needs python3-torch "
          "(apt-get install -y python3-torch)", file=sys.stderr)
    sys.exit(77)

TOL = 1e-5


def run_torch(model, clouds, uv, coef, dtype):
    """φ, φ_u, φ_v [B, M, 3] and the objective's gradients by name."""
    model = model.to(dtype)
    model.zero_grad()
    outs = atlas_torch.forward(model, torch.from_numpy(clouds).to(dtype),
                               torch.from_numpy(uv).to(dtype), tangents=True)
    loss = sum((torch.from_numpy(c).to(dtype) * t).sum() for c, t in zip(coef, outs))
    loss.backward()
    grads = {n: q.grad.detach().double().numpy() for n, q in model.named_parameters()}
    return [t.detach().double().numpy() for t in outs], grads


def main():
    directory = sys.argv[1]
    with open(os.path.join(directory, "case.json")) as f:
        case = json.load(f)
    c, p, b, n, m = (case[k] for k in ("C", "P", "B", "N", "M"))
    torch.manual_seed(0)
    model = atlas_torch.Atlas(c, p)
    manifest = atlas_torch.load_weights(model, directory)
    def read(name, shape):
        return atlas_torch.read_f32(directory, name, shape)

    clouds, uv = read("clouds.f32", (b, n, 3)), read("uv.f32", (m, 2))
    coef = [read(f"coef_{k}.f32", (b, m, 3)) for k in ("phi", "phi_u", "phi_v")]
    c_out = [read(f"{k}.f32", (b, m, 3)) for k in ("phi", "phi_u", "phi_v")]
    c_grads = atlas_torch.unflatten(manifest, read("grads.f32", (manifest["nparams"],)))

    # how much of the decoders' first layer sits on softplus's linear branch
    with torch.no_grad():
        model64 = model.double()
        z = model64.encoder(torch.from_numpy(clouds).double())
        sz = torch.stack([d.fc1(torch.cat([torch.zeros(b, 2, dtype=z.dtype), z], 1))
                          for d in model64.decoders])
        print(f"fc1 pre-activations above the softplus threshold: "
              f"{(sz > 20).double().mean().item():.1%}")

    failures = 0
    for dtype in (torch.float64, torch.float32):
        outs, grads = run_torch(model, clouds, uv, coef, dtype)
        worst = ("", 0.0)
        for name, got, want in zip(("phi", "phi_u", "phi_v"), c_out, outs):
            err = atlas_torch.rel_error(got, want)
            worst = max(worst, (name, err), key=lambda t: t[1])
            if err > TOL:
                print(f"FAIL {dtype}: {name}: max error {err:.3g} of max |torch|")
                failures += 1
        for name, got in c_grads.items():
            err = atlas_torch.rel_error(got, grads[name])
            worst = max(worst, ("grad " + name, err), key=lambda q: q[1])
            if err > TOL:
                print(f"FAIL {dtype}: grad {name}: max error {err:.3g} of max |torch|")
                failures += 1
        print(f"torch {str(dtype).split('.')[-1]}: {3 + len(manifest['tensors'])} tensors, "
              f"worst max|C - torch|/max|torch| = {worst[1]:.2e} ({worst[0]})")
    if failures:
        sys.exit(1)
    print("atlas network matches PyTorch")


if __name__ == "__main__":
    main()

"""The atlas family of reference-protocol §2–§4 in PyTorch: the one torch
implementation that tcbench's C code is checked and timed against.

Used by tests/pytorch/atlas_net_check.py (network and Jacobians),
tests/pytorch/atlas_step_check.py (one training step per method) and
bench/train_step_torch.py (the PyTorch peer of bench_train_step).

Written from the reference definitions, not from the C code: the network
as TCSR builds it, the Jacobians by autograd w.r.t. the UV input with
create_graph=True (as TCSR computes them, so the losses' backward is a
double backward), the losses as §3 states them.

Importing this module needs torch and numpy; callers map an ImportError to
their own "skipped" exit.
"""
import json
import os

import numpy as np
import torch

# reference-protocol §3.2–§3.4
ALPHA_MC = 0.1
ALPHA_SCISO = 1e-3
DSR_WEIGHTS = {"e": 1.0, "g": 1.0, "skew": 1.0, "stretch": 0.0, "total_area": 100.0}
DSR_EPS = 1e-20
METHODS = ("atlasnet", "dsr", "mca")


class Encoder(torch.nn.Module):
    """PointNet, TCSR's EncoderPointNet with enc_batch_norm=False; the 1×1
    convolutions are per-point linear layers."""

    def __init__(self, c):
        super().__init__()
        self.conv1 = torch.nn.Linear(3, 64)
        self.conv2 = torch.nn.Linear(64, 128)
        self.conv3 = torch.nn.Linear(128, c)
        self.fc1 = torch.nn.Linear(c, c)
        self.fc2 = torch.nn.Linear(c, c)

    def forward(self, x):  # x [B, N, 3]
        h = torch.relu(self.conv1(x))
        h = torch.relu(self.conv2(h))
        h = self.conv3(h).max(dim=1)[0]
        return torch.relu(self.fc2(torch.relu(self.fc1(h))))


class Decoder(torch.nn.Module):
    """DecoderAtlasNet: [u, v, z] → C' → C' → C'//2 → C'//4 → 3."""

    def __init__(self, c):
        super().__init__()
        w = c + 2
        self.fc1 = torch.nn.Linear(w, w)
        self.fc2 = torch.nn.Linear(w, w // 2)
        self.fc3 = torch.nn.Linear(w // 2, w // 4)
        self.fc4 = torch.nn.Linear(w // 4, 3)
        self.act = torch.nn.Softplus()  # beta=1, threshold=20

    def forward(self, x):
        x = self.act(self.fc1(x))
        x = self.act(self.fc2(x))
        x = self.act(self.fc3(x))
        return self.fc4(x)


class Atlas(torch.nn.Module):
    def __init__(self, c, p):
        super().__init__()
        self.encoder = Encoder(c)
        self.decoders = torch.nn.ModuleList(Decoder(c) for _ in range(p))


def read_f32(directory, name, shape):
    return np.fromfile(os.path.join(directory, name), dtype="<f4").reshape(shape)


def read_flat(directory, stem):
    """(manifest, flat float32 vector) of weights written by
    tcb_atlas_model_export as STEM.bin + STEM.json."""
    with open(os.path.join(directory, stem + ".json")) as f:
        manifest = json.load(f)
    flat = np.fromfile(os.path.join(directory, stem + ".bin"), dtype="<f4")
    assert flat.size == manifest["nparams"], (flat.size, manifest["nparams"])
    return manifest, flat


def unflatten(manifest, flat):
    """{tensor name: array} of a flat vector in the manifest's layout."""
    return {t["name"]: flat[t["offset"]:t["offset"] + t["count"]].reshape(t["shape"])
            for t in manifest["tensors"]}


def load_weights(model, directory, stem="weights"):
    """Loads the C-exported STEM.bin/.json into model; returns the manifest."""
    manifest, flat = read_flat(directory, stem)
    state = model.state_dict()
    values = unflatten(manifest, flat)
    assert set(state) == set(values), "tensor names differ"
    for name, value in values.items():
        assert tuple(state[name].shape) == value.shape, name
        state[name] = torch.from_numpy(value.copy())
    model.load_state_dict(state)
    return manifest


def forward(model, clouds, uv, tangents):
    """clouds [B, N, 3], uv [M, 2] (tensors of the model's dtype; patch k
    decodes samples [k·M/P, (k+1)·M/P), shared by the B shapes) →
    φ [B, M, 3] and, with tangents, φ_u = ∂φ/∂u, φ_v = ∂φ/∂v [B, M, 3],
    differentiable w.r.t. the parameters (else None, None)."""
    b, p = clouds.shape[0], len(model.decoders)
    m = uv.shape[0] // p
    z = model.encoder(clouds)
    zs = z.unsqueeze(1).expand(b, m, z.shape[1])
    # one UV copy per shape so that ∂φ[b, i]/∂uv[b, i] is a plain gradient
    uv_in = uv.unsqueeze(0).expand(b, -1, -1).clone().requires_grad_(tangents)
    phi = torch.cat([dec(torch.cat([uv_in[:, k * m:(k + 1) * m], zs], dim=2))
                     for k, dec in enumerate(model.decoders)], dim=1)
    if not tangents:
        return phi, None, None
    jac = [torch.autograd.grad(phi[..., c].sum(), uv_in, create_graph=True)[0]
           for c in range(3)]  # jac[c][b, i] = (∂φ_c/∂u, ∂φ_c/∂v)
    return phi, torch.stack([j[..., 0] for j in jac], 2), torch.stack([j[..., 1] for j in jac], 2)


def chamfer(pred, target, exact_nn=True):
    """L_CD (§3.1) of pred [B, M, 3] and target [B, N, 3]: squared distances
    to the nearest neighbour, mean over the B·M predictions plus mean over
    the B·N input points. As TCSR: argmin on the full distance matrix, then
    the distances recomputed with autograd. With exact_nn the matrix is
    computed from differences, so near ties resolve as exactly as the C
    code's k-NN does (the cross-checks); else by torch's faster
    |a|² + |b|² − 2ab GEMM (the benchmark)."""
    mode = "donot_use_mm_for_euclid_dist" if exact_nn else "use_mm_for_euclid_dist"
    with torch.no_grad():
        d = torch.cdist(pred, target, compute_mode=mode)
        to_target, to_pred = d.argmin(dim=2), d.argmin(dim=1)  # [B, M], [B, N]
    near_target = torch.gather(target, 1, to_target.unsqueeze(2).expand(-1, -1, 3))
    near_pred = torch.gather(pred, 1, to_pred.unsqueeze(2).expand(-1, -1, 3))
    return ((pred - near_target) ** 2).sum(2).mean() + ((target - near_pred) ** 2).sum(2).mean()


def fundamental_form(phi_u, phi_v):
    """E, F, G [B, M] (§2.4)."""
    return (phi_u * phi_u).sum(2), (phi_u * phi_v).sum(2), (phi_v * phi_v).sum(2)


def metric_consistency(phi_u, phi_v):
    """L_mc (§3.2): mean over the pairs (0,1), (2,3), … and the samples of
    (E_a − E_b)² + 2 (F_a − F_b)² + (G_a − G_b)²."""
    e, f, g = fundamental_form(phi_u, phi_v)
    return ((e[0::2] - e[1::2]) ** 2 + 2 * (f[0::2] - f[1::2]) ** 2
            + (g[0::2] - g[1::2]) ** 2).mean()


def scaled_isometry(phi_u, phi_v, area_gt, p):
    """L_sciso (§3.3) with DSR_WEIGHTS; area_gt [B]; p patches of equal
    sample counts."""
    e, f, g = fundamental_form(phi_u, phi_v)
    a2 = torch.clamp(e * g - f * f, min=0)
    w = 1 / (a2 + DSR_EPS)
    terms = {
        "e": ((e - e.mean()) ** 2 * w).mean(),
        "g": ((g - g.mean()) ** 2 * w).mean(),
        "skew": (f * f * w).mean(),
        "stretch": ((e - g) ** 2 * w).mean(),
    }
    total = torch.sqrt(a2).reshape(e.shape[0], p, -1).mean(dim=2).sum(dim=1)
    terms["total_area"] = (torch.clamp(total - area_gt, min=0) ** 2).mean()
    return sum(DSR_WEIGHTS[k] * v for k, v in terms.items())


def uses_tangents(method):
    return method != "atlasnet"


def method_loss(method, model, clouds, uv, area_gt, exact_nn=True):
    """The total training loss of one method (§3.2–§3.4) on a batch:
    clouds [B, N, 3], uv [M, 2], area_gt [B] tensors of the model's dtype;
    exact_nn as for chamfer."""
    phi, phi_u, phi_v = forward(model, clouds, uv, uses_tangents(method))
    loss = chamfer(phi, clouds, exact_nn)
    if method == "mca":
        loss = loss + ALPHA_MC * metric_consistency(phi_u, phi_v)
    elif method == "dsr":
        loss = loss + ALPHA_SCISO * scaled_isometry(phi_u, phi_v, area_gt, len(model.decoders))
    return loss


def rel_error(got, want):
    """max |got − want| relative to max |want| (1 where want is all zero)."""
    scale = np.abs(want).max()
    return np.abs(got - want).max() / (scale if scale > 0 else 1.0)

"""CC (Groueix et al., SGP'19, cycle-consistent deformation) in PyTorch: the
torch implementation that tcbench's C code (methods/cycle) is checked and
timed against.

Used by tests/pytorch/cc_net_check.py (network, gradients, running
statistics), tests/pytorch/cc_step_check.py (one training step) and
bench/train_step_cc_torch.py (the PyTorch peer of the C training step).

A port of the CC code (ThibaultGROUEIX/CycleConsistentDeformation), not of
the C code:
  network   auxiliary/model.py AE_Meta_AtlasNet (forward_classic,
            forward_classic_with_latent), MetaPointGenCon2, Meta_FC_Layer_2,
            FC_Layer, MetaVector; auxiliary/model_pointnetfeat.py
            PointNetfeat; auxiliary/my_utils.py weights_init;
  losses    auxiliary/useful_losses.py forward_chamfer, batch_idx,
            batch_cycle_2, batch_cycle_3, L2, chamferL2_assym2 (ASSYM_2);
  the step  training/trainer.py triplet_chamfer_loss and train_iteration,
            training/triplet_point_cloud.py TripletPointCloud (add_*,
            compute_loss_train_Deformation_ChamferL2, compute_loss_cycle2,
            compute_loss_cycle3, compute_loss_selfReconstruction).
Changes, none of which alters what is computed:
  * CPU instead of .cuda(); the identity added to the predicted weights is
    made in the input's dtype (the CC code's torch.eye is float32);
  * sizes are parameters: PointNet's last width C (CC: 1024), the latent Z
    (CC: 512; MetaVector's hidden widths are Z and Z/2, CC's hard-coded 512
    and 256), the meta-MLP hidden_sizes (CC: [64] * 6);
  * no STN3d module (the CC code builds one in PointNetfeat and never calls
    it: trans=False), so no "encoder.0.stn.*" tensors;
  * FC_Layer creates bn1 only where it uses it: the CC code also builds an
    (unused, untrained) BatchNorm1d(3) in fc_end, whose four tensors and
    num_batches_tracked a CC checkpoint has and tcbench's manifest has not;
  * x_latent / y_latent default to None instead of the CC code's `is 0`
    test (forward_chamfer passes 0 for "compute it");
  * distChamfer (a CUDA extension) is replaced by nearest neighbours found
    by torch.cdist + argmin without gradient and the squared distances
    recomputed with autograd from the gathered points: the same values and
    the same gradient as the extension's backward;
  * compute_loss_selfReconstruction takes the target P4 as an argument
    (a caller that has none computes it with selfrec_target, as the CC
    code does: rotation back, then anisotropic scaling by U(0.5, 1.5)),
    and keeps its two outputs (P4_P3, P3_P4) for the checks.
Additions for the cross-checks: the nearest-neighbour indices can be given
instead of searched (nn_idx), and losses_at evaluates the same loss at
given network outputs.

Importing this module needs torch and numpy; callers map an ImportError to
their own "skipped" exit.
"""
import collections
import json
import os
import re

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

# ---- the network (auxiliary/model_pointnetfeat.py, auxiliary/model.py) ----


class PointNetfeat(nn.Module):
    """PointNetfeat(global_feat=True, trans=False): x [B, 3, N] → [B, C]."""

    def __init__(self, c=1024):
        super().__init__()
        self.c = c
        self.conv1 = torch.nn.Conv1d(3, 64, 1)
        self.conv2 = torch.nn.Conv1d(64, 128, 1)
        self.conv3 = torch.nn.Conv1d(128, c, 1)
        self.bn1 = torch.nn.BatchNorm1d(64)
        self.bn2 = torch.nn.BatchNorm1d(128)
        self.bn3 = torch.nn.BatchNorm1d(c)

    def forward(self, x):
        x = F.relu(self.bn1(self.conv1(x)))
        x = F.relu(self.bn2(self.conv2(x)))
        x = self.bn3(self.conv3(x))
        x, _ = torch.max(x, 2)
        return x.view(-1, self.c)


class MetaVector(nn.Module):
    """The parameter predictor: [B, 2Z] → [B, K]."""

    def __init__(self, bottleneck_size, target_size, hidden=(512, 256)):
        super().__init__()
        self.fc1 = nn.Linear(bottleneck_size, hidden[0])
        self.fc2 = nn.Linear(hidden[0], hidden[1])
        self.fc3 = nn.Linear(hidden[1], target_size)
        self.bn1 = nn.BatchNorm1d(hidden[0])
        self.bn2 = nn.BatchNorm1d(hidden[1])

    def forward(self, x):
        x = F.relu(self.bn1(self.fc1(x)))
        x = F.relu(self.bn2(self.fc2(x)))
        return self.fc3(x)


class FC_Layer(nn.Module):
    def __init__(self, source_size, target_size, activation="ReLU", batchnorm=True):
        super().__init__()
        self.batchnorm = batchnorm
        self.conv1 = torch.nn.Conv1d(source_size, target_size, 1)
        if batchnorm:  # the CC code builds bn1 unconditionally (see the top)
            self.bn1 = torch.nn.BatchNorm1d(target_size)
        self.activation_function = nn.ReLU() if activation == "ReLU" else nn.Tanh()

    def forward(self, x):
        if self.batchnorm:
            return self.activation_function(self.bn1(self.conv1(x)))
        return self.activation_function(self.conv1(x))


class Meta_FC_Layer_2(nn.Module):
    """x ← ReLU(bn0((x + b)ᵀ · (W + I))ᵀ), then the fixed FC_Layer; W, b are
    the shape's slice [cursor_W*, cursor_B*) of the predicted parameters."""

    def __init__(self, source_size, target_size, activation="ReLU", batchnorm=True,
                 cursor_Wstart=0, cursor_Wend=1, cursor_Bstart=0, cursor_Bend=1):
        super().__init__()
        self.fc = FC_Layer(source_size, target_size, activation, batchnorm)
        self.cursor_Wstart, self.cursor_Wend = cursor_Wstart, cursor_Wend
        self.cursor_Bstart, self.cursor_Bend = cursor_Bstart, cursor_Bend
        self.bn0 = torch.nn.BatchNorm1d(source_size)

    def forward(self, args):
        x, parameters = args
        weight = parameters[:, self.cursor_Wstart:self.cursor_Wend].contiguous()
        bias = parameters[:, self.cursor_Bstart:self.cursor_Bend].contiguous()
        bias = bias.unsqueeze(2).expand(x.size(0), bias.size(1), x.size(2)).contiguous()
        eye = torch.eye(bias.size(1), dtype=x.dtype, device=x.device)
        weight = weight.view(x.size(0), bias.size(1), bias.size(1)).contiguous() + \
            eye.unsqueeze(0).repeat(x.size(0), 1, 1)
        x = x + bias
        x = x.transpose(2, 1).contiguous()
        x = torch.bmm(x, weight)
        x = x.transpose(2, 1).contiguous()
        x = F.relu(self.bn0(x))
        return [self.fc(x), parameters]


class MetaPointGenCon2(nn.Module):
    def __init__(self, bottleneck_size, hidden_sizes, predictor_hidden=(512, 256)):
        super().__init__()
        self.hidden_sizes = hidden_sizes
        self.num_parameters = 9 + 3
        for i in hidden_sizes:
            self.num_parameters = self.num_parameters + i * i + i
        self.parameter_predictor = MetaVector(bottleneck_size, self.num_parameters,
                                              predictor_hidden)
        hidden_layer = collections.OrderedDict()
        hidden_layer['fc_0'] = Meta_FC_Layer_2(3, hidden_sizes[0], cursor_Wstart=0,
                                               cursor_Wend=9, cursor_Bstart=9, cursor_Bend=12)
        cursor = 12
        for i, size in enumerate(hidden_sizes[:-1]):
            hidden_layer['fc_' + str(i + 1)] = Meta_FC_Layer_2(
                hidden_sizes[i], hidden_sizes[i + 1], cursor_Wstart=cursor,
                cursor_Wend=cursor + size * size, cursor_Bstart=cursor + size * size,
                cursor_Bend=cursor + size + size * size)
            cursor = cursor + size * size + size
        last = hidden_sizes[-1]
        hidden_layer['fc_end'] = Meta_FC_Layer_2(
            last, 3, activation="Tanh", batchnorm=False, cursor_Wstart=cursor,
            cursor_Wend=cursor + last * last, cursor_Bstart=cursor + last * last,
            cursor_Bend=cursor + last * last + last)
        self.MLP = nn.Sequential(hidden_layer)

    def forward(self, x, feature_vector):
        parameters = self.parameter_predictor(feature_vector)
        x, _ = self.MLP([x, parameters])
        return 2 * x


class AE_Meta_AtlasNet(nn.Module):
    """CC's network, skip_connections=False (forward = forward_classic).
    Clouds as the CC code passes them: [B, 3, N]; the output [B, 3, N] is x
    deformed towards y."""

    def __init__(self, c=1024, z=512, hidden_sizes=(64,) * 6):
        super().__init__()
        self.encoder = nn.Sequential(PointNetfeat(c), nn.Linear(c, z), nn.BatchNorm1d(z),
                                     nn.ReLU())
        self.encoder2 = nn.Sequential(PointNetfeat(c), nn.Linear(c, z), nn.BatchNorm1d(z),
                                      nn.ReLU())
        self.decoder = MetaPointGenCon2(2 * z, list(hidden_sizes), (z, z // 2))

    def forward(self, x, y):
        x_latent = self.encoder(x)
        y_latent = self.encoder2(y)
        latent = torch.cat([x_latent, y_latent], 1)
        return self.decoder(x, latent).contiguous()

    def forward_classic_with_latent(self, x, y, x_latent=None, y_latent=None):
        if x_latent is None:
            x_latent = self.encoder(x)
        if y_latent is None:
            y_latent = self.encoder2(y)
        latent = torch.cat([x_latent, y_latent], 1)
        return self.decoder(x, latent).contiguous(), x_latent, y_latent


def weights_init(m):
    """my_utils.weights_init, applied over PyTorch's default init."""
    classname = m.__class__.__name__
    if classname.find("Conv") != -1:
        m.weight.data.normal_(0.0, 0.02)
    elif classname.find("BatchNorm") != -1:
        m.weight.data.normal_(1.0, 0.02)
        m.bias.data.fill_(0)


def build(c, z, h, l):
    """A fresh network with the CC code's initialisation."""
    net = AE_Meta_AtlasNet(c, z, [h] * l)
    net.apply(weights_init)
    return net


# ---- the losses (auxiliary/useful_losses.py) --------------------------------


def dist_chamfer(a, b, exact_nn=True, idx=None):
    """distChamfer(a, b) for a, b [B, N, 3]: dist1 [B, N] squared distance of
    each point of a to its nearest in b, idx1 that index; dist2, idx2 the
    same from b to a. The indices are found without gradient (with exact_nn
    from coordinate differences, so near ties resolve as an exact search
    does; else by torch's faster |a|² + |b|² − 2ab GEMM, the benchmark), the
    distances recomputed from the gathered points with autograd. idx
    (optional): (idx1, idx2) given instead of searched (the cross-check
    takes the C side's, verified there to be nearest up to float32 ties)."""
    if idx is None:
        mode = "donot_use_mm_for_euclid_dist" if exact_nn else "use_mm_for_euclid_dist"
        with torch.no_grad():
            d = torch.cdist(a, b, compute_mode=mode)
            idx1, idx2 = d.argmin(dim=2), d.argmin(dim=1)  # [B, Na] into b, [B, Nb] into a
    else:
        idx1, idx2 = (torch.as_tensor(np.asarray(i, dtype=np.int64)) for i in idx)
    near_b = torch.gather(b, 1, idx1.unsqueeze(2).expand(-1, -1, 3))
    near_a = torch.gather(a, 1, idx2.unsqueeze(2).expand(-1, -1, 3))
    return ((a - near_b) ** 2).sum(2), ((b - near_a) ** 2).sum(2), idx1, idx2


def batch_idx(idx, fix):
    idx = idx.reshape(-1).data.long()
    return (idx + fix[:len(idx)]).long()


def forward_chamfer(network, P1, P2, local_fix=None, latent=False, latent_P1=None, latent_P2=None,
                    exact_nn=True, nn_idx=None):
    """P1 deformed towards P2 ([B, N, 3] in and out), and its Chamfer
    outputs; nn_idx as dist_chamfer's idx."""
    P1_tmp = P1.transpose(2, 1).contiguous()
    P2_tmp = P2.transpose(2, 1).contiguous()
    if latent:
        P2_P1, latent_vector_P1, latent_vector_P2 = network.forward_classic_with_latent(
            P1_tmp, P2_tmp, x_latent=latent_P1, y_latent=latent_P2)
    else:
        P2_P1 = network(P1_tmp, P2_tmp)
    P2_P1 = P2_P1.transpose(2, 1).contiguous()
    dist1, dist2, idx1, idx2 = dist_chamfer(P2_P1, P2, exact_nn, nn_idx)
    if local_fix is not None:
        idx1 = batch_idx(idx1, local_fix)
        idx2 = batch_idx(idx2, local_fix)
    if latent:
        return (P2_P1, dist1, dist2, idx1.view(-1).long(), idx2.view(-1).long(),
                latent_vector_P1, latent_vector_P2)
    return P2_P1, dist1, dist2, idx1.view(-1).long(), idx2.view(-1).long()


def batch_cycle_2(P1_P2, idx1_P2_P1, batch_size):
    return P1_P2.view(-1, 3)[idx1_P2_P1].view(batch_size, -1, 3)


def batch_cycle_3(P1_P3, idx1_P2_P1, idx1_P3_P2, batch_size):
    return P1_P3.view(-1, 3)[idx1_P3_P2].contiguous()[idx1_P2_P1].contiguous().view(
        batch_size, -1, 3)


def L2(tens1, tens2):
    if tens1.nelement() == 0 or tens2.nelement() == 0:
        return 0
    return torch.sqrt(torch.mean((tens1 - tens2) ** 2) + 0.00000001)


def chamferL2_assym2(dist1, dist2):
    if dist1.nelement() == 0 or dist2.nelement() == 0:
        return 0
    return torch.mean(torch.sqrt(dist2))


def make_fix(batch, n, device=None):
    """Trainer.init_fix: the offset b·N of each flattened point."""
    return torch.arange(0, batch, device=device).view(batch, 1).repeat(1, n).view(-1).long() * n


def selfrec_target(P3, rot_matrix, scale):
    """compute_loss_selfReconstruction's P4 from P3 [B, N, 3], the
    augmentation's rot_matrix [B, 3, 3] and scale [B, 1, 3] (the CC code
    draws torch.rand(B, 1, 3) − 0.5)."""
    P4 = P3.bmm(rot_matrix.transpose(2, 1).contiguous()).detach()
    return P4 + scale * P4


# ---- one iteration (training/trainer.py, training/triplet_point_cloud.py) ---


class TripletPointCloud:
    """The CC code's TripletPointCloud with ASSYM_2 Chamfer. The add_*
    methods of the CC code store the forward_chamfer outputs of one pair
    under its names (P2_P1 = P1 deformed towards P2); here `add` does that
    for any pair name."""

    def __init__(self, P1, P2, P3):
        self.P1, self.P2, self.P3 = P1, P2, P3
        self.batchs = P1.size(0)

    # add_P2P1(P2_P1, dist1, dist2, idx1, idx2, latent_P1_1, latent_P2_2) etc.:
    # the deformation is named target_source, the latents latent_<source>_1
    # (encoder) and latent_<target>_2 (encoder2)
    def add(self, target, source, out):
        pair = f"{target}_{source}"
        D, dist1, dist2, idx1, idx2, lat_source, lat_target = out
        setattr(self, pair, D)
        setattr(self, "dist1_" + pair, dist1)
        setattr(self, "dist2_" + pair, dist2)
        setattr(self, "idx1_" + pair, idx1)
        setattr(self, "idx2_" + pair, idx2)
        setattr(self, f"latent_{source}_1", lat_source)
        setattr(self, f"latent_{target}_2", lat_target)

    def compute_loss_train_Deformation_ChamferL2(self):
        c = chamferL2_assym2
        self.loss_train_Deformation_ChamferL2 = (1 / 6.0) * (
            c(self.dist1_P2_P1, self.dist2_P2_P1) + c(self.dist1_P1_P2, self.dist2_P1_P2) +
            c(self.dist1_P3_P2, self.dist2_P3_P2) + c(self.dist1_P2_P3, self.dist2_P2_P3) +
            c(self.dist1_P1_P3, self.dist2_P1_P3) + c(self.dist1_P3_P1, self.dist2_P3_P1))

    def compute_loss_cycle2(self):
        P1_P2_cycle = batch_cycle_2(self.P1_P2, self.idx1_P2_P1, self.batchs)
        P2_P1_cycle = batch_cycle_2(self.P2_P1, self.idx1_P1_P2, self.batchs)
        P3_P2_cycle = batch_cycle_2(self.P3_P2, self.idx1_P2_P3, self.batchs)
        P2_P3_cycle = batch_cycle_2(self.P2_P3, self.idx1_P3_P2, self.batchs)
        P1_P3_cycle = batch_cycle_2(self.P1_P3, self.idx1_P3_P1, self.batchs)
        P3_P1_cycle = batch_cycle_2(self.P3_P1, self.idx1_P1_P3, self.batchs)
        self.loss_train_cycleL2_2 = (1 / 6.0) * (
            L2(P1_P2_cycle, self.P1) + L2(P2_P1_cycle, self.P2) + L2(P3_P2_cycle, self.P3) +
            L2(P2_P3_cycle, self.P2) + L2(P1_P3_cycle, self.P1) + L2(P3_P1_cycle, self.P3))

    def compute_loss_cycle3(self):
        b = self.batchs
        P1_P3_P2_cycle = batch_cycle_3(self.P1_P3, self.idx1_P2_P1, self.idx1_P3_P2, b)
        P2_P1_P3_cycle = batch_cycle_3(self.P2_P1, self.idx1_P3_P2, self.idx1_P1_P3, b)
        P3_P2_P1_cycle = batch_cycle_3(self.P3_P2, self.idx1_P1_P3, self.idx1_P2_P1, b)
        P1_P2_P3_cycle = batch_cycle_3(self.P1_P2, self.idx1_P3_P1, self.idx1_P2_P3, b)
        P2_P3_P1_cycle = batch_cycle_3(self.P2_P3, self.idx1_P1_P2, self.idx1_P3_P1, b)
        P3_P1_P2_cycle = batch_cycle_3(self.P3_P1, self.idx1_P2_P3, self.idx1_P1_P2, b)
        self.loss_train_cycleL2_3 = (1 / 6.0) * (
            L2(P1_P3_P2_cycle, self.P1) + L2(P2_P1_P3_cycle, self.P2) +
            L2(P3_P2_P1_cycle, self.P3) + L2(P1_P2_P3_cycle, self.P1) +
            L2(P2_P3_P1_cycle, self.P2) + L2(P3_P1_P2_cycle, self.P3))

    def compute_loss_selfReconstruction(self, network, P4):
        P3 = self.P3.transpose(2, 1).contiguous()
        P4 = P4.transpose(2, 1).contiguous()
        P4_P3 = network(P3, P4)  # forward pass
        P3_P4 = network(P4, P3)  # forward pass
        self.P4_P3, self.P3_P4 = P4_P3, P3_P4  # [B, 3, N]; kept for the checks
        self.loss_train_selfReconstruction_L2 = (1 / 2.0) * (L2(P4_P3, P4) + L2(P3_P4, P3))


def triplet_chamfer_loss(network, triplet, fix, exact_nn=True, nn_idx=None):
    """Trainer.triplet_chamfer_loss: six network calls; encoder runs on
    P1, P2, P3 (calls 1, 2, 4), encoder2 on P2, P1, P3 (calls 1, 2, 3).
    nn_idx {deformation name ("P2_P1"): (idx1, idx2)} as forward_chamfer's."""
    t = triplet
    refs = nn_idx or {}

    def fc(P1, P2, lat1, lat2, name):
        return forward_chamfer(network, P1, P2, fix, True, lat1, lat2, exact_nn, refs.get(name))

    t.add("P2", "P1", fc(t.P1, t.P2, None, None, "P2_P1"))
    t.add("P1", "P2", fc(t.P2, t.P1, None, None, "P1_P2"))
    t.add("P3", "P2", fc(t.P2, t.P3, t.latent_P2_1, None, "P3_P2"))
    t.add("P2", "P3", fc(t.P3, t.P2, None, t.latent_P2_2, "P2_P3"))
    t.add("P1", "P3", fc(t.P3, t.P1, t.latent_P3_1, t.latent_P1_2, "P1_P3"))
    t.add("P3", "P1", fc(t.P1, t.P3, t.latent_P1_1, t.latent_P3_2, "P3_P1"))
    t.compute_loss_train_Deformation_ChamferL2()


TERMS = ("chamfer", "cycle2", "cycle3", "selfrec")


def train_iteration_loss(network, P1, P2, P3, P4=None, exact_nn=True, weights=None, nn_idx=None):
    """Trainer.train_iteration up to the backward, λ_chamfer = λ_cycle2 =
    λ_cycle3 = 1 and, when P4 is given (the warm-up, epoch <
    epoch_reconstruct), the self-reconstruction term with weight 1.
    weights {term: factor} multiplies a term (the checks' negative
    controls); nn_idx as triplet_chamfer_loss's. Returns (total loss
    tensor, {term: float}, triplet)."""
    w = {k: 1.0 for k in TERMS}
    w.update(weights or {})
    t = TripletPointCloud(P1, P2, P3)
    fix = make_fix(P1.size(0), P1.size(1), P1.device)
    triplet_chamfer_loss(network, t, fix, exact_nn, nn_idx)
    total = w["chamfer"] * t.loss_train_Deformation_ChamferL2
    t.compute_loss_cycle2()
    total = total + w["cycle2"] * t.loss_train_cycleL2_2
    t.compute_loss_cycle3()
    total = total + w["cycle3"] * t.loss_train_cycleL2_3
    terms = {"chamfer": t.loss_train_Deformation_ChamferL2.item(),
             "cycle2": t.loss_train_cycleL2_2.item(), "cycle3": t.loss_train_cycleL2_3.item(),
             "selfrec": 0.0}
    if P4 is not None:
        t.compute_loss_selfReconstruction(network, P4)
        total = total + w["selfrec"] * 1.0 * t.loss_train_selfReconstruction_L2
        terms["selfrec"] = t.loss_train_selfReconstruction_L2.item()
    terms["total"] = total.item()
    return total, terms, t


def losses_at(P1, P2, P3, D, P4=None, D_self=None, weights=None, nn_idx=None):
    """The same loss as train_iteration_loss, evaluated at given network
    outputs instead of running the network: D {deformation name ("P2_P1",
    …): [B, N, 3]} for the six pairs and, with P4, D_self = (P4_P3, P3_P4)
    [B, N, 3]; the nearest neighbours are found on D (or given: nn_idx as
    triplet_chamfer_loss's). Returns (total
    tensor, {term: float}); the gradient w.r.t. D is the loss gradient the
    network's backward starts from."""
    w = {k: 1.0 for k in TERMS}
    w.update(weights or {})
    t = TripletPointCloud(P1, P2, P3)
    fix = make_fix(P1.size(0), P1.size(1), P1.device)
    clouds = {"P1": P1, "P2": P2, "P3": P3}
    for name, d in D.items():
        target, source = name.split("_")
        dist1, dist2, idx1, idx2 = dist_chamfer(d, clouds[target], True, (nn_idx or {}).get(name))
        t.add(target, source,
              (d, dist1, dist2, batch_idx(idx1, fix), batch_idx(idx2, fix), None, None))
    t.compute_loss_train_Deformation_ChamferL2()
    t.compute_loss_cycle2()
    t.compute_loss_cycle3()
    total = (w["chamfer"] * t.loss_train_Deformation_ChamferL2
             + w["cycle2"] * t.loss_train_cycleL2_2 + w["cycle3"] * t.loss_train_cycleL2_3)
    terms = {"chamfer": t.loss_train_Deformation_ChamferL2.item(),
             "cycle2": t.loss_train_cycleL2_2.item(), "cycle3": t.loss_train_cycleL2_3.item(),
             "selfrec": 0.0}
    if P4 is not None:
        selfrec = (1 / 2.0) * (L2(D_self[0], P4) + L2(D_self[1], P3))
        total = total + w["selfrec"] * selfrec
        terms["selfrec"] = selfrec.item()
    terms["total"] = total.item()
    return total, terms


# ---- tcbench's weight files ---------------------------------------------------


def read_f32(directory, name, shape):
    return np.fromfile(os.path.join(directory, name), dtype="<f4").reshape(shape)


def read_i32(directory, name, shape):
    return np.fromfile(os.path.join(directory, name), dtype="<i4").reshape(shape)


def read_flat(directory, stem):
    """(manifest, flat float32 vector: parameters then buffers) of weights
    written by tcb_cc_net_export as STEM.bin + STEM.json."""
    with open(os.path.join(directory, stem + ".json")) as f:
        manifest = json.load(f)
    assert manifest["format"] == "tcbench-cc-weights", manifest["format"]
    flat = np.fromfile(os.path.join(directory, stem + ".bin"), dtype="<f4")
    assert flat.size == manifest["nparams"] + manifest["nbuffers"], \
        (flat.size, manifest["nparams"], manifest["nbuffers"])
    return manifest, flat


def unflatten(manifest, flat, params_only=False):
    """{tensor name: array} of a flat vector in the manifest's layout (with
    params_only, of a gradient vector: parameters only)."""
    out = {}
    for t in manifest["tensors"]:
        if params_only and t["offset"] >= manifest["nparams"]:
            continue
        out[t["name"]] = flat[t["offset"]:t["offset"] + t["count"]].reshape(t["shape"])
    return out


def from_manifest(manifest):
    """A network of the manifest's sizes."""
    return AE_Meta_AtlasNet(manifest["C"], manifest["Z"], [manifest["H"]] * manifest["L"])


def load_weights(model, directory, stem="weights"):
    """Loads STEM.bin/.json into model (conv weights [out, in] → [out, in,
    1]); every state_dict tensor but num_batches_tracked must be in the
    manifest and vice versa. Returns the manifest."""
    manifest, flat = read_flat(directory, stem)
    values = unflatten(manifest, flat)
    state = model.state_dict()
    names = {n for n in state if not n.endswith("num_batches_tracked")}
    missing, extra = sorted(names - set(values)), sorted(set(values) - names)
    assert not missing and not extra, f"tensor names differ: torch only {missing}, C only {extra}"
    for name, value in values.items():
        shape = tuple(state[name].shape)
        if shape != value.shape:
            assert shape == value.shape + (1,), (name, shape, value.shape)
            value = value.reshape(shape)
        state[name] = torch.from_numpy(value.copy()).to(state[name].dtype)
    model.load_state_dict(state)
    return manifest


def named_tensors(model):
    """{manifest name: float64 array} of parameters and running statistics,
    conv weights as [out, in]."""
    out = {}
    for name, t in model.state_dict().items():
        if name.endswith("num_batches_tracked"):
            continue
        a = t.detach().double().numpy()
        out[name] = a.reshape(a.shape[:2]) if a.ndim == 3 else a
    return out


def named_grads(model):
    out = {}
    for name, q in model.named_parameters():
        a = q.grad.detach().double().numpy()
        out[name] = a.reshape(a.shape[:2]) if a.ndim == 3 else a
    return out


def rel_error(got, want):
    """max |got − want| relative to max |want| (1 where want is all zero)."""
    scale = np.abs(want).max()
    return np.abs(got - want).max() / (scale if scale > 0 else 1.0)


# Biases whose constant a training-mode batch norm subtracts, so that their
# exact gradient is zero and both sides hold rounding noise: those of the
# layers that feed one, and PointNet's bn3 β (max-pool, Linear, then the
# batch norm over the shapes). Their errors are measured against the
# gradient of the same layer's weight (what a non-zero bias gradient would
# be of the order of: Σ_rows dx against Σ_rows dx·h).
BEFORE_BN = re.compile(r"(encoder2?\.0\.conv\d|encoder2?\.0\.bn3|encoder2?\.1"
                       r"|decoder\.parameter_predictor\.fc[12]"
                       r"|decoder\.MLP\.fc_\d+\.fc\.conv1)\.bias$")


def grad_error(name, got, grads):
    """rel_error, or for a BEFORE_BN bias max |got − torch| / max |∂weight|."""
    if not BEFORE_BN.search(name):
        return rel_error(got, grads[name])
    scale = np.abs(grads[name[:-len("bias")] + "weight"]).max()
    return np.abs(got - grads[name]).max() / scale

"""DynoSurf's pieces in PyTorch, written as the reference runs them
(github yaoyx689/DynoSurf @ a2b7324) with the library calls it makes
spelled out: the shape network (code/model/dmtet_network.py), kaolin's
marching_tetrahedra (kaolin/ops/conversions/tetmesh.py, v0.14), pytorch3d's
sample_points_from_meshes and chamfer_distance(norm=1) (v0.7.4), and the
approximate SDF (code/loss.py approximate_sdf_loss). The tcbench checks
import these; nothing here calls tcbench."""
import torch

SHAPE_WIDTHS = [33, 128, 128, 128, 128, 128, 4]


class Embedder:
    """The NeRF embedder: x, then sin and cos of x times 2^0 … 2^(multires−1)."""

    def __init__(self, multires):
        self.freqs = 2.0 ** torch.linspace(0.0, multires - 1, multires)

    def __call__(self, x):
        out = [x]
        for f in self.freqs:
            out += [torch.sin(x * f), torch.cos(x * f)]
        return torch.cat(out, -1)


def shape_net(params):
    """The Decoder's bias-free layers with LeakyReLU (slope 0.01)."""
    return mlp(params, SHAPE_WIDTHS, 0.01)


def shape_forward(net, x, edge):
    """trainer.py: sdf = out[:, 0], v = x + tanh(out[:, 1:4]) · edge."""
    out = net(Embedder(5)(x))
    return out, out[:, 0], x + torch.tanh(out[:, 1:4]) * edge


BASE_TET_EDGES = torch.tensor([0, 1, 0, 2, 0, 3, 1, 2, 1, 3, 2, 3])
TRIANGLE_TABLE = torch.tensor([
    [-1, -1, -1, -1, -1, -1], [1, 0, 2, -1, -1, -1], [4, 0, 3, -1, -1, -1], [1, 4, 2, 1, 3, 4],
    [3, 1, 5, -1, -1, -1], [2, 3, 0, 2, 5, 3], [1, 4, 0, 1, 5, 4], [4, 2, 5, -1, -1, -1],
    [4, 5, 2, -1, -1, -1], [4, 1, 0, 4, 5, 1], [3, 2, 0, 3, 5, 2], [1, 3, 5, -1, -1, -1],
    [4, 1, 2, 4, 3, 1], [3, 0, 4, -1, -1, -1], [2, 0, 1, -1, -1, -1], [-1, -1, -1, -1, -1, -1]])
NUM_TRIANGLES_TABLE = torch.tensor([0, 1, 1, 2, 1, 2, 2, 1, 1, 2, 2, 1, 2, 1, 1, 0])
V_ID = torch.pow(2, torch.arange(4))


def marching_tetrahedra(pos, tet, sdf):
    """kaolin's steps: torch.unique over the valid tets' sorted edges, the
    crossing ones numbered in that order, the interpolation weights flipped
    over s_a − s_b, faces from the 16-case table, one-triangle tets first."""
    with torch.no_grad():
        occ_n = sdf > 0
        occ_fx4 = occ_n[tet.reshape(-1)].reshape(-1, 4)
        occ_sum = occ_fx4.sum(-1)
        valid_tets = (occ_sum > 0) & (occ_sum < 4)
        all_edges = tet[valid_tets][:, BASE_TET_EDGES].reshape(-1, 2)
        all_edges = torch.sort(all_edges, dim=1)[0]
        unique_edges, idx_map = torch.unique(all_edges, dim=0, return_inverse=True)
        mask_edges = occ_n[unique_edges.reshape(-1)].reshape(-1, 2).sum(-1) == 1
        mapping = torch.ones(unique_edges.shape[0], dtype=torch.long) * -1
        mapping[mask_edges] = torch.arange(int(mask_edges.sum()))
        idx_map = mapping[idx_map]
        interp_v = unique_edges[mask_edges]
    edges_to_interp = pos[interp_v.reshape(-1)].reshape(-1, 2, 3)
    edges_to_interp_sdf = sdf[interp_v.reshape(-1)].reshape(-1, 2, 1)
    edges_to_interp_sdf = torch.cat([edges_to_interp_sdf[:, :1], -edges_to_interp_sdf[:, 1:]], 1)
    denominator = edges_to_interp_sdf.sum(1, keepdim=True)
    edges_to_interp_sdf = torch.flip(edges_to_interp_sdf, [1]) / denominator
    verts = (edges_to_interp * edges_to_interp_sdf).sum(1)
    idx_map = idx_map.reshape(-1, 6)
    tetindex = (occ_fx4[valid_tets] * V_ID.unsqueeze(0)).sum(-1)
    num_triangles = NUM_TRIANGLES_TABLE[tetindex]
    faces = torch.cat((
        torch.gather(idx_map[num_triangles == 1], 1, TRIANGLE_TABLE[tetindex[num_triangles == 1]][:, :3]).reshape(-1, 3),
        torch.gather(idx_map[num_triangles == 2], 1, TRIANGLE_TABLE[tetindex[num_triangles == 2]][:, :6]).reshape(-1, 3),
    ), dim=0)
    return verts, faces


def sample_points(verts, faces, face_idx, w):
    """sample_points_from_meshes(return_normals=True) for given draws: the
    points w0 a + w1 b + w2 c and their faces' unit normals
    (b − a) × (c − b), normalised with eps 1e-6 as pytorch3d does."""
    a, b, c = (verts[faces[face_idx, k]] for k in range(3))
    pts = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:3] * c
    n = torch.nn.functional.normalize(torch.cross(b - a, c - b, dim=1), eps=1e-6, dim=1)
    return pts, n


def _cos_term(a, b):
    return 1 - torch.nn.functional.cosine_similarity(a, b, dim=1, eps=1e-6).abs()


def chamfer_l1(x, nx, y, ny):
    """chamfer_distance(x, y, x_normals, y_normals, norm=1): the L1-nearest
    neighbours both ways (exact, by a full distance matrix), means over
    points, 1 − |cos| for the normals."""
    d = torch.cdist(x.detach().double(), y.detach().double(), p=1)
    to_y, to_x = d.argmin(1), d.argmin(0)
    cham = (x - y[to_y]).abs().sum(1).mean() + (y - x[to_x]).abs().sum(1).mean()
    normal = _cos_term(nx, ny[to_y]).mean() + _cos_term(ny, nx[to_x]).mean()
    return cham, normal


def approx_sdf(v, p, n, k=10, r=0.1, search=torch.float64):
    """approximate_sdf_loss's target: over the k nearest points,
    softmax(exp(−d²/r²)) weights of n·(v − p). The neighbours are searched
    in `search` (float64: the checks' exact ties; the bench's peer float32)."""
    d2 = torch.cdist(v.detach().to(search), p.to(search)) ** 2
    idx = d2.topk(k, dim=1, largest=False).indices
    diff = v[:, None, :] - p[idx]
    pp = diff.norm(dim=-1)
    w = torch.softmax(torch.exp(-pp ** 2 / (r * r)), dim=-1)
    return (w * (n[idx] * diff).sum(-1)).sum(-1)


def mlp(params, widths, slope, dtype=torch.float32):
    """Bias-free Linear layers with (Leaky)ReLU between them, loaded from
    the flat [out][in] weights; returns (the module, its Linear layers)."""
    layers = []
    for i in range(len(widths) - 1):
        layers.append(torch.nn.Linear(widths[i], widths[i + 1], bias=False, dtype=dtype))
        if i < len(widths) - 2:
            layers.append(torch.nn.LeakyReLU(slope) if slope > 0 else torch.nn.ReLU())
    net = torch.nn.Sequential(*layers)
    linears = [m for m in net if isinstance(m, torch.nn.Linear)]
    at = 0
    with torch.no_grad():
        for m in linears:
            k = m.weight.numel()
            m.weight.copy_(params[at:at + k].reshape(m.weight.shape))
            at += k
    assert at == params.numel()
    return net, linears


TRANSFORM_WIDTHS = [20, 128, 128, 128, 128, 128, 6]
BLEND_WIDTHS = [6, 128, 128, 128, 128, 128, 1]


def so3_exp(r):
    """LieAlgebra/so3.py exp: R = I + sinc1(θ) W + sinc2(θ) W², with the
    reference's series below θ = 0.01 (sinc.py)."""
    theta = r.norm(dim=-1, keepdim=True)[..., None]
    small = theta < 0.01
    t2 = theta * theta
    safe = torch.where(small, torch.ones_like(theta), theta)
    a = torch.where(small, 1 - t2 / 6 * (1 - t2 / 20 * (1 - t2 / 42)), torch.sin(safe) / safe)
    b = torch.where(small, 0.5 * (1 - t2 / 12 * (1 - t2 / 30 * (1 - t2 / 56))), (1 - torch.cos(safe)) / (safe * safe))
    zero = torch.zeros_like(r[..., 0])
    W = torch.stack([torch.stack([zero, -r[..., 2], r[..., 1]], -1),
                     torch.stack([r[..., 2], zero, -r[..., 0]], -1),
                     torch.stack([-r[..., 1], r[..., 0], zero], -1)], -2)
    eye = torch.eye(3, dtype=r.dtype).expand_as(W)
    return eye + a * W + b * (W @ W)


def deformer_transforms(control, transform_net, frames):
    """ControlPts_deformer: raw [F][K][6] = MLP_T(posenc([t, c_k], 2)), R = exp(raw[..., :3])."""
    K = control.shape[0]
    t = torch.tensor(frames, dtype=control.dtype)[:, None, None].expand(len(frames), K, 1)
    tc = torch.cat([t, control[None].expand(len(frames), K, 3)], -1)
    raw = transform_net(Embedder(2)(tc))
    return raw, so3_exp(raw[..., :3])


def deformer_weights(control, blend_net, x):
    """softmax_k MLP_W([x, x − c_k]) [n][K]."""
    K = control.shape[0]
    xe = x[:, None, :].expand(x.shape[0], K, 3)
    return torch.softmax(blend_net(torch.cat([xe, xe - control[None]], -1))[..., 0], -1)


def deform(x, w, R, raw):
    """Σ_k w_k (R_k x + T_k) for one frame: x [n][3], R [K][3][3], raw [K][6]."""
    moved = torch.einsum("kab,nb->nka", R, x) + raw[None, :, 3:]
    return (w[..., None] * moved).sum(1)


def gaussian_weights(control, x, sigma=0.1):
    d2 = ((x[:, None, :] - control[None]) ** 2).sum(-1)
    return torch.softmax(-d2 / (2 * sigma * sigma), -1)


MOTION_WEIGHTS = {"chamfer": 500, "normal": 0.001, "identity": 1, "sdf_sign": 100, "smooth": 1000}


def robust_way(a, na, b, nb):
    """calc_robust_chamfer_single_direction: Σ w(d²) d² over a's nearest
    points in b (w the Welsch weight, detached) and the mean of 1 − |cos|."""
    with torch.no_grad():
        j = torch.cdist(a, b).argmin(1)
    s = ((a - b[j]) ** 2).sum(1)
    w = torch.exp(-s.detach() ** 2 / (2 * 0.3 ** 2))
    cos = torch.nn.functional.cosine_similarity(na, nb[j], dim=1, eps=1e-6)
    return (w * s).sum(), (1 - cos.abs()).mean()


def motion_terms(control, transform_net, blend_net, tv, tf, pts, nrm, y, yhat, key, draw, search=torch.float64):
    """Stage 2's five terms, unweighted (code/loss.py calc_joint_loss; the
    weights are MOTION_WEIGHTS): the template tv, tf carried into every
    frame of pts, nrm; draw(t, X_t) gives frame t's surface draws (face
    indices, barycentric weights); the grid picks y with their SDF yhat;
    the approximate SDF's neighbours searched in `search`."""
    F = len(pts)
    raw, R = deformer_transforms(control, transform_net, list(range(F)))
    wt, wg = deformer_weights(control, blend_net, tv), deformer_weights(control, blend_net, y)
    X = torch.stack([deform(tv, wt, R[t], raw[t]) for t in range(F)])
    Y = torch.stack([deform(y, wg, R[t], raw[t]) for t in range(F)])
    cham = normal = 0
    for t in range(F):
        xs, nxs = sample_points(X[t], tf, *draw(t, X[t]))
        c1, n1 = robust_way(xs, nxs, pts[t], nrm[t])
        c2, n2 = robust_way(pts[t], nrm[t], xs, nxs)
        cham, normal = cham + (c1 + c2) / F, normal + (n1 + n2) / F
    identity = (raw[key] ** 2).sum()
    s = torch.stack([approx_sdf(Y[t], pts[t], nrm[t], search=search) for t in range(F)]).to(Y.dtype)
    rho = torch.softmax(-s.detach() ** 2 / (2 * 0.1 ** 2), 0)
    sdf_sign = (rho * torch.sigmoid(100 * yhat)[None] - rho * torch.sigmoid(100 * s)).abs().mean()
    nbrs = [sorted([min(t + 1, F - 1), max(t - 1, 0)]) for t in range(F)]
    D = torch.stack([X[u] - X[t] for t in range(F) for u in nbrs[t]])
    smooth = sum(((D[:, tf[:, a]] - D[:, tf[:, b]]) ** 2).sum() for a, b in ((0, 1), (1, 2), (0, 2))) / (3 * len(tf))
    return {"chamfer": cham, "normal": normal, "identity": identity, "sdf_sign": sdf_sign, "smooth": smooth}

#!/usr/bin/env python3
"""A template method's keyframe template against the keyframe's ground-truth mesh.

    scripts/keyframe_template.py CONFIG DATASET/SEQUENCE WORK_DIR [--samples N] [--seed S]

WORK_DIR is a neupig, pdg or dynosurf cell's work directory (runs/<run>/
work/<dataset>/<sequence>/<method>/seed_<s>), where its fit wrote
template_keyframe_<K>.obj in the sequence's coordinates (neupig and pdg
before training, dynosurf after its stage 1). Prints one line per measure:
the template's vertex and face counts; its edges with one face (holes) and with more than
two (sheets that touch); whether every directed edge occurs once
(consistently oriented); its connected components and the largest one's
faces; and sqrt(Chamfer)/diagonal against frame K of the sequence as
`tcbench run CONFIG` scores it (tcbench.load_sequence), with Chamfer the sum
of the two mean squared nearest distances between N area-uniform samples of
each surface (scipy's cKDTree) and the diagonal the GT frame's bounding box.
Independent of the C code: numpy and scipy only, the mesh read from the OBJ.
A per-clip fit (the clip protocol's "fit": "per_clip") is named by its
clip, DATASET/<sequence>_<start> (ama/crane_0010), which loads as the
17-frame sequence the fit saw.
"""

from __future__ import annotations

import argparse
import glob
import os
import re
import sys

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree


def read_obj(path: str) -> tuple[np.ndarray, np.ndarray]:
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif parts and parts[0] == "f":
                faces.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64)


def edge_faces(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Faces per undirected edge, and occurrences per directed edge."""
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, per_directed = np.unique(directed, axis=0, return_counts=True)
    _, per_edge = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    return per_edge, per_directed


def components(faces: np.ndarray, nv: int) -> np.ndarray:
    """The component label of each face (faces joined through shared vertices)."""
    rows = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2]])
    cols = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(nv, nv))
    _, label = connected_components(graph, directed=False)
    return label[faces[:, 0]]


def sample_surface(verts: np.ndarray, faces: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    a, b, c = (verts[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    pick = rng.choice(len(faces), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return a[pick] + u[:, None] * (b[pick] - a[pick]) + v[:, None] * (c[pick] - a[pick])


def chamfer(p: np.ndarray, q: np.ndarray) -> float:
    d_pq, _ = cKDTree(q).query(p)
    d_qp, _ = cKDTree(p).query(q)
    return float(np.mean(d_pq ** 2) + np.mean(d_qp ** 2))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config")
    ap.add_argument("sequence", help="DATASET/SEQUENCE")
    ap.add_argument("work_dir")
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    found = glob.glob(os.path.join(args.work_dir, "template_keyframe_*.obj"))
    if len(found) != 1:
        print(f"{args.work_dir}: expected one template_keyframe_<K>.obj (a neupig, pdg or dynosurf fit's), "
              f"found {len(found)}", file=sys.stderr)
        return 2
    key = int(re.search(r"template_keyframe_(\d+)\.obj$", found[0]).group(1))
    dataset, _, sequence = args.sequence.partition("/")
    import tcbench  # the C library's own loading, normalisation and alignment
    seq = tcbench.load_sequence(args.config, dataset, sequence)
    gt_verts = seq["verts"][key].astype(np.float64)
    gt_faces = seq["faces"].astype(np.int64)

    verts, faces = read_obj(found[0])
    per_edge, per_directed = edge_faces(faces)
    label = components(faces, len(verts))
    sizes = np.bincount(label)
    sizes = sizes[sizes > 0]
    rng = np.random.default_rng(args.seed)
    cd = chamfer(sample_surface(verts, faces, args.samples, rng), sample_surface(gt_verts, gt_faces, args.samples, rng))
    diag = float(np.linalg.norm(gt_verts.max(axis=0) - gt_verts.min(axis=0)))
    print(f"template        {found[0]} (keyframe {key} of {seq['n_frames']})")
    print(f"vertices        {len(verts)}")
    print(f"faces           {len(faces)} (GT frame: {len(gt_verts)} vertices, {len(gt_faces)} faces)")
    print(f"boundary edges  {int(np.sum(per_edge == 1))}")
    print(f"edges in >2 faces {int(np.sum(per_edge > 2))}")
    print(f"oriented        {'yes' if per_directed.max() == 1 else 'no'} (directed edges used twice: "
          f"{int(np.sum(per_directed > 1))})")
    print(f"components      {len(sizes)} (largest {int(sizes.max())} faces)")
    print(f"sqrt(CD)/diag   {np.sqrt(cd) / diag:.5f} ({args.samples} samples each, diagonal {diag:.4g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())

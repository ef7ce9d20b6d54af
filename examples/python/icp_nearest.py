#!/usr/bin/env python3
"""Rigid ICP, then nearest neighbour: a tcbench method in numpy and scipy.

For pair (i, j) frame i's vertices are aligned to frame j's by rigid ICP
(nearest-neighbour matches, then the best rotation and translation by
Kabsch's SVD, repeated), and every aligned vertex takes the id of frame j's
nearest vertex. It learns nothing, so fit only records that it ran; the
protocol is in skeleton.py and docs/adding-a-method.md.

    "methods": [ { "name": "icp", "method": "external",
                   "params": { "command": ["examples/python/icp_nearest.py"] } } ]

run by $TCBENCH_PYTHON (or the params' "python"; else python3 from PATH).
"""
import json
import os
import sys

import numpy as np
from scipy.spatial import cKDTree

ITERATIONS = 30


def kabsch(src, dst):
    """The rotation R and translation t minimising |src R^T + t - dst|."""
    mu_s, mu_d = src.mean(0), dst.mean(0)
    u, _, vt = np.linalg.svd((src - mu_s).T @ (dst - mu_d))
    d = np.sign(np.linalg.det(vt.T @ u.T))  # a rotation, never a reflection
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return r, mu_d - r @ mu_s


def rigid_icp(src, tree, target):
    """src moved rigidly onto the cloud `target` (whose k-d tree is `tree`)."""
    moved = src
    for _ in range(ITERATIONS):
        _, nearest = tree.query(moved)
        r, t = kabsch(src, target[nearest])
        aligned = src @ r.T + t
        if np.allclose(aligned, moved, rtol=0, atol=1e-7):
            break
        moved = aligned
    return moved


def transfer(m):
    if not os.path.exists(os.path.join(m["model_dir"], "fitted.json")):
        sys.exit("icp_nearest: no fitted.json in %s: the fit step has not run" % m["model_dir"])
    frames = np.load(m["frames"]).astype(np.float64)
    for k, i, j in np.load(m["pairs"]):
        tree = cKDTree(frames[j])
        moved = rigid_icp(frames[i], tree, frames[j])
        _, ids = tree.query(moved)
        np.save(os.path.join(m["out_dir"], "%d.npy" % k), ids.astype(np.int32))


def main():
    step, manifest = sys.argv[-2], sys.argv[-1]
    with open(manifest) as f:
        m = json.load(f)
    if step == "fit":
        with open(os.path.join(m["model_dir"], "fitted.json"), "w") as f:
            json.dump({"method": "icp_nearest", "iterations": ITERATIONS}, f)
    elif step == "transfer":
        transfer(m)
    else:
        sys.exit("unknown step %r" % step)


if __name__ == "__main__":
    main()

"""tcbench from Python: the C library's own code, through ctypes.

    import tcbench
    seq = tcbench.load_sequence("configs/quick.json", "synth", "quadruped_walk")
    split = tcbench.load_split("splits/synth/quadruped_walk.json")
    i, j = split["pairs"][0]
    m = tcbench.pair_metrics(seq["verts"][j], my_predicted_vertex_ids)
    cell = tcbench.read_cell("runs/quick/cells/synth/quadruped_walk/nearest/seed_0.json")
    ev = tcbench.Evaluator("configs/quick.json", "synth", "quadruped_trot")
    result = ev.evaluate({k: my_ids_or_points(i, j) for k, (i, j) in enumerate(ev.pairs)})

Every number comes from libtcbench, computed by the code `tcbench run`
uses, so it equals what the cell files hold to the last bit; every error
is the C library's, raised as TcbError with its message. numpy is the only
dependency. _lib.py says how the library is found (TCBENCH_LIB first).
"""

from __future__ import annotations

import os

import numpy as np
from numpy.typing import ArrayLike

from ._convert import cell_of, sequence_of
from ._lib import ENV_VAR, TcbError, library, path_bytes
from .evaluate import Evaluator

__all__ = ["TcbError", "pair_metrics", "load_split", "load_sequence", "read_cell", "library_path", "ENV_VAR",
           "Evaluator"]

# Columns of a cell's pair row that a prediction alone does not determine:
# the frames, the Chamfer distance of a method's reconstructions, and the
# geodesic error, which needs frame j's faces (pair_metrics takes vertices
# only; a cell's rows have it, read_cell gives them).
_NOT_FROM_PREDICTION = ("i", "j", "cd", "geo", "geo_m2", "geo_auc", "geo_unreachable")


def library_path() -> str:
    """The path of the libtcbench this process loaded."""
    return library().path


def _frame(verts_j: ArrayLike) -> np.ndarray:
    """verts_j as C-ordered float32 (K, 3); a cast that would change a
    value is refused (frames are float32 in tcbench)."""
    v = np.asarray(verts_j)
    if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] < 1:
        raise ValueError(f"verts_j: shape {v.shape}: expected (K, 3) vertices")
    if v.dtype.kind not in "fiu":
        raise ValueError(f"verts_j: dtype {v.dtype}: expected float32 vertices")
    out = np.ascontiguousarray(v, dtype=np.float32)
    if v.dtype != np.float32 and not np.array_equal(out, v):
        raise ValueError(f"verts_j: dtype {v.dtype}: values change as float32 (tcbench's frames are float32)")
    return out


def _vertex_ids(pred_ids: ArrayLike, k: int) -> np.ndarray:
    """pred_ids as int32 (K,): integers only (never rounded from floats),
    any value int32 holds; the range [0, K) is the C library's check."""
    p = np.asarray(pred_ids)
    if p.shape != (k,):
        raise ValueError(f"pred_ids: shape {p.shape}: expected ({k},), one vertex id per vertex of verts_j")
    if p.dtype.kind not in "iu":
        raise ValueError(f"pred_ids: dtype {p.dtype}: vertex ids must be integers")
    info = np.iinfo(np.int32)
    bad = np.flatnonzero((p < info.min) | (p > info.max))
    if bad.size:
        raise ValueError(f"pred_ids[{bad[0]}] = {p[bad[0]]}: outside [0, {k})")
    return np.ascontiguousarray(p, dtype=np.int32)


def pair_metrics(verts_j: ArrayLike, pred_ids: ArrayLike) -> dict:
    """The metrics of one pair i -> j from the predicted vertex id of frame j
    for each vertex: verts_j is frame j's (K, 3) vertices (as load_sequence
    gives them), pred_ids the (K,) predicted ids (what a method's transfer
    projects to). Returns

    - ``error``, ``sq_error``, ``rank``: (K,) float64 per vertex: the
      Euclidean error |q_pred[k] - q_k|, its square d_k, and the rank (the
      fraction of vertices closer to q_k than d_k);
    - ``pck``: the (S,) PCK curve on squared errors, ``pck_thresholds`` its
      thresholds;
    - ``summary``: the pair's row of a cell file, {column: float}, bit for
      bit: n, sl2 (m_sL2, the mean error), sl2_m2, sl2sq, sl2sq_m2, rank,
      rank_m2, auc, and any column the cell format gains (the frames i, j,
      the Chamfer distance cd and the geodesic error geo, geo_m2, geo_auc,
      geo_unreachable are left out: a prediction does not have them, and
      the geodesic error needs the frame's faces);
    - ``m_sl2`` and ``auc``: summary["sl2"] and summary["auc"].
    """
    lib = library()
    v = _frame(verts_j)
    k = v.shape[0]
    p = _vertex_ids(pred_ids, k)
    columns = lib.info["pair_columns"]
    sq, rank = np.empty(k), np.empty(k)
    pck, row = np.empty(lib.info["pck_steps"]), np.empty(len(columns))
    lib.call("tcb_binding_pair_metrics", v, k, p, sq, rank, pck, pck.size, row, row.size)
    summary = {c: float(x) for c, x in zip(columns, row) if c not in _NOT_FROM_PREDICTION}
    return {
        "error": np.sqrt(sq),  # sqrt is correctly rounded: the value C's sL2 averages
        "sq_error": sq,
        "rank": rank,
        "pck": pck,
        "pck_thresholds": np.array([lib.c.tcb_pck_threshold(s) for s in range(pck.size)]),
        "summary": summary,
        "m_sl2": summary["sl2"],
        "auc": summary["auc"],
    }


def load_split(path: str | os.PathLike) -> dict:
    """A split file, read and validated by the C reader: its JSON fields
    (format, dataset, sequence, role, n_frames, blocks when it has them,
    seed, n_pairs) with ``pairs`` as an (n_pairs, 2) int32 array of frames
    (i, j)."""
    split = library().text("tcb_binding_split_json", path_bytes(path))
    split["pairs"] = np.array(split["pairs"], dtype=np.int32).reshape(-1, 2)
    return split


def read_cell(path: str | os.PathLike) -> dict:
    """A cell file, read and validated by the C reader (tcb_cell_load): its
    JSON fields as the C library understood them (include/tcb/results.h),
    with ``pairs`` as an (n_pairs, len(pair_columns)) float64 array whose
    columns are ``pair_columns`` (null, e.g. cd without reconstruction, is
    nan)."""
    return cell_of(library().text("tcb_binding_cell_json", path_bytes(path)))


def load_sequence(config: str | os.PathLike, dataset: str, sequence: str,
                  root: str | os.PathLike | None = None) -> dict:
    """The sequence `tcbench run CONFIG` scores dataset/sequence on: generated
    or read (through the config's cache), normalized and aligned as the
    config says, its pools drawn. Relative paths in the config are taken
    from the current directory, as the CLI takes them; root replaces the
    dataset's root (the CLI's --root DATASET=DIR). Returns name, n_frames,
    n_verts, n_faces, pool_size, normalization, input_points, sampling and
    blocks (a list of {name, start, n_frames}; empty: one block), and the
    arrays ``verts`` (F, V, 3) float32, ``faces`` (T, 3) int32, ``areas``
    (F,), ``pools`` (F, P, 3) float32, ``norm_shift`` (F, 3), ``norm_scale``
    (a float) and ``yaw`` (F,) when the frames were rotation-aligned."""
    lib = library()
    handle = lib.call("tcb_binding_sequence_load", path_bytes(config), dataset.encode(), sequence.encode(),
                      None if root is None else path_bytes(root))
    try:
        return sequence_of(lib, handle)
    finally:
        lib.c.tcb_binding_sequence_free(handle)

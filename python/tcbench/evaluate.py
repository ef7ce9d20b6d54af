"""Whole-split evaluation, the COCOeval shape: one evaluator per (config,
dataset, sequence), predictions for every pair of its split in, per-pair
rows and the summary out, the run's cell written on request.

    ev = tcbench.Evaluator("configs/quick.json", "synth", "quadruped_trot")
    ev.pairs                      # (N, 2) int32: pair k is frames (i, j)
    ev.sequence["verts"]          # (F, V, 3) float32, the split's normalised frames
    result = ev.evaluate(predictions)        # dict, list, or a .npz / directory path
    result["summary"]["sl2"]["mean"]         # m_sL2; every metric of a cell file
    ev.write_cell("my_method")               # runs/quick/cells/synth/quadruped_trot/my_method/seed_0.json

The scoring is libtcbench's tcb_evaluator (include/tcb/score.h), the code
`tcbench score` runs: each array goes to it as the bytes of a .npy file,
read by the reader the prediction files go through, so the numbers equal
`tcbench score`'s and a method's own cell to the last bit.
"""

from __future__ import annotations

import ctypes
import functools
import io
import os
from collections.abc import Mapping
from typing import Any, Union

import numpy as np

from ._convert import cell_of, sequence_of
from ._lib import Library, _Error, library, path_bytes

Predictions = Union[Mapping, list, tuple, np.ndarray, str, os.PathLike]


@functools.lru_cache(maxsize=None)
def _declared(lib: Library) -> Library:
    """lib with the evaluator's C prototypes declared (once)."""
    c, text, ptr, c_int = lib.c, ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int
    err = ctypes.POINTER(_Error)
    for name, restype, argtypes in [
        ("tcb_binding_evaluator_open", ptr, [text, text, text, text, text, err]),
        ("tcb_binding_evaluator_free", None, [ptr]),
        ("tcb_binding_evaluator_sequence", ptr, [ptr]),
        ("tcb_binding_evaluator_split_json", ptr, [ptr, err]),
        ("tcb_binding_evaluator_score", ptr, [ptr, c_int, ptr, ptr, text, c_int, err]),
        ("tcb_binding_evaluator_write", ptr, [ptr, text, text, c_int, c_int, err]),
    ]:
        f = getattr(c, name)
        f.restype, f.argtypes = restype, argtypes
    return lib


def _npy_bytes(k: int, a: Any) -> bytes:
    """Pair k's prediction as the bytes numpy.save writes (ids or points
    alike: the C reader judges dtype, shape and values)."""
    try:
        arr = np.asarray(a)
        buf = io.BytesIO()
        np.lib.format.write_array(buf, arr, allow_pickle=False)
    except (ValueError, TypeError) as e:
        raise ValueError(f"predictions[{k}]: {e}") from e
    return buf.getvalue()


def _pair_index(key: Any) -> int | None:
    """key as a pair index: an integer, or its decimal text as written by
    str(k) (the .npz members' names); None otherwise."""
    if isinstance(key, (bool, np.bool_)):
        return None
    if isinstance(key, (int, np.integer)):
        return int(key)
    if isinstance(key, str) and key.isdigit() and key.isascii() and str(int(key)) == key:
        return int(key)
    return None


def _as_list(predictions: Mapping | list | tuple | np.ndarray, n: int) -> list:
    """The predictions as a list indexed by pair; a mapping's keys must be
    the pair indices 0 .. n-1, each once."""
    if not isinstance(predictions, Mapping):
        items = list(predictions)
        if len(items) != n:
            raise ValueError(f"predictions: {len(items)} arrays for the {n} pairs of the split")
        return items
    keys = {}
    for key in predictions:
        k = _pair_index(key)
        if k is None:
            raise ValueError(f"predictions: key {key!r}: keys are pair indices (int, or str as np.load of an "
                             f".npz gives them), 0 to {n - 1}")
        if k in keys:
            raise ValueError(f"predictions: keys {keys[k]!r} and {key!r} name the same pair")
        keys[k] = key
    surplus = sorted(k for k in keys if not 0 <= k < n)
    missing = [k for k in range(n) if k not in keys]
    if surplus:
        raise ValueError(f"predictions: key {surplus[0]}: the split has {n} pairs (0 to {n - 1})")
    if missing:
        raise ValueError(f"predictions: no prediction for pair {missing[0]} (of 0 to {n - 1})"
                         + (f" and {len(missing) - 1} more" if len(missing) > 1 else ""))
    return [predictions[keys[k]] for k in range(n)]


class Evaluator:
    """Scores predictions for every pair of one sequence's split as
    `tcbench score` does, and writes them as a cell of the run.

    config, dataset, sequence: as `tcbench score CONFIG --dataset D
    --sequence S`; root and variant as its --root D=DIR and --variant. The
    config's relative paths are taken from the current directory, as the
    CLI takes them. A split file not there yet is drawn and saved as `tcbench
    run` would."""

    def __init__(self, config: str | os.PathLike, dataset: str, sequence: str,
                 root: str | os.PathLike | None = None, variant: str | None = None) -> None:
        self._lib = _declared(library())
        self._handle = None
        self._handle = self._lib.call(
            "tcb_binding_evaluator_open", path_bytes(config), dataset.encode(), sequence.encode(),
            None if root is None else path_bytes(root), None if variant is None else variant.encode())
        self.config, self.dataset = os.fspath(config), dataset
        split = self._lib.text("tcb_binding_evaluator_split_json", self._handle)
        #: (N, 2) int32: pair k is frames (pairs[k, 0], pairs[k, 1]) = (i, j)
        self.pairs = np.array(split.pop("pairs"), dtype=np.int32).reshape(-1, 2)
        #: the run directory write_cell uses by default (the config's output)
        self.run_dir = split.pop("run_dir")
        #: the split file's fields (path, format, role, seed, n_pairs, ...)
        self.split = split
        #: the sequence as load_sequence gives it: verts (F, V, 3) in the split's frame, faces, ...
        self.sequence = sequence_of(self._lib, self._lib.c.tcb_binding_evaluator_sequence(self._handle))
        self.result: dict | None = None

    def close(self) -> None:
        if self._handle:
            self._lib.c.tcb_binding_evaluator_free(self._handle)
            self._handle = None

    def __del__(self) -> None:
        self.close()

    def __enter__(self) -> "Evaluator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def evaluate(self, predictions: Predictions, any_frame: bool = False) -> dict:
        """Scores one prediction per pair of the split: a dict {pair index:
        array}, a list (or an array) of N arrays in pair order, or the path
        of an .npz or a directory in `tcbench score`'s format. Each array is
        pair k's for every vertex of frame i: vertex ids of frame j (an
        integer array (V,)) or points on frame j in the split's normalised
        frame (float32 or float64 (V, 3), projected onto frame j's nearest
        vertex). Points that fit the sequence far better once normalised
        again (raw coordinates) are refused unless any_frame.

        Returns the evaluation as a cell file holds it (read_cell's form):
        ``summary`` (every metric: sl2 = m_sL2, sl2sq, rank, auc, pck, the
        geodesic geo, geo_auc, geo_pck, geo_unreachable; each statistic
        {n, mean, m2}), ``pair_columns`` and ``pairs`` (N, len(pair_columns))
        float64, ``rows`` the same as a structured array with a field per
        column, and the cell's identity fields (split, role, status, ...)."""
        lib = self._lib
        self.result = None  # a failed evaluation leaves nothing to write (the library's cell is gone too)
        if isinstance(predictions, (str, os.PathLike)):
            cell = lib.text("tcb_binding_evaluator_score", self._handle, 0, None, None, path_bytes(predictions),
                            int(bool(any_frame)))
        else:
            blobs = [_npy_bytes(k, a) for k, a in enumerate(_as_list(predictions, len(self.pairs)))]
            n = len(blobs)
            arrays = (ctypes.c_char_p * n)(*blobs)
            lengths = (ctypes.c_size_t * n)(*(len(b) for b in blobs))
            cell = lib.text("tcb_binding_evaluator_score", self._handle, n, ctypes.cast(arrays, ctypes.c_void_p),
                            ctypes.cast(lengths, ctypes.c_void_p), None, int(bool(any_frame)))
        cell = cell_of(cell)
        cell["rows"] = np.rec.fromarrays(cell["pairs"].T, names=cell["pair_columns"])
        self.result = cell
        return cell

    def write_cell(self, label: str, run_dir: str | os.PathLike | None = None, seed: int = 0,
                   force: bool = False) -> str:
        """The last evaluation written as the run's cell
        <run_dir>/cells/<dataset>/<sequence>/<label>/seed_<seed>.json, as
        `tcbench score --name label --seed seed [--force]` writes it
        (run_dir: the config's output by default), so `tcbench report` and
        `check` show it as a row. Returns the cell's path."""
        if self.result is None:
            raise RuntimeError("write_cell: nothing evaluated yet (call evaluate first; a refused evaluation leaves nothing)")
        path = self._lib.call("tcb_binding_evaluator_write", self._handle,
                              None if run_dir is None else path_bytes(run_dir), label.encode(), int(seed),
                              int(bool(force)))
        return self._lib.take_text(path)

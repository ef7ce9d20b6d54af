"""C results as Python values: the forms load_sequence, read_cell and the
Evaluator share."""

from __future__ import annotations

import math

import numpy as np


def sequence_of(lib, handle) -> dict:
    """The sequence at a C tcb_sequence pointer as load_sequence returns it:
    its JSON description with each named array copied into numpy."""
    seq = lib.text("tcb_binding_sequence_json", handle)
    for name, spec in seq.pop("arrays").items():
        a = np.empty(spec["shape"], dtype=spec["dtype"])
        lib.call("tcb_binding_sequence_copy", handle, name.encode(), a.ctypes.data, a.nbytes)
        seq[name] = a
    seq["norm_scale"] = float(seq["norm_scale"])
    return seq


def cell_of(cell: dict) -> dict:
    """A cell's JSON with ``pairs`` as an (n_pairs, len(pair_columns))
    float64 array, nan where the file has null."""
    rows = [[math.nan if x is None else x for x in row] for row in cell["pairs"]]
    cell["pairs"] = np.array(rows, dtype=np.float64).reshape(-1, len(cell["pair_columns"]))
    return cell

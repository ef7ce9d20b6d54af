#!/usr/bin/env python3
"""Writes the .npz files tests/unit/test_npz.c reads (and the npz fuzz
target's seeds), with numpy's and zipfile's own writers.

Run from anywhere: python3 tests/data/npz/make.py (the files are committed;
rerun only to change them). Each holds three members, as
`tcbench score` reads them (test_npz.c expects exactly these):
  0.npy: int32 [0, 1, 2, 3]; 1.npy: float64 arange(12).reshape(4, 3) / 4;
  2.npy: uint16 [3, 2, 1, 0]
  stored.npz    np.savez (members stored, ZIP64 local fields: force_zip64)
  deflated.npz  np.savez_compressed
  zip64.npz     zipfile with its ZIP64 limits lowered, so the central
                directory's sizes and offsets and the end record are ZIP64
"""
import io
import os
import zipfile

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
arrays = {"0": np.array([0, 1, 2, 3], dtype=np.int32), "1": np.arange(12).reshape(4, 3) / 4,
          "2": np.array([3, 2, 1, 0], dtype=np.uint16)}

np.savez(os.path.join(here, "stored.npz"), **arrays)
np.savez_compressed(os.path.join(here, "deflated.npz"), **arrays)

zipfile.ZIP64_LIMIT, zipfile.ZIP_FILECOUNT_LIMIT = 16, 1
with zipfile.ZipFile(os.path.join(here, "zip64.npz"), "w", zipfile.ZIP_DEFLATED, allowZip64=True) as z:
    for name, a in arrays.items():
        buf = io.BytesIO()
        np.lib.format.write_array(buf, a, allow_pickle=False)
        z.writestr(name + ".npy", buf.getvalue())

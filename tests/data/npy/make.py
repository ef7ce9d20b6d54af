#!/usr/bin/env python3
"""Writes the .npy files tests/unit/test_npy.c reads, with numpy's own writer.

Run from anywhere: python3 tests/data/npy/make.py (the files are committed;
rerun only to change them). Values (test_npy.c expects exactly these):
  i<n>: [0, 1, -1, min, max] of the type; u<n>: [0, 1, 2, max - 1, max]
  b1: [True, False, True]
  f4/f8: [0, -1.5, max, smallest subnormal, inf, nan]
  points_*: arange(12).reshape(4, 3) * 0.25 - 1 (C or Fortran order)
  cube_F_i2: arange(24).reshape(2, 3, 4) - 12, Fortran order, big-endian
  scalar_i8: 7 (shape ()); empty_i4: shape (0,); empty_f8: shape (0, 3)
"""
import os
import numpy as np
from numpy.lib import format as npf

here = os.path.dirname(os.path.abspath(__file__))


def save(name, a, version=(1, 0)):
    with open(os.path.join(here, name + ".npy"), "wb") as f:
        npf.write_array(f, a, version=version, allow_pickle=False)


for n in (1, 2, 4, 8):
    orders = "<>" if n > 1 else "|"
    for o in orders:
        suffix = {"<": "le", ">": "be", "|": ""}[o]
        tag = "_" + suffix if suffix else ""
        i, u = np.iinfo("i%d" % n), np.iinfo("u%d" % n)
        save("i%d%s" % (n, tag), np.array([0, 1, -1, i.min, i.max], dtype=o + "i%d" % n))
        save("u%d%s" % (n, tag), np.array([0, 1, 2, u.max - 1, u.max], dtype=o + "u%d" % n))
        if n >= 4:
            fi = np.finfo("f%d" % n)
            vals = [0, -1.5, fi.max, fi.smallest_subnormal, np.inf, np.nan]
            save("f%d_%s" % (n, suffix), np.array(vals, dtype=o + "f%d" % n))
save("b1", np.array([True, False, True]))

points = np.arange(12).reshape(4, 3) * 0.25 - 1
save("points_C_f8", points.astype("<f8"))
save("points_F_f8", np.asfortranarray(points.astype("<f8")))
save("points_F_f4_be", np.asfortranarray(points.astype(">f4")))
save("points_v2", points.astype("<f4"), version=(2, 0))
save("points_v3", points.astype("<f4"), version=(3, 0))
save("cube_F_i2", np.asfortranarray((np.arange(24).reshape(2, 3, 4) - 12).astype(">i2")))
save("scalar_i8", np.array(7, dtype="<i8"))
save("empty_i4", np.zeros((0,), dtype="<i4"))
save("empty_f8", np.zeros((0, 3), dtype="<f8"))

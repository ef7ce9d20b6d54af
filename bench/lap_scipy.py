"""scipy side of bench_lap: times scipy.optimize.linear_sum_assignment on a
matrix file written by bench_lap (int32 n_rows, int32 n_cols, then float64
row-major) and prints "<best ms> <total>".

usage: lap_scipy.py FILE [reps]
"""
import sys
import time

import numpy as np
from scipy.optimize import linear_sum_assignment


def read_matrix(path):
    with open(path, "rb") as f:
        n_rows, n_cols = np.fromfile(f, dtype="<i4", count=2)
        return np.fromfile(f, dtype="<f8", count=n_rows * n_cols).reshape(n_rows, n_cols)


def main():
    cost = read_matrix(sys.argv[1])
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    best = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        rows, cols = linear_sum_assignment(cost)
        best = min(best, time.perf_counter() - t0)
    print("%.3f %.17g" % (best * 1e3, cost[rows, cols].sum()))


if __name__ == "__main__":
    main()

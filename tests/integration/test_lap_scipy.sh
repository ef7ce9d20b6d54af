#!/usr/bin/env bash
# tcb_lap_solve against scipy.optimize.linear_sum_assignment: numpy writes
# random and degenerate matrices (ties, duplicated rows and columns, huge
# dynamic range, negative costs, duplicated points), both solvers solve them
# (tcbench through `bench_lap --solve`), and the optimal totals must agree to
# 1e-12 of the summed |cost| (rounding is ~1e-15 here; 1e-9 let a solver with
# a wrong dual update pass on the offset matrix, 5e-11 off). Assignments may
# differ where the optimum is not unique.
# Also checks that bad matrices fail with exit status 2 and a message.
# Skipped when /usr/bin/python3 has no scipy.
set -euo pipefail
: "${TCB_BUILD_DIR:?}"

if ! /usr/bin/python3 -c "import numpy, scipy" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
bench="$TCB_BUILD_DIR/bench/bench_lap"
if [ ! -x "$bench" ]; then
  echo "missing $bench: build the bench_lap target"
  exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

/usr/bin/python3 - "$bench" "$tmp" <<'PY'
import subprocess, sys
import numpy as np
from scipy.optimize import linear_sum_assignment

bench, tmp = sys.argv[1], sys.argv[2]
rng = np.random.default_rng(20240607)

def write(name, c):
    path = "%s/%s.bin" % (tmp, name)
    with open(path, "wb") as f:
        np.array(c.shape, dtype="<i4").tofile(f)
        np.ascontiguousarray(c, dtype="<f8").tofile(f)
    return path

def sqdist(p, q):
    return ((p[:, None, :] - q[None, :, :]) ** 2).sum(-1)

def with_duplicates(n, distinct):
    base = rng.random((distinct, 3))
    return base[rng.integers(distinct, size=n)]

cases = []
for n in (1, 2, 3, 5, 10, 50, 200, 600):
    cases.append(("uniform_%d" % n, rng.random((n, n))))
for n in (10, 100, 400):
    cases.append(("ints3_%d" % n, rng.integers(0, 3, (n, n)).astype(float)))
    cases.append(("ints20_%d" % n, rng.integers(0, 20, (n, n)).astype(float)))
cases.append(("all_equal_300", np.full((300, 300), 0.125)))
base = rng.random((60, 250))
cases.append(("dup_rows_250", base[rng.integers(60, size=250)]))
cases.append(("dup_cols_250", rng.random((250, 60))[:, rng.integers(60, size=250)]))
u = rng.random((300, 300))
cases.append(("dynamic_300", np.where(rng.random((300, 300)) < 0.5, 1e-9 * u, 1e9 * u)))
cases.append(("negative_300", rng.uniform(-1e3, 1e3, (300, 300))))
cases.append(("offset_300", 1e6 + rng.random((300, 300))))
cases.append(("sqdist_800", sqdist(rng.random((800, 3)), rng.random((800, 3)))))
cases.append(("sqdist_dups_500", sqdist(with_duplicates(500, 120), with_duplicates(500, 120))))

worst = 0.0
for name, c in cases:
    out = subprocess.run([bench, "--solve", write(name, c)], capture_output=True, text=True)
    assert out.returncode == 0, (name, out.returncode, out.stderr)
    lines = out.stdout.split("\n")
    total = float(lines[0].split()[1])
    cols = np.array([int(x) for x in lines[1].split()])
    n = c.shape[0]
    assert sorted(cols.tolist()) == list(range(n)), (name, "not a permutation")
    mine = c[np.arange(n), cols]
    rows, ref_cols = linear_sum_assignment(c)
    ref = c[rows, ref_cols]
    # Relative to the magnitude of the summed terms (negative costs can make
    # the total itself near zero).
    scale = max(np.abs(ref).sum(), 1e-300)
    assert abs(total - mine.sum()) <= 1e-12 * scale, (name, total, mine.sum())
    diff = abs(total - ref.sum()) / scale
    assert diff <= 1e-12, (name, total, ref.sum(), diff)
    worst = max(worst, diff)

def expect_failure(name, c, needle):
    out = subprocess.run([bench, "--solve", write(name, c)], capture_output=True, text=True)
    assert out.returncode == 2 and needle in out.stderr, (name, out.returncode, out.stderr)

expect_failure("rectangular", rng.random((3, 4)), "3x4")
bad = rng.random((3, 3)); bad[1, 2] = np.nan
expect_failure("nan", bad, "(row 1, col 2)")
bad = rng.random((3, 3)); bad[2, 0] = np.inf
expect_failure("inf", bad, "(row 2, col 0)")
print("lap vs scipy: %d matrices agree, largest relative difference %.1e" % (len(cases), worst))
PY

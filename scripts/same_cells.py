#!/usr/bin/env python3
"""Are two run directories' cells the same? For a change that must not
change behaviour (a refactoring, a move): every cell file of RUN_A has its
twin in RUN_B and back, and every field of each pair is equal, numbers to
the last bit, except those that differ between any two runs of one build
(git_revision, timings, peak_rss_kb). `tcbench check` is the tolerant
comparison; this one is exact.

    scripts/same_cells.py RUN_A RUN_B      exit 0: the same, 1: not, 2: bad input
"""
import glob
import json
import os
import sys

VOLATILE = {"git_revision", "timings", "peak_rss_kb"}


def cells(run):
    return sorted(os.path.relpath(p, run) for p in glob.glob(os.path.join(run, "cells", "**", "*.json"),
                                                              recursive=True))


def main():
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    a, b = sys.argv[1:]
    fa, fb = cells(a), cells(b)
    if not fa:
        print(f"same_cells: {a}: no cells", file=sys.stderr)
        return 2
    differ = 0
    for f in sorted(set(fa) ^ set(fb)):
        print(f"only in {a if f in fa else b}: {f}")
        differ += 1
    for f in sorted(set(fa) & set(fb)):
        with open(os.path.join(a, f)) as fa_, open(os.path.join(b, f)) as fb_:
            ca, cb = json.load(fa_), json.load(fb_)
        keys = [k for k in sorted(set(ca) | set(cb)) if k not in VOLATILE and ca.get(k) != cb.get(k)]
        if keys:
            print(f"differ: {f}: {', '.join(keys)}")
            differ += 1
    print(f"{len(set(fa) | set(fb))} cells, {differ} differ (every field compared exactly but "
          f"{', '.join(sorted(VOLATILE))})")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())

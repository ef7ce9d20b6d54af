#!/usr/bin/env bash
# tcbench's paired bootstrap against an independent numpy computation (skipped
# when /usr/bin/python3 has no numpy). bootstrap_dump writes the inputs,
# every resample's draws (A's seeds, B's seeds, then the pairs) and its
# estimate and interval; numpy recomputes each resample's mean difference
# from those indices, the interval with np.percentile (default "linear"),
# and the estimate from the full data: all equal to 1e-12. Cases: one seed
# each (the seed level a no-op), several seeds of different counts, and
# many pairs; 10 000 resamples each.
set -euo pipefail
: "${TCB_BOOTSTRAP_DUMP:?}"

if ! /usr/bin/python3 -c "import numpy" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy (scripts/setup.sh installs it)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cases="1:1:50:0 3:2:40:1 4:4:200:2"
for c in $cases; do
  IFS=: read -r sa sb p seed <<< "$c"
  mkdir "$tmp/$c"
  "$TCB_BOOTSTRAP_DUMP" "$sa" "$sb" "$p" "$seed" 10000 "$tmp/$c"
done

/usr/bin/python3 - "$tmp" $cases <<'PY'
import sys
import numpy as np

tmp, cases = sys.argv[1], sys.argv[2:]
for case in cases:
    sa, sb, p, _ = map(int, case.split(":"))
    d = "%s/%s/" % (tmp, case)
    xa = np.fromfile(d + "xa.bin", dtype="<f8").reshape(sa, p)
    xb = np.fromfile(d + "xb.bin", dtype="<f8").reshape(sb, p)
    est, lo, hi, n = open(d + "result.txt").read().split()
    est, lo, hi, n = float(est), float(lo), float(hi), int(n)
    assert n == 10000, (case, n)
    draws = np.fromfile(d + "draws.bin", dtype="<i4").reshape(n, sa + sb + p)
    seeds_a, seeds_b, pairs = draws[:, :sa], draws[:, sa:sa + sb], draws[:, sa + sb:]
    assert (seeds_a >= 0).all() and (seeds_a < sa).all(), case
    assert (seeds_b >= 0).all() and (seeds_b < sb).all(), case
    assert (pairs >= 0).all() and (pairs < p).all(), case
    # each resample: mean over drawn pairs of (mean over drawn A seeds) − (mean over drawn B seeds)
    means = np.empty(n)
    for r in range(n):
        a = xa[seeds_a[r]][:, pairs[r]].mean(axis=0)
        b = xb[seeds_b[r]][:, pairs[r]].mean(axis=0)
        means[r] = (a - b).mean()
    ref_lo, ref_hi = np.percentile(means, [2.5, 97.5])
    ref_est = (xa.mean(axis=0) - xb.mean(axis=0)).mean()
    for name, ours, ref in (("estimate", est, ref_est), ("lo", lo, ref_lo), ("hi", hi, ref_hi)):
        assert abs(ours - ref) <= 1e-12, (case, name, ours, ref)
    # the pairs are drawn, not fixed: the interval has width; the draws are not degenerate
    assert hi - lo > 0 and len(np.unique(pairs)) == p, case
    print("S_A %d S_B %d P %3d: estimate %.6f, 95 %% interval [%.6f, %.6f] = numpy's to 1e-12"
          % (sa, sb, p, est, lo, hi))
print("paired bootstrap vs numpy: %d cases agree" % len(cases))
PY

#!/usr/bin/env bash
# tcb_wilcoxon against scipy.stats.wilcoxon(d) with scipy's defaults
# (zero_method "wilcox", no continuity correction, method "auto"): the
# statistic and the two-sided p-value must agree to 1e-10 (rounding is
# ~1e-16) on random vectors (n = 0..200: continuous, rounded so that |d|
# ties, integers with zeros, all zeros — which scipy refuses with a
# ValueError and tcbench reports as no test) and on real per-pair
# differences of m_sL2, rank and AUC between the cells of a tiny synthetic
# run (nearest, nricp, oracle; all 60 pairs, the normal approximation, and
# the first 30, the exact distribution). The method each reports must be
# scipy's: exact exactly when n ≤ 50 and no difference is 0.
# Skipped when /usr/bin/python3 has no scipy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_BUILD_DIR:?}"

if ! /usr/bin/python3 -c "import numpy, scipy.stats" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
dump="$TCB_BUILD_DIR/tests/wilcoxon_dump"
if [ ! -x "$dump" ]; then
  echo "missing $dump: build the wilcoxon_dump target"
  exit 1
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

cat > tiny.json <<'JSON'
{ "name": "tiny", "output": "runs/tiny", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 60, "pool_size": 2000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" }, { "name": "nricp" } ] }
JSON
"$TCBENCH" run tiny.json --quiet 2> run.log || { cat run.log; exit 1; }

/usr/bin/python3 - "$dump" <<'PY'
import json, subprocess, sys, warnings
import numpy as np
from scipy.stats import wilcoxon

dump = sys.argv[1]
rng = np.random.default_rng(20261203)
cases = []  # (name, differences)

# ---- random vectors
for n in list(range(0, 61)) + [75, 99, 100, 101, 150, 199, 200]:
    cases.append(("normal_%d" % n, rng.normal(0.2, 1.0, n)))
    cases.append(("halves_%d" % n, np.round(rng.normal(0.3, 1.0, n) * 2) / 2))   # ties, rare zeros
    cases.append(("ints_%d" % n, rng.integers(-3, 4, n).astype(float)))          # ties and zeros
    d = rng.normal(-0.1, 1e-3, n)
    d[rng.random(n) < 0.1] = 0.0                                                 # a few zeros
    cases.append(("zeros_%d" % n, d))
    cases.append(("shifted_%d" % n, rng.exponential(1.0, n) - 0.2))              # skewed, one-sided
for n in (1, 7, 51):
    cases.append(("allzero_%d" % n, np.zeros(n)))

# ---- real cells: per-pair differences over the common pairs
cells = "runs/tiny/cells/synth/quadruped_walk/"
def per_pair(method):
    c = json.load(open(cells + method + "/seed_0.json"))
    return np.array(c["pairs"], dtype=float), c["pair_columns"]
real = 0
for a, b in [("nearest", "nricp"), ("nricp", "nearest"), ("nearest", "oracle"), ("nricp", "oracle")]:
    pa, cols = per_pair(a)
    pb, _ = per_pair(b)
    # one split, so the same pairs (a pair may be drawn twice) in the same rows
    ij = [cols.index("i"), cols.index("j")]
    assert len(pa) == 60 and (pa[:, ij] == pb[:, ij]).all(), (a, b)
    for metric in ("sl2", "rank", "auc"):
        col = cols.index(metric)
        d = pa[:, col] - pb[:, col]
        for m in (60, 30):
            cases.append(("%s-%s_%s_%d" % (a, b, metric, m), d[:m]))
            real += 1

text = "".join("%d %s\n" % (len(d), " ".join(repr(float(x)) for x in d)) for _, d in cases)
out = subprocess.run([dump], input=text, capture_output=True, text=True, check=True).stdout.splitlines()
assert len(out) == len(cases), (len(out), len(cases))

worst_p = worst_t = 0.0
counts = {}
for (name, d), line in zip(cases, out):
    t, p, method, used = line.split()
    t, p, used = float(t), float(p), int(used)
    counts[method] = counts.get(method, 0) + 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's "switching to normal approximation"
        try:
            ref = wilcoxon(d)
            ref_t, ref_p = float(ref.statistic), float(ref.pvalue)
        except ValueError:               # every difference 0
            ref_t = ref_p = float("nan")
    if np.isnan(ref_p):
        assert method == "none" and np.isnan(p) and np.isnan(t), (name, line)
        continue
    zeros = int((d == 0).sum())
    want = "exact" if len(d) <= 50 and zeros == 0 else "normal"
    assert method == want, (name, method, want)
    assert used == (len(d) if want == "exact" else len(d) - zeros), (name, used)
    assert abs(t - ref_t) <= 1e-10, (name, t, ref_t)
    assert abs(p - ref_p) <= 1e-10, (name, p, ref_p)
    worst_p, worst_t = max(worst_p, abs(p - ref_p)), max(worst_t, abs(t - ref_t))
assert counts.get("exact", 0) > 100 and counts.get("normal", 0) > 100 and counts.get("none", 0) >= 5, counts
print("%d vectors (%d of real cells; %s): max |dp| %.3g, max |dT| %.3g"
      % (len(cases), real, counts, worst_p, worst_t))
PY

# A non-finite difference is refused, naming its index.
if printf '3 1 nan 2\n' | "$dump" > /dev/null 2> err.txt; then
  echo "FAIL: a NaN difference was accepted"; exit 1
fi
grep -qF "wilcoxon: difference 1 is not finite" err.txt || { cat err.txt; exit 1; }
echo "ok"

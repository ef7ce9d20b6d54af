#!/usr/bin/env bash
# Paired comparisons on a tiny synthetic run (nearest, oracle and oracle2 =
# the oracle again; two seeds each; 40 pairs): comparisons.csv's means,
# differences, Wilcoxon p and Holm-adjusted p equal numpy/scipy on the same
# cells (m_sL2, rank, AUC, m_geo; every pair of methods), and its 95 %
# intervals equal numpy's percentile of the resamples that bootstrap_dump
# draws from the same stream (seed 27, "compare/<metric>", 10 000
# resamples); the tables mark the two oracles as tied and not the nearest,
# and bold the oracle once its twin is gone; `tcbench compare` prints the
# same numbers and refuses unknown labels and sequences.
# Skipped when /usr/bin/python3 has no scipy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_BOOTSTRAP_DUMP:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

if ! /usr/bin/python3 -c "import numpy, scipy.stats" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

cat > tiny.json <<'JSON'
{ "name": "tiny", "output": "run", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1],
  "evaluation": { "pairs": 40, "pool_size": 2000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "oracle2", "method": "oracle" }, { "name": "nearest" } ] }
JSON
"$TCBENCH" run tiny.json --quiet 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" report run --quiet 2> /dev/null
for f in comparisons.md comparisons.tex comparisons.csv; do [ -s "run/report/$f" ] || { echo "FAIL: no $f"; exit 1; }; done

/usr/bin/python3 - "$TCB_BOOTSTRAP_DUMP" <<'PY'
import csv, glob, json, os, subprocess, sys
import numpy as np
from scipy.stats import wilcoxon

dump = sys.argv[1]
SCALE = {"sl2": 1e3, "rank": 1e2, "auc": 1e2, "geo": 1e3, "geo_auc": 1e2}
base = "run/cells/synth/quadruped_walk/"
methods = sorted(os.listdir(base))  # the table's row order
x = {}
for m in methods:
    seeds = []
    for path in sorted(glob.glob(base + m + "/seed_*.json")):
        c = json.load(open(path))
        cols = c["pair_columns"]
        seeds.append({k: np.array([r[cols.index(k)] for r in c["pairs"]], float) * SCALE[k] for k in SCALE})
    x[m] = seeds

rows = {(r["metric"], r["method_a"], r["method_b"]): r for r in csv.DictReader(open("run/report/comparisons.csv"))
        if r["sequence"] == "quadruped_walk"}

def close(got, want, what, rel=2e-8, abs_=1e-9):
    if not abs(float(got) - want) <= abs_ + rel * abs(want):
        sys.exit("FAIL %s: %r != %.12g" % (what, got, want))

def holm(p):
    order = np.argsort(p, kind="stable")
    adj, run = np.empty(len(p)), 0.0
    for rank, k in enumerate(order):
        run = max(run, min(1.0, (len(p) - rank) * p[k]))
        adj[k] = run
    return adj

checked = 0
for metric in ("sl2", "rank", "auc", "geo"):
    family = []
    for ia, a in enumerate(methods):
        for b in methods[ia + 1:]:
            r = rows[(metric, a, b)]
            xa = np.array([s[metric] for s in x[a]]); xb = np.array([s[metric] for s in x[b]])
            d = xa.mean(0) - xb.mean(0)
            close(r["mean_a"], xa.mean(0).mean(), f"{metric} {a} mean")
            close(r["diff"], d.mean(), f"{metric} {a}-{b} diff")
            assert r["seeds_a"] == "2" and r["n"] == "40" and r["over"] == "pairs", r
            if np.all(d == 0):
                assert r["p"] == "" and r["p_holm"] == "" and r["significant"] == "0", r
                p = None
            else:
                p = wilcoxon(d).pvalue
                close(r["p"], p, f"{metric} {a}-{b} p", rel=1e-8)
                family.append((r, p))
            # the interval: numpy on the resamples bootstrap_dump draws from the same stream
            os.makedirs("in", exist_ok=True), os.makedirs("out", exist_ok=True)
            xa.astype("<f8").tofile("in/xa.bin"); xb.astype("<f8").tofile("in/xb.bin")
            subprocess.run([dump, "2", "2", "40", "27", "10000", "out", "compare/" + metric, "in"], check=True)
            draws = np.fromfile("out/draws.bin", "<i4").reshape(10000, 44)
            sa, sb, pk = draws[:, :2], draws[:, 2:4], draws[:, 4:]
            va = xa[sa[:, :, None], pk[:, None, :]].mean(1)   # [R][P]: drawn A seeds at drawn pairs
            vb = xb[sb[:, :, None], pk[:, None, :]].mean(1)
            lo, hi = np.percentile((va - vb).mean(1), [2.5, 97.5])
            close(r["lo"], lo, f"{metric} {a}-{b} lo"); close(r["hi"], hi, f"{metric} {a}-{b} hi")
            checked += 1
    adj = holm(np.array([p for _, p in family]))
    for (r, _), q in zip(family, adj):
        close(r["p_holm"], q, f"{metric} {r['method_a']}-{r['method_b']} p_holm", rel=1e-8)
        sig = q < 0.05 and (float(r["lo"]) > 0 or float(r["hi"]) < 0)
        assert r["significant"] == str(int(sig)), r
assert checked == 12, checked
near = rows[("sl2", "nearest", "oracle")]
assert near["significant"] == "1" and float(near["lo"]) > 0, near
print("comparisons.csv equals numpy/scipy on %d comparisons" % checked)
PY

# The tables: the two oracles tied for best (≈, no bold), nearest unmarked;
# no clips were scored, so the Corr marks are empty, and no method has a
# surface: the reconstruction metrics' and Corr-mesh's fields too.
md=run/report/tables.md
grep -qE '^\| oracle \| 0\.00 ± 0\.00 ≈ \|' "$md" && grep -qE '^\| oracle2 \| 0\.00 ± 0\.00 ≈ \|' "$md" ||
    { echo "FAIL: the oracles are not tied"; cat "$md"; exit 1; }
grep -E '^\| nearest \|' "$md" | grep -qvE '≈|\*\*' || { echo "FAIL: nearest marked"; cat "$md"; exit 1; }
grep -qF "≈: tied for best" "$md" || { echo "FAIL: no legend"; exit 1; }
grep -qE '^synth,quadruped_walk,test,oracle2,.*,tie,tie,tie,,tie,tie,,{15}$' run/report/results.csv ||
    { echo "FAIL: results.csv marks"; cat run/report/results.csv; exit 1; }
grep -qF '0.00 $\pm$ 0.00$^{\approx}$' run/report/tables.tex || { echo "FAIL: tex tie"; exit 1; }
grep -qF '| oracle | **-' run/report/comparisons.md || { echo "FAIL: matrix"; cat run/report/comparisons.md; exit 1; }
grep -qF '\textbf{' run/report/comparisons.tex || { echo "FAIL: tex matrix"; exit 1; }

# Without its twin the oracle is significantly best: bold, no tie.
cp -r run solo && rm -rf solo/cells/synth/quadruped_walk/oracle2 solo/report
"$TCBENCH" report solo --quiet --resamples 2000 2> /dev/null
grep -qE '^\| oracle \| \*\*0\.00 ± 0\.00\*\* \| \*\*0\.00 ± 0\.00\*\* \| \*\*100\.00 ± 0\.00\*\* \|' solo/report/tables.md ||
    { echo "FAIL: oracle not bold"; cat solo/report/tables.md; exit 1; }
grep -qE '^synth,quadruped_walk,test,oracle,.*,best,best,best,,best,best,,{15}$' solo/report/results.csv ||
    { echo "FAIL: results.csv best"; exit 1; }

# tcbench compare: the same numbers as the report's matrix, and errors.
expect 0 "A = nearest, B = oracle on synth/quadruped_walk: paired over the split's pairs" \
    "$TCBENCH" compare run nearest oracle
lo=$(awk -F, '$2 == "quadruped_walk" && $4 == "sl2" && $5 == "nearest" && $6 == "oracle" { printf "%.3f", $14 }' run/report/comparisons.csv)
grep -E '^m_sL2 ×1e3 ' out.txt | grep -qF "[$lo, " || { echo "FAIL: compare's interval ($lo)"; cat out.txt; exit 1; }
grep -E '^m_sL2 ×1e3 ' out.txt | grep -qF "B better (significant)" || { echo "FAIL: verdict"; cat out.txt; exit 1; }
grep -qF "40 pairs; seeds: A 2, B 2" out.txt && ! grep -qF "one seed" out.txt || { echo "FAIL: counts"; cat out.txt; exit 1; }
grep -qF "not adjusted (one comparison" out.txt || { echo "FAIL: raw p not said"; exit 1; }
expect 0 "no difference" "$TCBENCH" compare run oracle oracle2 --sequence synth/quadruped_walk --resamples 500
expect 0 "1 sequence resampled" "$TCBENCH" compare run nearest oracle --sequence MEAN --dataset synth --resamples 500
expect 2 "compare: the run has no cell of method 'oracel'" "$TCBENCH" compare run nearest oracel
expect 2 "compare: synth/horse: no cell of nearest there (sequences of synth with both nearest and oracle: quadruped_walk; or MEAN)" \
    "$TCBENCH" compare run nearest oracle --sequence horse
expect 2 "--resamples: expected an integer from 100 to 10000000, got '10'" "$TCBENCH" compare run nearest oracle --resamples 10
expect 0 "usage: tcbench compare RUN_DIR A B" "$TCBENCH" compare --help
echo "compare test passed"

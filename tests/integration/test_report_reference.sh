#!/usr/bin/env bash
# `tcbench report RUN --reference`: a run beside published numbers, in the
# paper's shape, with ours/paper and the order of the methods, written as
# Markdown, LaTeX and CSV; the tables come from the run's config; bad
# references are errors that name the file and key and write nothing.
set -euo pipefail
: "${TCBENCH:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

cat > c.json <<'JSON'
{ "name": "c", "output": "run", "evaluation": { "pairs": 30 },
  "reference": { "source": "toy", "tables": ["B"] },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 8,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
"$TCBENCH" run c.json --quiet 2> /dev/null
sl2=$(/usr/bin/python3 -c "import json; print(json.load(open('run/cells/synth/quadruped_walk/nearest/seed_0.json'))['summary']['sl2']['mean'] * 1e3)")

# The paper of this test says nearest is twice as good as this run finds it, and
# better than the oracle: a flip. Table A is not the config's and stays out.
/usr/bin/python3 - "$sl2" <<'PY'
import json, sys
sl2 = float(sys.argv[1])
row = lambda m, v: {"paper_row": "row " + m, "dataset": "synth", "sequence": "quadruped_walk", "method": m,
                    "sl2": v, "rank": None, "auc": [50.0, 1.0], "cd": None}
json.dump({"format": "tcbench-reference/1", "name": "toy", "paper": "A toy paper",
           "tables": [{"id": "A", "title": "Table A", "rows": [row("oracle", [1, 1])]},
                      {"id": "B", "title": "Table B: toy", "rows": [row("oracle", [sl2, 2.0]), row("nearest", [sl2 / 2, None]),
                                                                    row("absent", [1.0, 1.0])]}]},
          open("toy.json", "w"))
PY
expect 0 "## Table B: toy" "$TCBENCH" report run --reference toy.json
grep -qF "Table A" out.txt && { echo "FAIL: table A is not the config's"; cat out.txt; exit 1; }
# Ratios beyond 1.5x either way are marked: nearest's 2.00, the oracle's 0.00.
grep -qE "^\| row nearest \| nearest \| [0-9.]+ ± [0-9.]+ \| [0-9.]+ \| 2\.00 † \|" out.txt || { echo "FAIL: nearest row"; cat out.txt; exit 1; }
grep -qE "^\| row oracle \| oracle \| 0\.00 ± 0\.00 \| [0-9.]+ ± 2\.00 \| 0\.00 † \|" out.txt || { echo "FAIL: oracle row"; cat out.txt; exit 1; }
grep -qF "†: ours beyond 1.5× the paper's" out.txt || { echo "FAIL: no legend of †"; cat out.txt; exit 1; }
grep -qF "Presets" out.txt && { echo "FAIL: no row names a preset"; cat out.txt; exit 1; }
grep -qF "| row absent | absent | not run |" out.txt || { echo "FAIL: absent row"; cat out.txt; exit 1; }
grep -qF "In the run but in no row" out.txt && { echo "FAIL: every cell has a row"; cat out.txt; exit 1; }
# 30 pairs: the oracle's lead is significant, so the paper's order flips for real.
grep -qF -- "- m_sL2 ↓: 1 ordering: agrees 0, flips (significant) 1, flips (within noise) 0" out.txt &&
grep -qF -- "  - the paper has row nearest better than row oracle: flips (significant)" out.txt ||
    { echo "FAIL: no significant flip"; cat out.txt; exit 1; }
grep -qF -- "- AUC ↑: nothing to order" out.txt || { echo "FAIL: AUC ties order nothing"; cat out.txt; exit 1; }
for f in md tex csv; do [ -s "run/report/reference_toy.$f" ]; done
grep -qF '\begin{tabular}' run/report/reference_toy.tex && grep -qF '\toprule' run/report/reference_toy.tex
/usr/bin/python3 - <<'PY'
import csv
rows = list(csv.DictReader(open("run/report/reference_toy.csv")))
near = [r for r in rows if r["method"] == "nearest" and r["metric"] == "sl2"][0]
assert abs(float(near["ratio"]) - 2) < 1e-5 and near["paper_std"] == "" and near["status"] == "ok", near
assert near["beyond_1_5x"] == "1", near
assert [r["status"] for r in rows if r["method"] == "absent"] == ["not run", "not run"]
PY

# A ratio within 1.5x is not marked: the paper made 1.4 times our nearest.
/usr/bin/python3 - <<'PY'
import json
ref = json.load(open("toy.json"))
near = ref["tables"][1]["rows"][1]
near["sl2"][0] *= 2 / 1.4
json.dump(ref, open("toy14.json", "w"))
PY
expect 0 "## Table B: toy" "$TCBENCH" report run --reference toy14.json --out near14
grep -qE "^\| row nearest \| nearest \| [0-9.]+ ± [0-9.]+ \| [0-9.]+ \| 1\.40 \|" out.txt || { echo "FAIL: 1.40 marked"; cat out.txt; exit 1; }
/usr/bin/python3 - <<'PY'
import csv
far = {r["method"]: r["beyond_1_5x"] for r in csv.DictReader(open("near14/reference_toy.csv")) if r["metric"] == "sl2"}
assert far == {"oracle": "1", "nearest": "0", "absent": "0"}, far
PY

# A cell of a method the paper did not run is named below the tables.
/usr/bin/python3 - <<'PY'
import json
ref = json.load(open("toy.json"))
del ref["tables"][1]["rows"][1]
json.dump(ref, open("toy_no_nearest.json", "w"))
PY
expect 0 "- synth / quadruped_walk: nearest" "$TCBENCH" report run --reference toy_no_nearest.json --out no_nearest
grep -qF "In the run but in no row of these tables (tables.md has them):" out.txt &&
    ! grep -qE "^- synth / quadruped_walk: .*oracle" out.txt || { echo "FAIL: cells without a row"; cat out.txt; exit 1; }

# A run whose cells name a preset other than `paper` says so above its
# tables, in the reference report, tables.md and tables.tex.
cp -r run runp
/usr/bin/python3 - <<'PY'
import json
p = "runp/cells/synth/quadruped_walk/nearest/seed_0.json"
c = json.load(open(p)); c["params"] = {"preset": "cpu"}; json.dump(c, open(p, "w"))
PY
expect 0 "**Presets**: nearest \`cpu\`. These are not the paper's training" "$TCBENCH" report runp --reference toy.json
"$TCBENCH" report runp --quiet
grep -qF "**Presets**: nearest \`cpu\`. These are not the paper's training" runp/report/tables.md || { echo "FAIL: tables.md"; exit 1; }
grep -qF "% presets: nearest \`cpu\` (not the paper's training)" runp/report/tables.tex || { echo "FAIL: tables.tex"; exit 1; }
/usr/bin/python3 - <<'PY'
import json
p = "runp/cells/synth/quadruped_walk/nearest/seed_0.json"
c = json.load(open(p)); c["params"] = {"preset": "paper"}; json.dump(c, open(p, "w"))
PY
expect 0 "**Presets**: nearest \`paper\`: the paper's training." "$TCBENCH" report runp --reference toy.json

# On 3 pairs no difference can be significant (Wilcoxon's smallest p with
# n = 3 is 0.25): the same flip is within the noise.
sed 's/"pairs": 30/"pairs": 3/; s/"output": "run"/"output": "run3", "splits_dir": "splits3"/' c.json > c3.json
"$TCBENCH" run c3.json --quiet 2> /dev/null
expect 0 "  - the paper has row nearest better than row oracle: flips (within noise)" \
    "$TCBENCH" report run3 --reference toy.json --resamples 1000

# Without a "reference" in the config: every table naming a cell of the run.
sed -i 's/"reference": { "source": "toy", "tables": \["B"\] },//' run/config.json
expect 0 "" "$TCBENCH" report run --reference toy.json --out elsewhere --quiet
[ ! -s out.txt ] && grep -qF "## Table A" elsewhere/reference_toy.md && grep -qF "## Table B" elsewhere/reference_toy.md

# Errors name what is wrong and write nothing.
rm -rf run/report
expect 2 "--reference iccv22: no such built-in reference" "$TCBENCH" report run --reference iccv22
expect 2 "no table of reference iccv21 names a cell of this run" "$TCBENCH" report run --reference iccv21
sed 's/"sl2": \[1, 1\]/"sl2": "high"/' toy.json > bad.json
expect 2 "bad.json: tables[0].rows[0].sl2: expected null or [mean, std]" "$TCBENCH" report run --reference bad.json
expect 2 "missing.json" "$TCBENCH" report run --reference missing.json
[ ! -e run/report ] || { echo "FAIL: a failed report wrote run/report"; ls run/report; exit 1; }
echo "reference report test passed"

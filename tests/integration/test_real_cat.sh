#!/usr/bin/env bash
# Real data: walking cat from ../shared/data (skipped when absent). Loads
# 35 frames × 1297 vertices, and on the common pairs oracle is perfect while
# nearest is not.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"

data="$TCB_SOURCE_DIR/../shared/data/anim"
if [ ! -d "$data/cat_walk" ]; then
  echo "skipped: $data/cat_walk is absent"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/config.json" <<JSON
{ "name": "cat", "output": "$tmp/run", "splits_dir": "$TCB_SOURCE_DIR/splits", "cache_dir": "$tmp/cache",
  "datasets": [ { "name": "anim", "source": "objdir", "root": "$data", "normalization": "first_frame",
                  "sequences": [ { "name": "cat_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
"$TCBENCH" run "$tmp/config.json" --quiet
/usr/bin/python3 - "$tmp/run" <<'PY'
import glob, json, sys
cells = {}
for p in glob.glob(sys.argv[1] + "/cells/**/*.json", recursive=True):
    c = json.load(open(p)); cells[c["method"]] = c
o, n = cells["oracle"]["summary"], cells["nearest"]["summary"]
assert o["n_pairs"] == 500 and n["n_pairs"] == 500
assert o["sl2"]["n"] == 500 * 1297, o["sl2"]["n"]     # every GT vertex of every pair
assert o["sl2"]["mean"] == 0 and o["rank"]["mean"] == 0 and o["auc"]["mean"] == 1
assert n["sl2"]["mean"] > 0 and n["rank"]["mean"] > 0 and n["auc"]["mean"] < 1
print("cat: nearest m_sL2 %.2f rank %.2f AUC %.2f" % (1e3 * n["sl2"]["mean"], 100 * n["rank"]["mean"], 100 * n["auc"]["mean"]))
PY

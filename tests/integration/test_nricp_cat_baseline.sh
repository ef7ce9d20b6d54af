#!/usr/bin/env bash
# Regression check of nrICP on walking cat (skipped when ../shared/data is
# absent): the fast strategies (propagate_simple, propagate_bijective) and the
# nearest floor must reproduce their rows of tests/baselines/nricp-cat.json,
# which holds all four strategies (the full run takes ~12 min; see the note
# in that config: configs/nricp-cat.json).
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"

if [ ! -d "$TCB_SOURCE_DIR/../shared/data/anim/cat_walk" ]; then
  echo "skipped: ../shared/data/anim/cat_walk is absent"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$TCB_SOURCE_DIR"   # relative data root and the committed splits

keep='["nearest", "nricp-simple", "nricp-bijective"]'
/usr/bin/python3 - "$tmp" "$keep" <<'PY'
import json, sys
tmp, keep = sys.argv[1], json.loads(sys.argv[2])
cfg = json.load(open("configs/nricp-cat.json"))
cfg["methods"] = [m for m in cfg["methods"] if m["name"] in keep]
cfg["cache_dir"] = tmp + "/cache"
json.dump(cfg, open(tmp + "/config.json", "w"))
base = json.load(open("tests/baselines/nricp-cat.json"))
base["rows"] = [r for r in base["rows"] if r["method"] in keep]
assert len(base["rows"]) == len(keep)
json.dump(base, open(tmp + "/baseline.json", "w"))
PY
"$TCBENCH" run "$tmp/config.json" --out "$tmp/run" --quiet
"$TCBENCH" check "$tmp/run" "$tmp/baseline.json"

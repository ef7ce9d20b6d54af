#!/usr/bin/env bash
# The default benchmark (configs/quick.json) reproduces the committed
# regression baseline: `tcbench check` exits 0, and oracle is perfect. The
# cc rows (a 400-iteration training) carry their own tolerances in the
# baseline: on one machine they repeat bit for bit, on another CPU the BLAS
# kernels round differently and the training amplifies it.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$TCB_SOURCE_DIR"   # the committed splits/ are reused, never rewritten

"$TCBENCH" run configs/quick.json --out "$tmp/run" --quiet
"$TCBENCH" check "$tmp/run" tests/baselines/quick.json

/usr/bin/python3 - "$tmp/run" <<'PY'
import glob, json, sys
cells = [json.load(open(p)) for p in glob.glob(sys.argv[1] + "/cells/**/*.json", recursive=True)]
assert len(cells) == 9, len(cells)
for c in cells:
    s = c["summary"]
    assert c["status"] == "ok", c["message"]
    assert s["n_pairs"] == 500
    if c["method"] == "oracle":
        assert s["sl2"]["mean"] == 0 and s["rank"]["mean"] == 0 and s["auc"]["mean"] == 1, s
    else:
        assert s["sl2"]["mean"] > 0 and s["auc"]["mean"] < 1, s
print("quick config: %d cells ok" % len(cells))
PY

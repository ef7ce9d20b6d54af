#!/usr/bin/env bash
# The clip protocol end to end (docs/protocol.md, "The clip protocol"): a
# tiny synthetic sequence (20 frames, raw coordinates) run with
# "protocol": ["pairs", "clips"] for oracle and nearest, then
#  - numpy recomputes Corr from the sequence's OBJ frames (written by
#    `tcbench datasets synth`, the same generator and seed): nearest's
#    transfer is the identity (its projection is the harness's), so its
#    points at clip frame t are frame 0's and err_t = mean_k |V_s,k - V_s+t,k|;
#    every err_t, each clip's corr (the mean over t = 1..16) and the
#    summary (n, mean, m2 over clips) must agree to 1e-12 relative, and each
#    clip's corr with DynoSurf's own computation (frame-0 nearest-point
#    matching by cKDTree, then frames 1-16) on the same points; oracle's
#    are 0 exactly, nearest's > 0; the report's Corr column shows them ×1e3;
#  - the clip split file: the starts as drawn again from the same seed
#    (deleted and redrawn: the same bytes), each clip inside the sequence;
#    a damaged file (a start whose clip runs past the end, starts out of
#    order, a wrong format) is refused with one line naming the file and key, exit 2;
#  - "protocol": "clips" alone: cells with no pairs ("-" under m_sL2) and Corr;
#  - a bad "protocol" value, a "clips" count without the clip protocol, and a
#    sequence shorter than a clip are refused with one line, exit 2.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

if ! /usr/bin/python3 -c "import numpy, scipy.spatial" 2>/dev/null; then
  echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

config() { # NAME PROTOCOL FRAMES [EXTRA EVALUATION KEYS]
  cat > "$1.json" <<JSON
{ "name": "$1", "output": "runs/$1", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 20, "pool_size": 2000, "protocol": $2 ${4:-} },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": $3, "normalization": "none",
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
}

config both '["pairs", "clips"]' 20 ', "clips": 3'
"$TCBENCH" run both.json --quiet 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" report runs/both > /dev/null
# compare pairs Corr over the clips: nearest's Corr against the oracle's 0;
# three differences can never reach p < 0.05 (at best 2^-2), and the
# verdict says so rather than "within noise".
"$TCBENCH" compare runs/both nearest oracle > compare.txt
grep -qF "Corr: paired over the 3 clips of the clip split" compare.txt &&
    grep -qE '^Corr ×1e3 +[0-9.]+ +0\.00 +[0-9.]+ +\[[0-9.]+, [0-9.]+\] +0\.25 +too few to test \(3\)$' compare.txt ||
    { echo "FAIL: compare's Corr"; cat compare.txt; exit 1; }
"$TCBENCH" datasets synth --out frames --frames 20 --sequence quadruped_walk > /dev/null
clips=splits/synth/quadruped_walk.clips.json
cp "$clips" clips.first

/usr/bin/python3 - <<'PY'
import glob, json, re
import numpy as np
from scipy.spatial import cKDTree

files = sorted(glob.glob("frames/quadruped_walk/*.obj"), key=lambda f: int(re.findall(r"\d+", f)[-1]))
V = np.array([[[float(x) for x in l.split()[1:4]] for l in open(f) if l.startswith("v ")] for f in files],
             dtype=np.float32).astype(np.float64)
assert V.shape[0] == 20, V.shape

split = json.load(open("splits/synth/quadruped_walk.clips.json"))
assert split["format"] == "tcbench-clips/1" and split["clip_frames"] == 17 and split["n_clips"] == 3, split
starts = split["starts"]
assert starts == sorted(set(starts)) and all(0 <= s and s + 16 < 20 for s in starts), starts

def cell(method):
    return json.load(open("runs/both/cells/synth/quadruped_walk/%s/seed_0.json" % method))

def close(a, b, what):
    assert abs(a - b) <= 1e-12 * max(abs(b), 1e-300), (what, a, b)

for method in ("oracle", "nearest"):
    c = cell(method)
    assert c["split"]["n_pairs"] == 20 and len(c["pairs"]) == 20, method
    cl = c["clips"]
    assert cl["clip_frames"] == 17 and cl["n_clips"] == 3 and cl["columns"] == ["start", "corr", "err"]
    assert [r[0] for r in cl["rows"]] == starts, (method, cl["rows"])
    corrs = []
    for s, corr, err in cl["rows"]:
        if method == "oracle":
            ref = np.zeros(16)
        else:  # the identity transfer: frame s's points where frame s+t's are
            ref = np.array([np.linalg.norm(V[s] - V[s + t], axis=1).mean() for t in range(1, 17)])
        assert len(err) == 16
        for t in range(16):
            close(err[t], ref[t], (method, s, t + 1))
        close(corr, ref.mean(), (method, s))
        corrs.append(ref.mean())
        # DynoSurf's own computation (evaluation/utils.py, eval_correspondences_mesh) on
        # the same inputs: the predicted vertices of frames 0-16 (frame 0: the GT one's,
        # as both methods have it) matched at frame 0 to the nearest GT point; equal.
        gt = [V[s + t] for t in range(17)]
        pred = [V[s]] + [V[s] if method == "nearest" else V[s + t] for t in range(1, 17)]
        ind = cKDTree(gt[0]).query(pred[0])[1]
        theirs = np.mean([np.linalg.norm(pred[t] - gt[t][ind], axis=-1).mean() for t in range(1, 17)])
        close(corr, theirs, (method, s, "DynoSurf's"))
    corrs = np.array(corrs)
    summ = c["summary"]["corr"]
    assert summ["n"] == 3, summ
    close(summ["mean"], corrs.mean(), (method, "mean"))
    assert abs(summ["m2"] - ((corrs - corrs.mean()) ** 2).sum()) <= 1e-12 * max(corrs.mean() ** 2, 1e-300), summ
    if method == "oracle":
        assert summ["mean"] == 0.0
    else:
        assert summ["mean"] > 1e-3, summ
        want = "%.2f ± %.2f" % (corrs.mean() * 1e3, corrs.std() * 1e3)
        md = open("runs/both/report/tables.md").read()
        assert "Corr ↓" in md and want in md, want
print("Corr agrees with numpy; oracle 0, nearest %.6f" % cell("nearest")["summary"]["corr"]["mean"])
PY

# The split file is drawn again from the seed: the same bytes.
rm "$clips"
"$TCBENCH" run both.json --quiet --force 2> run.log || { cat run.log; exit 1; }
cmp "$clips" clips.first

# A damaged clip split file: one line naming the file and key, exit 2.
damage() { # PYTHON-EXPRESSION-ON-d KEY
  /usr/bin/python3 -c "import json; d = json.load(open('clips.first')); $1; json.dump(d, open('$clips', 'w'))"
  expect 2 "$clips" "$TCBENCH" run both.json --quiet --force
  grep -qF "$2" err.txt || { echo "FAIL: no '$2' in:"; cat err.txt; exit 1; }
  [ "$(wc -l < err.txt)" -eq 1 ] || { echo "FAIL: not one line:"; cat err.txt; exit 1; }
}
damage 'd["starts"][-1] = 4' 'starts[2]: the clip of 17 frames from 4 ends past frame 19'
damage 'd["starts"] = d["starts"][::-1]' 'starts[1]:'
damage 'd["format"] = "tcbench-clips/9"' '.format: expected'
damage 'd["n_clips"] = 2' 'n_clips'
cp clips.first "$clips"

# Clips alone: no pairs, Corr only.
config only '"clips"' 20 ', "clips": 3'
"$TCBENCH" run only.json --quiet 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" report runs/only > /dev/null
/usr/bin/python3 - <<'PY'
import json
a = json.load(open("runs/both/cells/synth/quadruped_walk/nearest/seed_0.json"))
b = json.load(open("runs/only/cells/synth/quadruped_walk/nearest/seed_0.json"))
assert b["split"]["n_pairs"] == 0 and b["pairs"] == [] and b["summary"]["n_pairs"] == 0, b["split"]
assert b["clips"]["rows"] == a["clips"]["rows"], "clips alone must score what clips with pairs do"
# clips alone, no surfaces: the table has the Corr column only (a column no
# method of the dataset has is left out)
lines = open("runs/only/report/tables.md").read().splitlines()
head = [l for l in lines if l.startswith("| method |")][0]
row = [l for l in lines if l.startswith("| nearest |")][0]
assert [c.strip() for c in head.split("|")[1:-1]] == ["method", "Corr ↓"], head
assert row.split("|")[2].strip() not in ("", "-"), row
PY

# Refused configs: one line naming the key, exit 2.
config bad '"triplets"' 20
expect 2 'bad.json: evaluation.protocol: expected "pairs", "clips" or a list of them' "$TCBENCH" run bad.json
config bad '["pairs", "pairs"]' 20
expect 2 'bad.json: evaluation.protocol: expected' "$TCBENCH" run bad.json
config bad '"pairs"' 20 ', "clips": 3'
expect 2 'bad.json: evaluation.clips: only with the clip protocol' "$TCBENCH" run bad.json
rm -rf splits
config short '"clips"' 12
expect 2 'clips synth/quadruped_walk: no 17 consecutive frames in one block' "$TCBENCH" run short.json
echo "ok"

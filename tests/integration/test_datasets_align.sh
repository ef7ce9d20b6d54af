#!/usr/bin/env bash
# Rotation alignment end to end: `tcbench datasets align` recovers the yaws
# a sequence was turned by (written as JSON, plotted as PNG), a config with
# "align_rotation": true runs on them, and bad input is a clear error.
set -euo pipefail
: "${TCBENCH:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# A synthetic walk whose frame f is turned about y by -steps[f] x 3 degrees.
"$TCBENCH" datasets synth --out raw --sequence quadruped_walk --frames 6 2> /dev/null
/usr/bin/python3 - <<'PY'
import glob, math, os
steps = [0, 9, 40, 41, 110, 3]
os.makedirs("turned/walk")
for f, path in enumerate(sorted(glob.glob("raw/quadruped_walk/mesh_*.obj"))):
    t = -steps[f] * 2 * math.pi / 120
    c, s = math.cos(t), math.sin(t)
    out = []
    for line in open(path):
        if line.startswith("v "):
            x, y, z = map(float, line.split()[1:4])
            line = "v %.9g %.9g %.9g\n" % (c * x + s * z, y, -s * x + c * z)
        out.append(line)
    open("turned/walk/" + os.path.basename(path), "w").writelines(out)
PY

expect 0 "wrote rot.json and yaw.png" "$TCBENCH" datasets align turned/walk --out rot.json --plot yaw.png --samples 500
/usr/bin/python3 - <<'PY'
import json
r = json.load(open("rot.json"))
assert r["format"] == "tcbench-rotations/1" and r["steps"] == 120 and r["samples"] == 500, r
got = [f["step"] for f in r["frames"]]
assert got == [0, 9, 40, 41, 110, 3], got
assert [f["yaw_degrees"] for f in r["frames"]][:2] == [0, 27], r["frames"][:2]
assert r["frames"][0]["file"] == "mesh_0000.obj" and r["frames"][0]["chamfer"] == 0
assert all(f["chamfer"] > 0 for f in r["frames"][1:])
PY
head -c 8 yaw.png | od -c | grep -q "P   N   G" || { echo "FAIL: yaw.png is not a PNG"; exit 1; }

# The same alignment inside a run: nearest on the aligned sequence beats it
# on the turned one (the frames face alike again).
config() { # NAME ALIGN
    cat > "$1.json" <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "cache", "threads": 1,
  "evaluation": { "pairs": 20, "pool_size": 2000 },
  "datasets": [ { "name": "turned", "source": "objdir", "root": "turned", "normalization": "per_frame",
                  "align_rotation": $2, "sequences": [ { "name": "walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" } ] }
JSON
}
config plain false
config aligned true
for c in plain aligned; do "$TCBENCH" run $c.json --quiet > /dev/null 2>&1; done
/usr/bin/python3 - <<'PY'
import json
sl2 = {c: json.load(open("runs/%s/cells/turned/walk/nearest/seed_0.json" % c))["summary"]["sl2"]["mean"]
       for c in ("plain", "aligned")}
assert sl2["aligned"] < 0.5 * sl2["plain"], sl2
PY

# ---- bad input
expect 2 "datasets align: --out FILE is required" "$TCBENCH" datasets align turned/walk
expect 2 "datasets align: missing DIR" "$TCBENCH" datasets align --out x.json
expect 2 "datasets: --samples: expected an integer from 1 to 10000000, got '0'" "$TCBENCH" datasets align turned/walk --out x.json --samples 0
expect 2 "datasets: --plot applies to 'datasets align' only" "$TCBENCH" datasets list --plot p.png
expect 2 "nowhere: cannot open directory" "$TCBENCH" datasets align nowhere --out x.json
[ ! -e x.json ] || { echo "FAIL: x.json written despite errors"; exit 1; }
sed 's/"align_rotation": true/"align_rotation": "yes"/' aligned.json > bad.json
expect 2 "align_rotation" "$TCBENCH" run bad.json --quiet
echo "datasets align: ok"

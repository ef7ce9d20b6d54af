#!/usr/bin/env bash
# `tcbench frames` draws a few frames of a fitted cell. Checked here: for an
# atlas method (mca, preset tiny) the per-frame OBJs parse, carry a vt per
# vertex inside [0,1] and inside one chart's cell of the texture, index
# valid vertices, name checker.mtl, which names checker.png; the PNGs have
# the sizes the layout implies (the strip one panel per frame from one
# camera) and are not blank; for `nearest` the transfer strip and PLYs,
# whose source frame carries the body-place colours and whose other frames
# only colours of those. Bad requests fail with the reason and write nothing.
set -euo pipefail
: "${TCBENCH:?}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
cat > frames.json <<'JSON'
{ "name": "frames", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 1000, "input_points": 300, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "nearest" },
               { "name": "mca", "params": { "preset": "tiny", "iterations": 60 } } ] }
JSON
"$TCBENCH" run frames.json --out run --quiet 2> run.log || { cat run.log; exit 1; }

"$TCBENCH" frames run mca --frames 0,5,11 --out atlas --quiet > atlas.txt 2> atlas.log
"$TCBENCH" frames run nearest --count 4 --quiet > nearest.txt 2> nearest.log
"$TCBENCH" frames run mca --frames 0,5,11 --out again --quiet > /dev/null
cmp atlas/frame_5.obj again/frame_5.obj || { echo "the surface of frame 5 is not reproducible"; exit 1; }
grep -q "textured surface, frames 0, 5, 11" atlas.txt || { cat atlas.txt; exit 1; }
grep -q "transfer, frames 0, 4, 7, 11" nearest.txt || { cat nearest.txt; exit 1; }
# 60 iterations of 4 patches leave slivers (1 % of their share of the body
# or less): said on stderr, also under --quiet, in one line for the frames,
# and not on stdout, which has the account only
grep -q "^warning: mca seed 0: the surface collapsed: [1-4] of 4 patches in frame 0,.* in frame 11 (a patch is collapsed when its area is under 5 % of its share" atlas.log ||
    { echo "FAIL: the collapsed surface is not said"; cat atlas.log; exit 1; }
[ "$(grep -c collapsed atlas.log)" -eq 1 ] && ! grep -q collapsed atlas.txt nearest.txt nearest.log ||
    { echo "FAIL: collapse said more than once, on stdout or for a transfer"; exit 1; }
nearest_dir=$(sed -n 's/^files: \(.*\)\/$/\1/p' nearest.log)
[ "$nearest_dir" = run/frames/synth/quadruped_walk/nearest/seed_0 ] || { echo "directory '$nearest_dir'"; exit 1; }

/usr/bin/python3 - atlas "$nearest_dir" <<'PY'
import struct, sys, zlib
atlas, nearest = sys.argv[1:3]
CELL, PANEL, HEIGHT = 256, 360, 34 + 360 + 46  # views/checker.h, views/render.c

def png(path):
    """(width, height, rows of RGB(A) bytes) of an 8-bit PNG as cairo writes it."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, w = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (path, depth, colour)
            bpp = 3 if colour == 2 else 4
        if kind == b"IDAT": idat += body
        pos += 12 + n
    raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
    stride = w * bpp
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b, c = prev[x], prev[x - bpp] if x >= bpp else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line)); prev = line
    return w, h, bpp, rows

def colours(path):
    w, h, bpp, rows = png(path)
    return w, h, {r[x:x + 3] for r in rows for x in range(0, w * bpp, bpp)}

def obj(path):
    v, vt, faces, mtllib = [], [], [], None
    for line in open(path):
        t = line.split()
        if not t or t[0] == "#": continue
        if t[0] == "v": v.append(tuple(map(float, t[1:4])))
        elif t[0] == "vt": vt.append(tuple(map(float, t[1:3])))
        elif t[0] == "f": faces.append([tuple(int(i) for i in c.split("/")) for c in t[1:]])
        elif t[0] == "mtllib": mtllib = t[1]
    return v, vt, faces, mtllib

# atlas: tiny has 4 patches of 25 x 25 vertices, 2 x 24 x 24 faces each
meshes = {f: obj(f"{atlas}/frame_{f}.obj") for f in (0, 5, 11)}
for f, (v, vt, faces, mtllib) in meshes.items():
    assert mtllib == "checker.mtl", (f, mtllib)
    assert len(v) == len(vt) == 4 * 25 * 25 and len(faces) == 4 * 2 * 24 * 24, (f, len(v), len(vt), len(faces))
    assert all(0 <= a <= 1 and 0 <= b <= 1 for a, b in vt), f
    for face in faces:
        assert len(face) == 3 and all(1 <= i <= len(v) and i == t for i, t in face), (f, face)
        cells = {(int(vt[i - 1][0] * 2), int((1 - vt[i - 1][1]) * 2)) for i, _ in face}
        assert len(cells) == 1, (f, face)  # a face stays in its chart's cell of the 2 x 2 grid
    assert vt == meshes[0][1] and faces == meshes[0][2], f  # one texture for all frames
assert meshes[0][0] != meshes[5][0], "frames 0 and 5 decoded to the same surface"
mtl = open(f"{atlas}/checker.mtl").read()
assert "newmtl checker" in mtl and "map_Kd checker.png" in mtl, mtl
w, h, cols = colours(f"{atlas}/checker.png")
assert (w, h) == (2 * CELL, 2 * CELL) and len(cols) >= 8, (w, h, len(cols))
w, h, cols = colours(f"{atlas}/strip.png")
assert (w, h) == (3 * PANEL, HEIGHT), (w, h)  # one panel per frame, one camera
assert len(cols) > 20, "the strip looks blank"

# nearest: source frame in body-place colours, the others only in those colours
def ply_colours(path):
    lines = open(path).read().split("\n")
    end = lines.index("end_header")
    nv = next(int(l.split()[2]) for l in lines if l.startswith("element vertex "))
    return [tuple(map(int, l.split()[3:6])) for l in lines[end + 1:end + 1 + nv]]
src = ply_colours(f"{nearest}/frame_0.ply")
assert len(set(src)) > 100, "the source frame is not coloured by place"
for f in (4, 7, 11):
    got = ply_colours(f"{nearest}/frame_{f}.ply")
    assert len(got) == len(src) and set(got) <= set(src) and got != src, f
w, h, cols = colours(f"{nearest}/strip.png")
assert (w, h) == (4 * PANEL, HEIGHT) and len(cols) > 20, (w, h, len(cols))
print("frames files check out")
PY

# bad requests: the reason, a non-zero exit, nothing written
expect_fail() { # expected-message command...
    local want=$1; shift
    if "$@" > out.txt 2> err.txt; then echo "succeeded: $*"; exit 1; fi
    grep -qF -- "$want" err.txt || { echo "no '$want' in:"; cat err.txt; exit 1; }
}
expect_fail "no method labelled 'dsr'" "$TCBENCH" frames run dsr --out bad --quiet
expect_fail "--frames: frame 12 is outside quadruped_walk (frames 0 to 11)" "$TCBENCH" frames run mca --frames 0,12 --out bad --quiet
expect_fail "--frames: frame 3 is named twice" "$TCBENCH" frames run nearest --frames 3,3 --out bad --quiet
expect_fail "--count 13: quadruped_walk has 12 frames" "$TCBENCH" frames run nearest --count 13 --out bad --quiet
expect_fail "method 'nearest' (nearest) has no textured surface" "$TCBENCH" frames run nearest --style texture --out bad --quiet
expect_fail "--frames: expected up to 16 frame numbers" "$TCBENCH" frames run mca --frames 0,x --out bad
expect_fail "--style: expected auto, texture or transfer" "$TCBENCH" frames run mca --style pretty --out bad
expect_fail "--frames and --count exclude each other" "$TCBENCH" frames run mca --frames 0 --count 2 --out bad
expect_fail "is not a run directory" "$TCBENCH" frames nowhere mca --out bad --quiet
rm run/work/synth/quadruped_walk/mca/seed_0/model.ckpt
expect_fail "the cell has no fitted model yet" "$TCBENCH" frames run mca --out bad --quiet
test ! -e bad || { echo "a failed frames left 'bad' behind"; exit 1; }

# one frame: the source alone, in body-place colours
"$TCBENCH" frames run nearest --style transfer --frames 2 --out one --quiet > /dev/null
test -s one/strip.png && test -s one/frame_2.ply && test ! -e one/checker.png
echo "frames test passed"

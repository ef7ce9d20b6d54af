#!/usr/bin/env bash
# tcbench score: predictions written with numpy score exactly as the methods
# whose output they repeat (oracle: ids as int32 and big-endian int64, points
# as Fortran-ordered float64; nearest: points as float32 and as float64 in a
# version 3.0 file, ids computed in numpy as uint16, ids and points mixed in
# one directory; one .npz, stored by np.savez and deflated by
# np.savez_compressed), bit for bit in summary and pairs; report and check take
# the scored rows; a missing split is drawn as run draws it; a configured
# label, an existing cell and every kind of bad file or archive are refused
# with a message naming the file (and the member), and no cell is written.
# Skipped when /usr/bin/python3 has no numpy.
set -euo pipefail
: "${TCBENCH:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

if ! /usr/bin/python3 -c "import numpy" 2>/dev/null; then
    echo "skipped: /usr/bin/python3 cannot import numpy (scripts/setup.sh installs it)"
    exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# "normalization": "none": the frames tcbench scores on are the OBJ files'
# coordinates, so numpy can repeat nearest's points exactly.
cat > tiny.json <<'JSON'
{ "name": "tiny", "output": "runs/tiny", "splits_dir": "splits", "cache_dir": "",
  "evaluation": { "pairs": 20, "pool_size": 2000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12, "normalization": "none",
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
"$TCBENCH" run tiny.json --quiet 2> run.log || { cat run.log; exit 1; }
"$TCBENCH" datasets synth --out objs --sequence quadruped_walk --frames 12 2> /dev/null
cells=runs/tiny/cells/synth/quadruped_walk

/usr/bin/python3 - <<'PY'
import json, os
import numpy as np
from numpy.lib import format as npf

pairs = json.load(open("splits/synth/quadruped_walk.json"))["pairs"]
def frame(f):
    with open("objs/quadruped_walk/mesh_%04d.obj" % f) as obj:
        return np.array([l.split()[1:4] for l in obj if l.startswith("v ")], dtype=np.float32)
def write(d, k, a, version=None):
    os.makedirs(d, exist_ok=True)
    with open("%s/%d.npy" % (d, k), "wb") as f:
        npf.write_array(f, a, version=version)
for k, (i, j) in enumerate(pairs):
    K = len(frame(i))
    write("oracle_i32", k, np.arange(K, dtype="<i4"))
    write("oracle_i64_be", k, np.arange(K, dtype=">i8"))
    write("oracle_f8_F", k, np.asfortranarray(frame(j).astype("<f8")))
    write("nearest_f4", k, frame(i))
    write("nearest_f8_v3", k, frame(i).astype("<f8"), version=(3, 0))
    a, b = frame(i).astype(np.float64), frame(j).astype(np.float64)
    ids = ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1).argmin(1)
    write("nearest_u2", k, ids.astype("<u2"))
    write("nearest_mixed", k, ids.astype("<i8") if k % 2 else frame(i))
PY

score() { "$TCBENCH" score tiny.json --dataset synth --sequence quadruped_walk "$@"; }
for d in oracle_i32 oracle_i64_be oracle_f8_F nearest_f4 nearest_f8_v3 nearest_u2 nearest_mixed; do
    expect 0 "synth/quadruped_walk $d: 20 pairs" score --pred "$d" --name "$d"
    grep -qF "cell: $cells/$d/seed_0.json" err.txt || { cat err.txt; exit 1; }
done
expect 0 "oracle_files: 20 pairs, m_sL2 0.00" score --pred oracle_i32 --name oracle_files --seed 3

/usr/bin/python3 - <<'PY'
import json
cells = "runs/tiny/cells/synth/quadruped_walk/"
def cell(m, seed=0):
    return json.load(open(cells + "%s/seed_%d.json" % (m, seed)))
for method, scored in [("oracle", ["oracle_i32", "oracle_i64_be", "oracle_f8_F"]),
                       ("nearest", ["nearest_f4", "nearest_f8_v3", "nearest_u2", "nearest_mixed"])]:
    ref = cell(method)
    for s in scored:
        c = cell(s)
        assert c["summary"] == ref["summary"], (s, c["summary"]["sl2"], ref["summary"]["sl2"])
        assert c["pairs"] == ref["pairs"], s
        cols = c["pair_columns"]
        assert c["summary"]["cd"] is None and all(p[cols.index("cd")] is None for p in c["pairs"]), s
        # the geodesic error comes the same way (equal to the method's above)
        assert c["summary"]["geo_auc"]["n"] == 20 and c["summary"]["geo"]["n"] == c["summary"]["sl2"]["n"], s
        assert (c["summary"]["geo"]["mean"] == 0) == (method == "oracle"), s
        for key in ("format", "dataset", "sequence", "role", "split", "status"):
            assert c[key] == ref[key], (s, key, c[key], ref[key])
        assert (c["method"], c["method_impl"], c["params"], c["message"], c["seed"]) == \
            (s, "scored", {"pred_dir": s}, "scored from files", 0), s
        assert c["timings"]["fit_s"] == 0, c["timings"]
assert cell("oracle_files", 3)["seed"] == 3 and cell("oracle_files", 3)["summary"] == cell("oracle")["summary"]
PY

# ---- report and check take the scored rows like any other
expect 0 "" "$TCBENCH" report runs/tiny --quiet
# (its MEAN row, over one test sequence: tied for best, ≈, like every other;
# no CD, Corr or reconstruction columns: no clips were scored, files hold
# no surfaces)
grep -qE '^\| nearest_u2 \| 11\.[0-9]+ ± [0-9.]+ ≈ \| .* \| [0-9.]+ ± [0-9.]+ ≈ \| [0-9.]+ ± [0-9.]+ ≈ \|$' runs/tiny/report/tables.md ||
    { echo "FAIL: no nearest_u2 row"; cat runs/tiny/report/tables.md; exit 1; }
expect 0 "baseline written" "$TCBENCH" check runs/tiny base.json --update
expect 0 "synth/quadruped_walk/nearest_f4" "$TCBENCH" check runs/tiny base.json
/usr/bin/python3 - <<'PY'
import json
rows = {r["method"]: r for r in json.load(open("base.json"))["rows"]}
for method, scored in [("oracle", "oracle_i32"), ("nearest", "nearest_mixed")]:
    a, b = dict(rows[method]), dict(rows[scored])
    a.pop("method"), b.pop("method")
    assert a == b, (a, b)
PY

# ---- a split not there yet is drawn as run draws it
sed 's/"splits_dir": "splits"/"splits_dir": "splits2"/' tiny.json > fresh.json
expect 0 "" "$TCBENCH" score fresh.json --dataset synth --sequence quadruped_walk --pred nearest_f4 --name x --out runs/fresh
cmp splits/synth/quadruped_walk.json splits2/synth/quadruped_walk.json
/usr/bin/python3 - <<'PY'
import json
a = json.load(open("runs/tiny/cells/synth/quadruped_walk/nearest/seed_0.json"))
b = json.load(open("runs/fresh/cells/synth/quadruped_walk/x/seed_0.json"))
assert a["summary"] == b["summary"] and a["pairs"] == b["pairs"]
PY

# ---- labels and reruns
expect 2 "--name: tiny.json has a method labelled 'nearest' (its cells are tcbench run's)" \
    score --pred nearest_f4 --name nearest
expect 2 "$cells/nearest_f4/seed_0.json exists: --force replaces it" score --pred nearest_f4 --name nearest_f4
expect 0 "oracle_i32: 20 pairs, m_sL2 11.56" score --pred nearest_f4 --name oracle_i32 --force
expect 2 "invalid method name \"a/b\"" score --pred nearest_f4 --name a/b
expect 2 "score: --pred DIR|FILE.npz is required" score --name y
expect 2 "--dataset: tiny.json has no dataset named 'nope'" \
    "$TCBENCH" score tiny.json --dataset nope --sequence quadruped_walk --pred nearest_f4 --name y
expect 2 "--sequence: dataset synth of tiny.json has no sequence named 'nope'" \
    "$TCBENCH" score tiny.json --dataset synth --sequence nope --pred nearest_f4 --name y
expect 2 "nowhere: no such file or directory (a directory of <k>.npy or an .npz)" score --pred nowhere --name y

# ---- bad prediction files: an error naming the file, no cell
# bad CASE PYTHON: a copy of oracle_i32 as bad_CASE, changed by PYTHON
# (run with np, K, d = the directory).
bad() {
    rm -rf "bad_$1"
    cp -r oracle_i32 "bad_$1"
    /usr/bin/python3 -c "import numpy as np, os; d = 'bad_$1'; K = 2688; $2"
}
bad missing "os.remove(d + '/7.npy')"
bad surplus "np.save(d + '/20.npy', np.arange(K))"
bad k "np.save(d + '/3.npy', np.arange(K - 1))"
bad float_ids "np.save(d + '/3.npy', np.arange(K, dtype=np.float64))"
bad bool_ids "np.save(d + '/3.npy', np.ones(K, dtype=bool))"
bad int_points "np.save(d + '/3.npy', np.zeros((K, 3), dtype=np.int32))"
bad shape "np.save(d + '/3.npy', np.zeros((K, 2), dtype=np.float32))"
bad shape3 "np.save(d + '/3.npy', np.zeros((K, 3, 1), dtype=np.float32))"
bad range "a = np.arange(K); a[5] = K; np.save(d + '/12.npy', a)"
bad negative "a = np.arange(K); a[9] = -1; np.save(d + '/12.npy', a)"
bad nan "p = np.zeros((K, 3), dtype=np.float32); p[11, 1] = np.nan; np.save(d + '/19.npy', p)"
bad inf "p = np.zeros((K, 3)); p[0, 2] = -np.inf; np.save(d + '/19.npy', p)"
bad huge "p = np.zeros((K, 3)); p[4, 0] = 1e30; np.save(d + '/19.npy', p)"
bad truncated "b = open(d + '/15.npy', 'rb').read(); open(d + '/15.npy', 'wb').write(b[:-100])"
bad text "open(d + '/15.npy', 'w').write('0 1 2 3\n')"
# refused SUFFIX: for each "CASE TEXT" line of stdin, scoring bad_CASE<SUFFIX>
# exits 2 saying TEXT and writes no cell.
refused() {
    while read -r case text; do
        expect 2 "$text" score --pred "bad_$case$1" --name bad
        [ ! -e "$cells/bad" ] || { echo "FAIL: bad_$case$1: a cell was written"; ls -R "$cells/bad"; exit 1; }
    done
}
refused "" <<'CASES'
missing bad_missing/7.npy: no such file (one file per pair of splits/synth/quadruped_walk.json: 0.npy to 19.npy)
surplus bad_surplus/20.npy: splits/synth/quadruped_walk.json has only 20 pairs (0.npy to 19.npy)
k bad_k/3.npy: shape (2687,): expected (2688,) vertex ids or (2688, 3) points
float_ids bad_float_ids/3.npy: dtype <f8: vertex ids (shape (2688,)) must be integers (floats are not rounded to ids)
bool_ids bad_bool_ids/3.npy: dtype |b1: vertex ids (shape (2688,)) must be integers
int_points bad_int_points/3.npy: dtype <i4: points (shape (2688, 3)) must be float32 or float64
shape bad_shape/3.npy: shape (2688, 2): expected (2688,) vertex ids or (2688, 3) points
shape3 bad_shape3/3.npy: shape (2688, 3, 1): expected
range bad_range/12.npy: element 5: vertex id 2688 out of range [0, 2688)
negative bad_negative/12.npy: element 9: vertex id -1 out of range [0, 2688)
nan bad_nan/19.npy: point 11, coordinate 1: NaN
inf bad_inf/19.npy: point 0, coordinate 2: infinite
huge bad_huge/19.npy: point 4, coordinate 0: beyond ±1e18
truncated bad_truncated/15.npy: truncated: shape (2688,) of <i4 needs 10752 bytes of data, the file has 10652
text bad_text/15.npy: not a .npy file
CASES
# ---- one results file: an .npz of members <k>.npy, stored or deflated
/usr/bin/python3 - <<'PY'
import glob, zipfile
import numpy as np
def arrays(d):
    return {str(k): np.load(f"{d}/{k}.npy") for k in range(20)}
np.savez("oracle.npz", **arrays("oracle_i32"))
np.savez_compressed("nearest.npz", **arrays("nearest_mixed"))
# a zip tool's archive of the directory: deflated, members in another order, a comment
with zipfile.ZipFile("zipped.npz", "w", zipfile.ZIP_DEFLATED) as z:
    for k in reversed(range(20)):
        z.write(f"nearest_f4/{k}.npy", f"{k}.npy")
    z.comment = b"made by zip"
PY
expect 0 "synth/quadruped_walk npz_oracle: 20 pairs, m_sL2 0.00" score --pred oracle.npz --name npz_oracle
expect 0 "synth/quadruped_walk npz_nearest: 20 pairs, m_sL2 11." score --pred nearest.npz --name npz_nearest
expect 0 "synth/quadruped_walk npz_zipped: 20 pairs, m_sL2 11." score --pred zipped.npz --name npz_zipped
/usr/bin/python3 - <<'PY'
import json
cells = "runs/tiny/cells/synth/quadruped_walk/"
def cell(m):
    return json.load(open(cells + "%s/seed_0.json" % m))
for method, scored, path in [("oracle", "npz_oracle", "oracle.npz"), ("nearest", "npz_nearest", "nearest.npz"),
                             ("nearest", "npz_zipped", "zipped.npz")]:
    c, ref = cell(scored), cell(method)
    assert c["summary"] == ref["summary"] and c["pairs"] == ref["pairs"], scored
    assert (c["params"], c["message"]) == ({"pred_file": path}, "scored from files"), (c["params"], c["message"])
PY

# bad_npz CASE PYTHON: oracle.npz's arrays (a = {name: array}) written as
# bad_CASE.npz by PYTHON (np, zipfile and p, the path, at hand).
bad_npz() {
    /usr/bin/python3 -W ignore::UserWarning -c "
import numpy as np, zipfile
a = dict(np.load('oracle.npz')); p = 'bad_$1.npz'
$2"
}
bad_npz arr "np.savez(p, *[a[str(k)] for k in range(20)])"
bad_npz missing "del a['7']; np.savez(p, **a)"
bad_npz surplus "a['20'] = a['0']; np.savez(p, **a)"
bad_npz leading_zero "a['07'] = a.pop('7'); np.savez(p, **a)"
bad_npz other "np.savez(p, notes=np.zeros(1), **a)"
bad_npz twice "np.savez(p, **a); z = zipfile.ZipFile(p, 'a'); z.writestr('3.npy', b'x'); z.close()"
bad_npz shape "a['3'] = a['3'][:-1]; np.savez(p, **a)"
bad_npz not_npy "np.savez(p, **a); z = zipfile.ZipFile(p); m = {i.filename: z.read(i) for i in z.infolist()}; z.close(); m['5.npy'] = b'0 1 2'; z = zipfile.ZipFile(p, 'w'); [z.writestr(k, v) for k, v in m.items()]; z.close()"
bad_npz bzip2 "z = zipfile.ZipFile(p, 'w', zipfile.ZIP_BZIP2); [z.writestr(k + '.npy', v.tobytes()) for k, v in a.items()]; z.close()"
bad_npz crc "np.savez(p, **a); b = bytearray(open(p, 'rb').read()); i = b.index(b'NUMPY'); b[i + 200] ^= 1; open(p, 'wb').write(b)"
bad_npz inflate "np.savez_compressed(p, **a); b = bytearray(open(p, 'rb').read()); i = b.index(b'PK\\x03\\x04'); b[i + 60:i + 80] = bytes(20); open(p, 'wb').write(b)"
bad_npz truncated "np.savez(p, **a); b = open(p, 'rb').read(); open(p, 'wb').write(b[:len(b) // 2])"
bad_npz text "open(p, 'w').write('0 1 2 3\\n')"
refused .npz <<'CASES'
arr bad_arr.npz: member arr_0.npy: members are named by the pair index (0.npy to 19.npy): np.savez(path, **{str(k): a for k, a in enumerate(arrays)}), not np.savez(path, *arrays)
missing bad_missing.npz: no member 7.npy (one per pair of splits/synth/quadruped_walk.json: 0.npy to 19.npy)
surplus bad_surplus.npz: member 20.npy: not a pair of splits/synth/quadruped_walk.json (0.npy to 19.npy): predictions for another split?
leading_zero bad_leading_zero.npz: member 07.npy: not a pair of splits/synth/quadruped_walk.json
other bad_other.npz: member notes.npy: not a pair of splits/synth/quadruped_walk.json
twice bad_twice.npz: member 3.npy appears twice
shape bad_shape.npz: 3.npy: shape (2687,): expected (2688,) vertex ids or (2688, 3) points
not_npy bad_not_npy.npz: 5.npy: not a .npy file
bzip2 bad_bzip2.npz: 0.npy: ZIP compression method 12 (np.savez stores, np.savez_compressed deflates: 0 or 8)
crc bad_crc.npz: 0.npy: CRC-32 mismatch (a damaged archive)
inflate bad_inflate.npz: 0.npy: cannot inflate
truncated bad_truncated.npz: not a ZIP archive (no end record): an .npz is what np.savez writes
text bad_text.npz: not a ZIP archive (no end record)
CASES
echo "score test passed"

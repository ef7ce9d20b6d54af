#!/usr/bin/env bash
# Adding a baseline in C as a new user does it (docs/adding-a-method.md,
# sections 3 and 4, by their own commands): tcbench installed into a
# prefix, a plug-in built against the installed headers and library, the
# INSTALLED binary running a two-sequence config. Then each way a new
# method breaks, planted in turn, gets the behaviour a user expects:
#   - a transfer with one huge point, with NaN, with vertex ids written as
#     coordinates: that cell fails naming pair and vertex, the run goes on,
#     the other cells are untouched, and a rerun after the fix computes
#     exactly the failed cell;
#   - the plug-in rebuilt with other code: its cells are refused like
#     changed params, naming the fix; `cells` says "(other settings)";
#     `inspect` refuses to recompute a pair with the other build;
#     --force --only recomputes them, and the cell records the new build;
#   - the same file by --plugin and the config's "plugins": loaded once; a
#     different file with the same method name: refused naming both files;
#   - a table without transfer, a table of a future ABI: refused, naming
#     the missing function, and the headers to rebuild against.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# ---- section 3: install, build the plug-in against the installed tcbench
prefix=$tmp/prefix
cmake --install "$TCB_BUILD_DIR" --prefix "$prefix" >/dev/null
tcbench=$prefix/bin/tcbench
# The installed binary finds the installed library by itself.
expect 0 "tcbench " env -u LD_LIBRARY_PATH "$tcbench" version
libdir=$(dirname "$(find "$prefix" -name 'libtcbench.so' | head -n1)")
# A plug-in of a sanitized tcbench needs the sanitizer runtime too.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)

# The plug-in (centroid_plugin.c: nearest after aligning the frames'
# centroids, ~60 lines); CENTROID_FAULT breaks its transfer without a
# rebuild, so that a rerun without it is the fix.
cp "$TCB_SOURCE_DIR/tests/integration/centroid_plugin.c" centroid.c
build() { # build OUT [-DNAME...]: the plug-in, as docs/adding-a-method.md builds it
    local out=$1
    shift
    "$CC" -std=c11 -O2 -shared -fPIC $sanitize "$@" -I"$prefix/include" centroid.c \
        -L"$libdir" -ltcbench -lcjson -lm -o "$out"
}
build libcentroid.so

# ---- section 4: list it, and run a config that lists it
expect 0 "centroid" "$tcbench" --plugin ./libcentroid.so methods
cat > mine.json <<'JSON'
{ "name": "mine", "output": "runs/mine", "splits_dir": "splits", "cache_dir": "",
  "plugins": ["./libcentroid.so"],
  "evaluation": { "pairs": 12, "pool_size": 1000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 10,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" },
                                 { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" }, { "name": "centroid" } ] }
JSON
expect 0 "cells: 4 in all, 4 computed, 0 already done, 0 failed" "$tcbench" run mine.json --quiet
cells=runs/mine/cells/synth
cell_sums() { (cd "$cells" && find . -name '*.json' | sort | xargs sha256sum); }
cell_sums > before.txt
cp -r runs/mine first
/usr/bin/python3 - "$cells/quadruped_walk/centroid/seed_0.json" "$PWD/libcentroid.so" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
assert c["status"] == "ok", c["status"]
assert c["plugin"]["path"] == sys.argv[2], c["plugin"]
assert len(c["plugin"]["fnv1a64"]) == 16 and c["plugin"]["abi"] >= 7, c["plugin"]
assert c["plugin"]["version"] == "1.0", c["plugin"]
PY

# ---- bad transfers: one cell fails, named; the others stay; a rerun after
# the fix computes exactly that cell
# Each fault is planted where the plug-in first meets quadruped_trot: its
# cell (id 3, as `tcbench cells` numbers them) computed again.
fault() { # fault KIND MESSAGE
    CENTROID_FAULT="$1:quadruped_trot" expect 1 "synth/quadruped_trot/centroid/seed 0: transfer " \
        "$tcbench" run mine.json --quiet --force --cell 3
    grep -qF "1 computed, 0 already done, 1 failed" err.txt || { echo "FAIL: $1"; cat err.txt; exit 1; }
    grep -qF "$2" err.txt || { echo "FAIL: $1: no '$2'"; cat err.txt; exit 1; }
    /usr/bin/python3 - "$cells/quadruped_trot/centroid/seed_0.json" "$2" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
assert c["status"] == "failed", c["status"]          # not "diverged": a rerun retries it
assert sys.argv[2] in c["message"] and "(pair " in c["message"], c["message"]
PY
    cell_sums | grep -v quadruped_trot/centroid > others.txt
    grep -v quadruped_trot/centroid before.txt | cmp -s - others.txt || { echo "FAIL: $1 touched other cells"; exit 1; }
    expect 0 "cells: 4 in all, 1 computed, 3 already done, 0 failed" "$tcbench" run mine.json --quiet
    # ... and computes it as the first run did, to the last bit.
    expect 0 "4 cells, 0 differ" /usr/bin/python3 "$TCB_SOURCE_DIR/scripts/same_cells.py" first runs/mine
}
fault huge "returned a point beyond ±1e+18 (vertex "
fault nan "returned a non-finite point (vertex "
fault ids "no points of the shape (vertex ids or another unit written as coordinates?)"

# ---- the plug-in rebuilt with other code: refused like changed params
build libcentroid.so -DSHIFT=0.001f '-DVERSION="1.1"' 
expect 2 "--force --only centroid" "$tcbench" run mine.json --quiet
grep -qF "plugin_fnv1a64" err.txt || { echo "FAIL: the refusal does not say the plug-in changed"; cat err.txt; exit 1; }
grep -qF "cells: 2 in all, 0 computed, 2 already done, 0 failed" err.txt || { cat err.txt; exit 1; }
expect 0 "" "$tcbench" cells mine.json
[ "$(grep -c 'centroid .* done (other settings)$' out.txt)" -eq 2 ] || { echo "FAIL: cells"; cat out.txt; exit 1; }
[ "$(grep -c 'nearest .* done$' out.txt)" -eq 2 ] || { echo "FAIL: cells"; cat out.txt; exit 1; }
# inspect would recompute a pair with other code than the cell's: refused
expect 2 "centroid's cells were computed by the build " \
    "$tcbench" inspect runs/mine centroid 0 --sequence synth/quadruped_walk --quiet
grep -qF "(rebuilt since): recompute them with 'tcbench run CONFIG --force --only centroid' first" err.txt ||
    { cat err.txt; exit 1; }
old=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["plugin"]["fnv1a64"])' \
      "$cells/quadruped_walk/centroid/seed_0.json")
expect 0 "cells: 2 in all, 2 computed, 0 already done, 0 failed" "$tcbench" run mine.json --quiet --force --only centroid
new=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["plugin"]["fnv1a64"])' \
      "$cells/quadruped_walk/centroid/seed_0.json")
[ "$old" != "$new" ] || { echo "FAIL: the cell does not record the new build"; exit 1; }
/usr/bin/python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["plugin"]["version"] == "1.1"' \
    "$cells/quadruped_walk/centroid/seed_0.json"
expect 0 "" "$tcbench" inspect runs/mine centroid 0 --sequence synth/quadruped_walk --quiet
cell_sums | grep nearest > nearest.txt
grep nearest before.txt | cmp -s - nearest.txt || { echo "FAIL: the rebuilt plug-in's run touched nearest"; exit 1; }
expect 0 "cells: 4 in all, 0 computed, 4 already done" "$tcbench" run mine.json --quiet

# ---- one file however named; another file with the same name refused
expect 0 "cells: 4 in all, 0 computed, 4 already done" "$tcbench" --plugin "$PWD/libcentroid.so" run mine.json --quiet
cp libcentroid.so libcopy.so
expect 2 "libcentroid.so: a method named 'centroid' is already registered from $PWD/libcopy.so" \
    "$tcbench" --plugin ./libcopy.so run mine.json --quiet

# ---- incomplete and future tables
build libnotransfer.so -DNULL_TRANSFER
expect 2 "libnotransfer.so: method 'centroid' has no transfer (create, fit, transfer and destroy are required)" \
    "$tcbench" --plugin ./libnotransfer.so methods
build libfuture.so -DABI=99
expect 2 "libfuture.so: method ABI version 99, this tcbench" "$tcbench" --plugin ./libfuture.so methods
grep -qF "rebuild the plug-in against this tcbench's headers" err.txt || { cat err.txt; exit 1; }
echo "ok: a new plug-in's faults each fail or refuse what they should, and nothing else"

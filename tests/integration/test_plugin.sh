#!/usr/bin/env bash
# An out-of-tree plug-in, built only against the INSTALLED headers and
# library, is listed by `tcbench methods` and runs through the harness; so
# does one whose table has the shorter layout of method ABI 2 (built
# against the older header: the harness must read nothing past its end,
# which the sanitized build's redzones would catch).
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

cmake --install "$TCB_BUILD_DIR" --prefix "$tmp/prefix" >/dev/null
libdir=$(dirname "$(find "$tmp/prefix" -name 'libtcbench.so' | head -n1)")
# Plug-ins of a sanitized tcbench need the sanitizer runtime too.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
"$CC" -std=c11 -O2 -Wall -Wextra -Werror -shared -fPIC $sanitize \
  -I"$tmp/prefix/include" "$TCB_SOURCE_DIR/examples/plugin/centroid_nearest.c" \
  -L"$libdir" -ltcbench -lcjson -o "$tmp/libcentroid_nearest.so"

# The ABI 2 table, as the older header laid it out (no prepare_pairs).
cat > "$tmp/old_abi.c" <<'C'
#include <string.h>
#include <tcb/method.h>
typedef struct v2_ops {
    int abi_version;
    const char *name, *description;
    int (*create)(const char *, void **, tcb_error *);
    int (*fit)(void *, const tcb_sequence *, const tcb_fit_ctx *, tcb_error *);
    int (*transfer)(void *, const tcb_sequence *, int, int, const float *, int, float *, tcb_rng *, tcb_error *);
    int (*reconstruct)(void *, const tcb_sequence *, int, int, int, tcb_rng *, float **, int *, tcb_error *);
    int (*save)(void *, const char *, tcb_error *);
    int (*load)(void *, const tcb_sequence *, const char *, tcb_error *);
    void (*destroy)(void *);
    void (*estimate)(void *, const tcb_cost_query *, tcb_cost_estimate *);
} v2_ops;
static int create(const char *p, void **self, tcb_error *err) { (void)p, (void)err; *self = NULL; return TCB_OK; }
static int fit(void *self, const tcb_sequence *seq, const tcb_fit_ctx *ctx, tcb_error *err)
{
    (void)self, (void)seq, (void)ctx, (void)err;
    return TCB_OK;
}
static int transfer(void *self, const tcb_sequence *seq, int i, int j, const float *src, int n, float *out,
                    tcb_rng *rng, tcb_error *err)
{
    (void)self, (void)seq, (void)i, (void)j, (void)rng, (void)err;
    memcpy(out, src, (size_t)n * 3 * sizeof *out);
    return TCB_OK;
}
static void destroy(void *self) { (void)self; }
static const v2_ops old = {2, "old_abi", "nearest, built against method ABI 2", create, fit, transfer,
                           NULL, NULL, NULL, destroy, NULL};
const tcb_method_ops *const *tcb_plugin_methods(int *count);
const tcb_method_ops *const *tcb_plugin_methods(int *count)
{
    static const tcb_method_ops *const t[] = {(const tcb_method_ops *)(const void *)&old};
    *count = 1;
    return t;
}
C
"$CC" -std=c11 -O2 -Wall -Wextra -Werror -shared -fPIC $sanitize -I"$tmp/prefix/include" "$tmp/old_abi.c" \
  -o "$tmp/libold_abi.so"

"$TCBENCH" --plugin "$tmp/libcentroid_nearest.so" methods > "$tmp/methods.txt"
grep -q "centroid_nearest" "$tmp/methods.txt" || { cat "$tmp/methods.txt"; echo "plug-in not listed"; exit 1; }
grep -q "oracle" "$tmp/methods.txt" || { echo "built-ins missing"; exit 1; }

cat > "$tmp/config.json" <<JSON
{ "name": "plugin", "output": "$tmp/run", "splits_dir": "$tmp/splits", "cache_dir": "",
  "plugins": ["$tmp/libcentroid_nearest.so", "$tmp/libold_abi.so"],
  "evaluation": { "pairs": 20 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 30,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "nearest" }, { "name": "centroid_nearest" },
               { "name": "centroid_off", "method": "centroid_nearest", "params": { "translate": false } },
               { "name": "old_abi" } ] }
JSON
"$TCBENCH" run "$tmp/config.json" --quiet

/usr/bin/python3 - "$tmp/run" <<'PY'
import glob, json, sys
cells = {}
for path in glob.glob(sys.argv[1] + "/cells/**/*.json", recursive=True):
    c = json.load(open(path))
    cells[c["method"]] = c
assert set(cells) == {"nearest", "centroid_nearest", "centroid_off", "old_abi"}, cells.keys()
for name, c in cells.items():
    assert c["status"] == "ok", (name, c["status"], c["message"])
    assert c["summary"]["n_pairs"] == 20, name
# With the shift switched off the plug-in is exactly `nearest`.
assert cells["centroid_off"]["summary"] == cells["nearest"]["summary"]
assert cells["centroid_off"]["method_impl"] == "centroid_nearest"
assert cells["old_abi"]["summary"] == cells["nearest"]["summary"]
print("plug-in cells ok")
PY

# A broken plug-in path is a clear input error (exit 2).
set +e
"$TCBENCH" --plugin "$tmp/missing.so" methods 2> "$tmp/err.txt"
rc=$?
set -e
[ "$rc" -eq 2 ] || { echo "expected exit 2 for a missing plug-in, got $rc"; exit 1; }
grep -q "missing.so" "$tmp/err.txt" || { cat "$tmp/err.txt"; exit 1; }
# A plug-in built for another ABI version is refused, naming the problem.
cat > "$tmp/bad_abi.c" <<'C'
#include <tcb/method.h>
static const tcb_method_ops bad = { .abi_version = TCB_METHOD_ABI_VERSION + 98, .name = "bad" };
const tcb_method_ops *const *tcb_plugin_methods(int *count);
const tcb_method_ops *const *tcb_plugin_methods(int *count)
{
    static const tcb_method_ops *const t[] = {&bad};
    *count = 1;
    return t;
}
C
"$CC" -std=c11 -shared -fPIC $sanitize -I"$tmp/prefix/include" "$tmp/bad_abi.c" -o "$tmp/libbad.so"
set +e
"$TCBENCH" --plugin "$tmp/libbad.so" methods 2> "$tmp/err.txt"
rc=$?
set -e
[ "$rc" -eq 2 ] || { echo "expected exit 2 for a wrong-ABI plug-in, got $rc"; exit 1; }
grep -q "ABI version" "$tmp/err.txt" || { cat "$tmp/err.txt"; exit 1; }
echo "plug-in test passed"

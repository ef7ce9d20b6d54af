# Sourced by the integration tests that drive python/tcbench: skips (77)
# when /usr/bin/python3 has no numpy; sets lib (the build's libtcbench),
# sanitizer_env and py, /usr/bin/python3 with the source tree's package,
# that library and pychecks.py (the shared checks).

if ! /usr/bin/python3 -c "import numpy" 2>/dev/null; then
    echo "skipped: /usr/bin/python3 cannot import numpy (scripts/setup.sh installs it)"
    exit 77
fi
lib=$TCB_BUILD_DIR/libtcbench.so

# A sanitized library (TCB_SANITIZE) loads into python only after the ASan
# runtime, and the interpreter's own allocations are not ours to leak-check.
sanitizer_env=()
if readelf -d "$lib" | grep -q 'NEEDED.*libasan'; then
    sanitizer_env=(LD_PRELOAD="$("${CC:-gcc}" -print-file-name=libasan.so)" ASAN_OPTIONS=detect_leaks=0)
fi
py() { env "${sanitizer_env[@]}" PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$TCB_SOURCE_DIR/python:$TCB_SOURCE_DIR/tests/integration" TCBENCH_LIB="$lib" /usr/bin/python3 "$@"; }

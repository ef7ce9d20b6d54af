# Sourced by the tests that `pip install .` as a researcher does: skips (77)
# when /usr/bin/python3 lacks numpy, venv with pip, setuptools or wheel.
#   venv_install DIR: the checkout's files as git sees them (tracked, and new
#     files not ignored: what a clone has) copied to DIR/src, a fresh virtual
#     environment DIR/venv (Debian's numpy and setuptools through
#     --system-site-packages), `pip install --no-build-isolation --no-index`
#     of the copy, offline, pip's output in DIR/pip.log; the copy is kept
#     (the caller deletes it once done with it).
#   in_venv DIR WORKDIR COMMAND...: COMMAND in WORKDIR in a fresh shell with
#     the venv activated (its bin/ first on PATH) and an otherwise empty
#     environment (PATH and HOME only: no PYTHONPATH, no TCBENCH_LIB).
# setup.py builds the library in TCBENCH_CMAKE_BUILD_DIR, here the test's own
# build (only bringing tcbench_lib up to date: seconds, not a rebuild);
# TCB_TEST_PIP_FRESH_BUILD=1 leaves it unset, so pip configures and builds a
# Release library from scratch in the copy, as a user's `pip install .` does.
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}"

if ! /usr/bin/python3 -c "import numpy, setuptools, wheel, ensurepip, venv" 2>/dev/null; then
    echo "skipped: /usr/bin/python3 lacks numpy, setuptools, wheel or venv (scripts/setup.sh installs them)"
    exit 77
fi

venv_install() {
    local dir=$1
    mkdir -p "$dir/src" "$dir/home"
    if git -C "$TCB_SOURCE_DIR" rev-parse --git-dir > /dev/null 2>&1; then
        (cd "$TCB_SOURCE_DIR" && git ls-files -z --cached --others --exclude-standard |
            tar --null -T - --ignore-failed-read -cf - 2> /dev/null) | tar -C "$dir/src" -xf -
    else
        tar -C "$TCB_SOURCE_DIR" --exclude='./build*' --exclude=./.git -cf - . | tar -C "$dir/src" -xf -
    fi
    local build_dir=("TCBENCH_CMAKE_BUILD_DIR=$TCB_BUILD_DIR")
    [ "${TCB_TEST_PIP_FRESH_BUILD:-}" = 1 ] && build_dir=()
    /usr/bin/python3 -m venv --system-site-packages "$dir/venv"
    (cd "$dir/home" && env "${build_dir[@]}" PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_NO_CACHE_DIR=1 \
        "$dir/venv/bin/pip" install --no-build-isolation --no-index "$dir/src") > "$dir/pip.log" 2>&1
}

# A sanitized library (TCB_SANITIZE) loads into python only after the ASan runtime.
venv_sanitizer_env=()
if readelf -d "$TCB_BUILD_DIR/libtcbench.so" | grep -q 'NEEDED.*libasan'; then
    venv_sanitizer_env=(LD_PRELOAD="$("${CC:-gcc}" -print-file-name=libasan.so)" ASAN_OPTIONS=detect_leaks=0)
fi

in_venv() {
    local dir=$1 work=$2
    shift 2
    (cd "$work" && env -i PATH="$dir/venv/bin:/usr/bin:/bin" HOME="$dir/home" "${venv_sanitizer_env[@]}" "$@")
}

#!/usr/bin/env bash
# `pip install .` as a researcher runs it, offline: a fresh virtual
# environment (Debian's numpy and setuptools through --system-site-packages),
# `pip install --no-build-isolation --no-index` of a copy of the checkout (its
# git files, as a clone has them; pip's in-tree build writes there, not into
# the source tree), the copy deleted, then `import tcbench` from an empty
# directory in an empty environment (PATH and HOME only: no PYTHONPATH, no
# TCBENCH_LIB): the library it loads is the one inside the venv, and it
# computes. `pip uninstall` takes the library with it; `pip install ./python`
# fails saying to install from the root.
# The install is tests/integration/venv.sh's (TCB_TEST_PIP_FRESH_BUILD=1: a
# build from scratch, as a user's). Skipped when /usr/bin/python3 lacks
# numpy, venv with pip, setuptools or wheel.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/venv.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/empty"
venv_install "$tmp" || { echo "FAIL: pip install"; cat "$tmp/pip.log"; exit 1; }
test -f "$tmp/src/pyproject.toml" && test -f "$tmp/src/setup.py" || { echo "FAIL: no pyproject.toml/setup.py in the copy"; exit 1; }
# A wheel for this platform (it carries a compiled library), not a pure one.
grep -q "filename=tcbench-.*-linux_[a-z0-9_]*\.whl" "$tmp/pip.log" || { echo "FAIL: not a platform wheel"; cat "$tmp/pip.log"; exit 1; }
# ./python is not the way, and says so.
if (cd "$tmp/home" && PIP_DISABLE_PIP_VERSION_CHECK=1 "$tmp/venv/bin/pip" install --no-build-isolation --no-index \
        "$tmp/src/python") > "$tmp/pip_python.log" 2>&1; then
    echo "FAIL: pip install ./python succeeded"; exit 1
fi
grep -qF "install from the repository root: \`pip install .\` there" "$tmp/pip_python.log" || { cat "$tmp/pip_python.log"; exit 1; }
rm -rf "$tmp/src"

fresh() { in_venv "$tmp" "$tmp/empty" "$@"; }
fresh python3 - "$tmp/venv" <<'PY'
import os, sys
import numpy as np
import tcbench
venv = os.path.realpath(sys.argv[1])
lib = tcbench.library_path()
assert os.path.realpath(lib).startswith(venv + "/"), lib
assert os.path.dirname(os.path.realpath(lib)) == os.path.dirname(os.path.realpath(tcbench.__file__)), lib
assert not os.path.islink(lib), lib
assert "PYTHONPATH" not in os.environ and tcbench.ENV_VAR not in os.environ
m = tcbench.pair_metrics(np.eye(3, dtype=np.float32), [1, 1, 2])
assert m["summary"]["n"] == 3 and m["rank"].tolist() == [1 / 3, 0.0, 0.0], m["rank"]
print("installed:", lib)
PY

# TCBENCH_LIB still goes first: a wrong one is an error, not the bundled copy.
out=$(fresh TCBENCH_LIB=/nowhere/libtcbench.so python3 -c 'import tcbench; tcbench.library_path()' 2>&1) &&
    { echo "FAIL: TCBENCH_LIB=/nowhere loaded"; exit 1; }
grep -qF "TCBENCH_LIB: /nowhere/libtcbench.so (no such file)" <<< "$out" || { echo "$out"; exit 1; }

lib=$(fresh python3 -c 'import tcbench; print(tcbench.library_path())')
fresh pip uninstall -y tcbench > "$tmp/uninstall.log" 2>&1 || { cat "$tmp/uninstall.log"; exit 1; }
[ ! -e "$lib" ] || { echo "FAIL: pip uninstall left $lib"; exit 1; }
echo "python install test passed"

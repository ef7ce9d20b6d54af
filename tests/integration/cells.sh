# Sourced by the integration tests that interrupt runs and compare them cell
# by cell.

# same_cells A B: the same cell files with the same contents, but for the
# fields that measure the machine rather than the method.
same_cells() {
    /usr/bin/python3 - "$1" "$2" <<'PY'
import json, os, sys
def cells(root):
    out = {}
    for d, _, files in os.walk(os.path.join(root, "cells")):
        for f in files:
            c = json.load(open(os.path.join(d, f)))
            c.pop("timings"); c.pop("peak_rss_kb")
            out[os.path.relpath(os.path.join(d, f), root)] = c
    return out
a, b = cells(sys.argv[1]), cells(sys.argv[2])
assert sorted(a) == sorted(b), (sorted(a), sorted(b))
for k in a:
    assert a[k] == b[k], "cell %s differs" % k
print("%d cells identical" % len(a))
PY
}

# kill_when PID COMMAND...: SIGKILL the run PID as soon as COMMAND succeeds
# (polling for up to a minute), or let it be once it has exited.
kill_when() {
    local pid=$1
    shift
    for _ in $(seq 3000); do
        "$@" && break
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.02
    done
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
}

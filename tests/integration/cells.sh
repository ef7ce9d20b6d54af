# Sourced by the integration tests that interrupt runs and compare them cell
# by cell, and by those that check the cells of a carried template.

# enter_temp_dir: a fresh temporary directory as $tmp and the working
# directory, removed at exit, when a background run whose pid the test puts
# in $pid is killed too.
enter_temp_dir() {
    tmp=$(mktemp -d)
    pid=""
    trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
    cd "$tmp"
}

# same_cells A B: the same cell files with the same contents, but for the
# fields that measure the machine rather than the method.
same_cells() { compare_cells "$1" "$2" same; }

# cells_within A B: every cell file B has (its locks and temporaries aside)
# is complete and equal to A's: what a run stopped anywhere may leave.
cells_within() { compare_cells "$1" "$2" within; }

compare_cells() {
    /usr/bin/python3 - "$1" "$2" "$3" <<'PY'
import json, os, sys
mode = sys.argv[3]
def cells(root):
    out = {}
    for d, _, files in os.walk(os.path.join(root, "cells")):
        for f in files:
            if mode == "within" and not f.endswith(".json"):
                continue
            c = json.load(open(os.path.join(d, f)))
            c.pop("timings"); c.pop("peak_rss_kb")
            out[os.path.relpath(os.path.join(d, f), root)] = c
    return out
a, b = cells(sys.argv[1]), cells(sys.argv[2])
if mode == "same":
    assert sorted(a) == sorted(b), (sorted(a), sorted(b))
else:
    assert set(b) <= set(a), sorted(set(b) - set(a))
for k in b:
    assert a[k] == b[k], "cell %s differs" % k
print("%d cells identical" % len(b))
PY
}

# stop_when PID COMMAND...: SIGSTOP the run PID as soon as COMMAND succeeds
# (polling for up to a minute) and leave it stopped (status 0); status 1
# when the run exited or COMMAND never succeeded (the run goes on). COMMAND
# is asked while the run is stopped, so the run stays in the state COMMAND
# saw: on a loaded machine a lock seen held could otherwise be released
# before a signal sent after the look lands.
stop_when() {
    local pid=$1
    shift
    for _ in $(seq 3000); do
        kill -STOP "$pid" 2>/dev/null || return 1
        "$@" && return 0
        kill -CONT "$pid" 2>/dev/null || return 1
        sleep 0.02
    done
    return 1
}

# kill_when PID COMMAND...: SIGKILL the run PID in the state COMMAND saw
# (stop_when), or after a minute, or let it be once it has exited.
kill_when() {
    local pid=$1
    shift
    stop_when "$pid" "$@" || true
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
}

# kill_mid_fit CONFIG WORK CELL [RUN OPTIONS]: a run of CONFIG into killed/
# is killed once the training state killed/WORK/train.ckpt exists and before
# killed/CELL is written, then resumed, which its log must announce.
kill_mid_fit() {
    local config=$1 work=killed/$2 cell=killed/$3
    shift 3
    "$TCBENCH" run "$config" --out killed --quiet "$@" &
    pid=$!
    kill_when "$pid" test -s "$work/train.ckpt"
    pid=""
    [ -s "$work/train.ckpt" ] && [ ! -e "$cell" ] ||
        { echo "FAIL: the kill did not land between the first checkpoint and the end"; exit 1; }
    # Not quiet (CI=true would be): the resume is announced at log level info.
    CI= "$TCBENCH" run "$config" --out killed "$@" 2> resume.log
    grep -q "resuming training at iteration [1-9]" resume.log || { echo "FAIL: did not resume"; cat resume.log; exit 1; }
}

# check_carried_cell CELL: the cell of a method whose template is carried
# into every frame (pdg, dynosurf) is ok with every metric, a CD on each of
# its 6 pairs, and the reconstruction metrics of its surface on every frame
# of its pairs.
check_carried_cell() {
    /usr/bin/python3 - "$1" <<'PY'
import json, math, sys
c = json.load(open(sys.argv[1]))
assert c["status"] == "ok", (c["status"], c["message"])
s = c["summary"]
assert s["n_pairs"] == 6 and s["cd"]["n"] == 6
for key in ("sl2", "rank", "auc", "cd", "geo"):
    assert math.isfinite(s[key]["mean"]), key
frames = sorted({f for p in c["pairs"] for f in p[:2]})
surf = c["surface"]
assert [r[0] for r in surf["rows"]] == frames, surf
for key in ("cdl2", "nc", "fscore05", "fscore1"):
    assert s[key]["n"] == len(frames), (key, s[key])
PY
}

#!/usr/bin/env bash
# The external method (a method in any language, "method": "external"):
# the numpy/scipy example (rigid ICP + nearest) runs through it with sane
# metrics; the Python skeleton (nearest as it stands) and a command writing
# oracle's ids give cells bit-identical to those built-ins'; reconstructions
# give a CD; a non-zero exit (its last lines quoted, in order), the
# "diverged" status 3, a timeout (a command ignoring SIGTERM killed after
# its grace), a malformed, a missing prediction, a missing reconstruction
# and a command that does not exist fail the cell with a message naming
# the file or the command (the run exits 1 and lists them, log tails
# included), and leave none of its processes behind; bad
# params stop the run before it starts. inspect, frames and a resumed run
# reuse the fit; --force clears the command's model directory. A stop request
# (SIGTERM to tcbench) stops the command gracefully in fit and in transfer,
# exits 75, and the rerun finishes the cell (without refitting after a
# stop in transfer). The program that ran is named, as an absolute path, in
# the log and in every failure: a .py command runs under params.python,
# else $TCBENCH_PYTHON, else python3 from PATH (here a shim without numpy,
# first on PATH as a pyenv shim can be), and the examples run as .py
# commands under TCBENCH_PYTHON. Skipped when /usr/bin/python3 lacks numpy
# or scipy.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

py=/usr/bin/python3
if ! "$py" -c "import numpy, scipy" 2>/dev/null; then
    echo "skipped: /usr/bin/python3 cannot import numpy and scipy (scripts/setup.sh installs them)"
    exit 77
fi

# tcbench makes the command's Python output unbuffered (so a failure's last
# lines come in order); the check of that must not find it already set.
unset PYTHONUNBUFFERED

tmp=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill -9 "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
cd "$tmp"
ex=$TCB_SOURCE_DIR/examples/python
fake=$TCB_SOURCE_DIR/tests/integration/external_fake.py

# config FILE METHODS...: a config on a small synthetic sequence.
config() {
    local file=$1 methods
    shift
    methods=$(IFS=,; echo "$*")
    cat > "$file" <<JSON
{ "name": "ext", "output": "run", "splits_dir": "splits", "cache_dir": "", "threads": 1,
  "evaluation": { "pairs": 20, "pool_size": 2000 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 12,
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ $methods ] }
JSON
}
# ext LABEL 'COMMAND LIST' [MORE PARAMS]: an external method.
ext() { echo "{ \"name\": \"$1\", \"method\": \"external\", \"params\": { \"command\": [$2]${3:+, $3} } }"; }
fake() { ext "$1" "\"$py\", \"$fake\", \"$2\"" "${3:-}"; }

# The examples as a user lists them: the script alone, its interpreter from TCBENCH_PYTHON.
export TCBENCH_PYTHON=$py
config ext.json '{ "name": "nearest" }' '{ "name": "oracle" }' \
    "$(ext icp "\"$ex/icp_nearest.py\"")" "$(ext skeleton "\"$ex/skeleton.py\"")" \
    "$(fake ids oracle)" "$(fake recon recon)" "$(fake fail fail)" "$(fake diverge diverge)" \
    "$(fake timeout sleep '"timeout_s": 4')" "$(fake stubborn stubborn '"timeout_s": 4, "grace_s": 0.5')" \
    "$(fake malformed malformed)" "$(fake missing missing)" "$(fake partial_recon partial_recon)" \
    "$(ext nocmd '"tcb-no-such-command"')" "$(ext nofile '"/nonexistent/tcb-cmd"')"
# Eight cells fail (no result): the run exits 1 and lists them at the end,
# the crashed command's last log lines in its message.
rc=0
"$TCBENCH" run ext.json --quiet 2> run.log || rc=$?
[ "$rc" -eq 1 ] && grep -qF "15 computed, 0 already done, 8 failed, 1 diverged" run.log &&
    sed -n '/^failed cells (no result; a rerun retries them):$/,$p' run.log |
    grep -qE "^synth/quadruped_walk/fail/seed 0: fit: .*its last lines: line 6 \| .* \| line 15$" ||
    { echo "FAIL: run with failed cells exited $rc"; cat run.log; exit 1; }

"$py" - <<'PY'
import json, os
cells = "run/cells/synth/quadruped_walk/"
work = "run/work/synth/quadruped_walk/"
def cell(m):
    return json.load(open(cells + m + "/seed_0.json"))
def ok(m):
    c = cell(m)
    assert c["status"] == "ok", (m, c["status"], c["message"])
    assert c["method_impl"] == "external" and c["summary"]["n_pairs"] == 20, m
    return c
nearest, oracle = cell("nearest"), cell("oracle")
for m, ref in [("skeleton", nearest), ("ids", oracle)]:
    c = ok(m)
    assert c["summary"] == ref["summary"] and c["pairs"] == ref["pairs"], m
icp = ok("icp")["summary"]
assert 0 < icp["sl2"]["mean"] < nearest["summary"]["sl2"]["mean"], (icp["sl2"], nearest["summary"]["sl2"])
assert icp["cd"] is None
recon = ok("recon")["summary"]
assert recon["sl2"] == nearest["summary"]["sl2"] and recon["cd"]["n"] == 20 and recon["cd"]["mean"] > 0, recon["cd"]

def failed(m, status, *texts, absent=()):
    c = cell(m)
    assert c["status"] == status, (m, c["status"], c["message"])
    for t in texts:
        assert t in c["message"], (m, t, c["message"])
    for t in absent:
        assert t not in c["message"], (m, t, c["message"])
    return c
lines = " | ".join("line %d" % n for n in range(6, 16))
failed("fail", "failed", "fit: `", "external_fake.py fail fit` exited with status 2",
       "(program /usr/bin/python3, log ", "external.log); its last lines: " + lines, absent=["line 5 |"])
failed("diverge", "diverged", "exited with status 3: diverged", "loss is nan")
for m in ["timeout", "stubborn"]:
    c = failed(m, "failed", "did not finish within timeout_s = 4 s and was stopped", "its last lines: waiting")
    assert c["timings"]["fit_s"] < 11, (m, c["timings"])  # stubborn: SIGKILL after the 0.5 s grace
    for pid in map(int, open(work + m + "/seed_0/model/pids").read().split()):
        try:
            state = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()[0]
        except FileNotFoundError:
            continue
        assert state == "Z", (m, pid, "still running")
failed("malformed", "failed", "(pair 0): ", "/pred/0.npy: not a .npy file", "NUMPY); program: /usr/bin/python3")
failed("missing", "failed", "prepare_pairs 0-19: ", "/pred/3.npy: no such file (the transfer step writes one prediction per pair); program: /usr/bin/python3")
failed("partial_recon", "failed", "/pred/recon_2_i.npy: no such file (reconstructions are written for every pair or for none)")
failed("nocmd", "failed", "fit: external.params.command: 'tcb-no-such-command': not found in PATH")
failed("nofile", "failed", "fit: external.params.command: '/nonexistent/tcb-cmd': no such executable file")
log = open(work + "icp/seed_0/external.log").read()
assert "icp_nearest.py fit\n==== program: /usr/bin/python3 [TCBENCH_PYTHON]\n" in log, log[:300]
print("external cells check out")
PY

# ---- which python: a shim `python3` without numpy first on PATH
mkdir shim
printf '#!/bin/sh\necho "ModuleNotFoundError: No module named numpy (the shim)" >&2\nexit 1\n' > shim/python3
chmod +x shim/python3
shim=$tmp/shim/python3
skel=\"$ex/skeleton.py\"
config which.json "$(ext default "$skel")" "$(ext listed "\"python3\", $skel")" \
    "$(ext param "$skel" "\"python\": \"$py\"")" "$(ext param_over_env "$skel" "\"python\": \"$py\"")"
# which_run OUT [NAME=VALUE...]: which.json run into OUT, PATH led by the shim, no TCBENCH_PYTHON unless given.
which_run() {
    local out=$1
    shift
    env -u TCBENCH_PYTHON PATH="$tmp/shim:$PATH" "$@" "$TCBENCH" run which.json --out "$out" --quiet 2> "$out.log" || true
}
which_run plain
which_run env TCBENCH_PYTHON="$py"
which_run env_shim TCBENCH_PYTHON=python3
"$py" - "$shim" "$py" <<'PY'
import json, sys
shim, py = sys.argv[1:]
def cell(out, m):
    return json.load(open(f"{out}/cells/synth/quadruped_walk/{m}/seed_0.json"))
def log(out, m):
    return open(f"{out}/work/synth/quadruped_walk/{m}/seed_0/external.log").read()
def ran(out, m, status, program):
    c = cell(out, m)
    assert c["status"] == status, (out, m, c["status"], c["message"])
    assert f"==== program: {program}\n" in log(out, m), (out, m, program, log(out, m))
    if status == "failed":
        assert f"(program {program}, log " in c["message"], (out, m, c["message"])
        assert "its last lines: ModuleNotFoundError: No module named numpy (the shim)" in c["message"], c["message"]
ran("plain", "default", "failed", f"{shim} [python3 from PATH]")
ran("plain", "listed", "failed", f"{shim} [python3 from PATH]")          # as listed: the shim
ran("plain", "param", "ok", f"{py} [external.params.python]")
ran("env", "default", "ok", f"{py} [TCBENCH_PYTHON]")
ran("env", "listed", "failed", f"{shim} [python3 from PATH]")            # TCBENCH_PYTHON is for .py commands
ran("env_shim", "default", "failed", f"{shim} [TCBENCH_PYTHON, python3 from PATH]")
ran("env_shim", "param_over_env", "ok", f"{py} [external.params.python]")
print("the program that ran is named")
PY
# An interpreter that is not there: the cell's message names where it came from.
config nopython.json "$(ext default "$skel")"
TCBENCH_PYTHON=/nonexistent/python "$TCBENCH" run nopython.json --out nopython --quiet 2> nopython.log || true
grep -qF "TCBENCH_PYTHON (the interpreter of $ex/skeleton.py): '/nonexistent/python': no such executable file" \
    nopython/cells/synth/quadruped_walk/default/seed_0.json || { cat nopython/cells/synth/quadruped_walk/default/seed_0.json nopython.log; exit 1; }

# inspect reloads the fit (no second fit) and recomputes the same pair.
log=run/work/synth/quadruped_walk/icp/seed_0/external.log
"$TCBENCH" inspect run icp 2 --out inspect --quiet > inspect.txt
grep -qF "(agree: " inspect.txt || { cat inspect.txt; exit 1; }
[ "$(grep -c 'icp_nearest.py fit$' "$log")" -eq 1 ] && [ "$(grep -c 'icp_nearest.py transfer$' "$log")" -eq 2 ] ||
    { echo "FAIL: inspect refitted"; cat "$log"; exit 1; }
# frames announces its transfers too (one more transfer step, numbered from
# 0) and draws the skeleton exactly as nearest.
"$TCBENCH" frames run skeleton --count 4 --out frames_skeleton --quiet > /dev/null
"$TCBENCH" frames run nearest --count 4 --out frames_nearest --quiet > /dev/null
for f in frames_nearest/*.ply; do cmp "$f" "frames_skeleton/${f#frames_nearest/}"; done
log=run/work/synth/quadruped_walk/skeleton/seed_0/external.log
[ "$(grep -c 'skeleton.py transfer$' "$log")" -eq 2 ] && [ "$(ls run/work/synth/quadruped_walk/skeleton/seed_0/pred)" = "0.npy
1.npy
2.npy" ] || { echo "FAIL: frames' transfer step"; cat "$log"; ls run/work/synth/quadruped_walk/skeleton/seed_0/pred; exit 1; }
# --force empties the work directory, the command's model directory included.
touch run/work/synth/quadruped_walk/icp/seed_0/model/stale
"$TCBENCH" run ext.json --only icp --force --quiet
[ ! -e run/work/synth/quadruped_walk/icp/seed_0/model/stale ] && [ -e run/work/synth/quadruped_walk/icp/seed_0/model/fitted.json ] ||
    { echo "FAIL: --force left the model directory"; find run/work/synth/quadruped_walk/icp; exit 1; }

# Bad params stop the run before any cell.
config bad.json "$(ext empty '')"
expect 2 "methods[0].params: external.params.command: expected a list of 1 to 256 strings" "$TCBENCH" run bad.json --out bad
config bad.json "$(ext unknown '"true"' '"timeout": 5')"
expect 2 "external.params.timeout: unknown key" "$TCBENCH" run bad.json --out bad

# stop LABEL: a run of LABEL alone, sent SIGTERM once its command waits; exit 75.
stop() {
    local rc=0 pids=stopped/work/synth/quadruped_walk/$1/seed_0/model/pids
    CI= "$TCBENCH" run stop.json --out stopped --only "$1" 2> "stop_$1.log" &
    pid=$!
    for _ in $(seq 3000); do [ -s "$pids" ] && break; sleep 0.02; done
    kill -TERM "$pid"
    wait "$pid" || rc=$?
    pid=""
    [ "$rc" -eq 75 ] || { echo "FAIL: $1: exit $rc after SIGTERM, expected 75"; cat "stop_$1.log"; exit 1; }
    grep -qF "was stopped by the stop request (SIGTERM, SIGKILL after 10 s)" "stop_$1.log" || { cat "stop_$1.log"; exit 1; }
    [ ! -e "stopped/cells/synth/quadruped_walk/$1/seed_0.json" ] || { echo "FAIL: $1: a stopped cell was written"; exit 1; }
    for p in $(cat "$pids"); do
        ! grep -qv ') Z' "/proc/$p/stat" 2>/dev/null || { echo "FAIL: $1: process $p outlived the stop"; exit 1; }
    done
    rm "$pids"
}
config stop.json "$(fake stop_fit stop_fit)" "$(fake stop_transfer stop_transfer)"
stop stop_fit
[ -e stopped/work/synth/quadruped_walk/stop_fit/seed_0/model/saved ] || { echo "FAIL: the command got no SIGTERM"; exit 1; }
stop stop_transfer
[ -s stopped/work/synth/quadruped_walk/stop_transfer/seed_0/model.ckpt ] || { echo "FAIL: the fit was not kept"; exit 1; }
"$TCBENCH" run stop.json --out stopped --quiet
log=stopped/work/synth/quadruped_walk/stop_transfer/seed_0/external.log
[ "$(grep -c 'stop_transfer fit$' "$log")" -eq 1 ] || { echo "FAIL: refitted after a stop in transfer"; cat "$log"; exit 1; }
"$py" - <<'PY'
import json
ref = json.load(open("run/cells/synth/quadruped_walk/nearest/seed_0.json"))["summary"]
for m in ["stop_fit", "stop_transfer"]:
    c = json.load(open("stopped/cells/synth/quadruped_walk/%s/seed_0.json" % m))
    assert c["status"] == "ok" and c["summary"] == ref, (m, c["status"], c["message"])
print("stopped cells resumed")
PY
echo "external test passed"

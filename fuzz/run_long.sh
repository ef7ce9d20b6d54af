#!/usr/bin/env bash
# The long fuzzing run: every target of a fuzz build until RUNS executions
# or SECONDS seconds, whichever comes first, growing its corpus in
# BUILD/fuzz/corpus/<target>, TCB_FUZZ_JOBS targets at a time (default 2),
# then a table of executions, time, coverage (edges, features), corpus
# size and findings.
#   fuzz/run_long.sh BUILD_DIR [RUNS [SECONDS [TARGET...]]]
# BUILD_DIR is configured with CC=clang -DTCB_FUZZ=ON (fuzz/README.md).
# A finding is left as BUILD_DIR/fuzz/findings/<target>-crash-* (or leak-,
# timeout-, oom-): reproduce it with BUILD_DIR/fuzz/fuzz_<target> FILE.
set -euo pipefail
build=$(realpath "${1:?usage: fuzz/run_long.sh BUILD_DIR [RUNS [SECONDS [TARGET...]]]}")
runs=${2:-1000000}
seconds=${3:-1800}
shift $(($# < 3 ? $# : 3))
src=$(cd "$(dirname "$0")/.." && pwd)
cd "$build/fuzz"
mkdir -p findings logs
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    mapfile -t targets < <(ctest -N | sed -n 's/.*fuzz_smoke_\([a-z_]*\)$/\1/p')
fi

one() {
    local t=$1 args
    # The smoke test's own command line (seeds, dictionary), with this
    # run's limits in place of the smoke test's time.
    args=$(ctest -R "^fuzz_smoke_${t}\$" --show-only=json-v1 |
        /usr/bin/python3 -c 'import json,sys; print("\n".join(json.load(sys.stdin)["tests"][0]["command"][1:]))' |
        grep -v '^-max_total_time=\|^-artifact_prefix=')
    mapfile -t args <<< "$args"
    LSAN_OPTIONS="suppressions=$src/tests/lsan.supp" OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive \
        ./"fuzz_$t" -runs="$runs" -max_total_time="$seconds" -artifact_prefix="findings/$t-" "${args[@]}" \
        > "logs/$t.log" 2>&1 || true
}
export -f one
export runs seconds src
printf '%s\n' "${targets[@]}" | xargs -P "${TCB_FUZZ_JOBS:-2}" -I{} bash -c 'one {}'

printf '| target | executions | seconds | edges | features | corpus | findings |\n|:---|---:|---:|---:|---:|---:|:---|\n'
for t in "${targets[@]}"; do
    log=logs/$t.log
    [ -s "$log" ] || continue
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
    last=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)
    cov=$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<< "$last")
    ft=$(sed -n 's/.*ft: \([0-9]*\).*/\1/p' <<< "$last")
    corp=$(sed -n 's/.*corp: \([0-9]*\).*/\1/p' <<< "$last")
    found=$(cd findings && ls "$t"-* 2> /dev/null | tr '\n' ' ' || true)
    printf '| %s | %s | %s | %s | %s | %s | %s |\n' "$t" "${execs:-?}" "${secs:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "${found:-none}"
done

#!/usr/bin/env bash
# README command 2: install what is missing, build with AddressSanitizer and
# UndefinedBehaviorSanitizer, and run the whole test suite (unit tests,
# CLI integration tests, the regression check of the quick config with the
# Release build, and the real-data tests when ../shared/data is present).
set -euo pipefail
cd "$(dirname "$0")/.."

# Each stage's wall time is printed at the end with the slowest tests, so
# the next stage or test that makes the suite slow is visible.
stage_t0=$SECONDS
stages=()
stage() { stages+=("$(printf '  %8d s  %s' $((SECONDS - stage_t0)) "$1")"); stage_t0=$SECONDS; }
print_stages() { echo "time by stage:"; printf '%s\n' "${stages[@]}"; }

scripts/setup.sh --tests
stage "packages (scripts/setup.sh --tests)"
# Debug information: line tables only (-g1; clang's -gline-tables-only
# below), what the sanitizers' stack traces print, without the variables
# and types only a debugger reads: a quarter less compiling (a build to
# debug in is configured without these two flags: CMake's -g).
cmake -S . -B build-test -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTCB_SANITIZE=ON \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >/dev/null
cmake --build build-test -j"$(nproc)" >/dev/null
stage "sanitized build (build-test)"
# The default benchmark's regression check runs a Release build: its 24
# cells under the sanitizers would take most of the suite's time, and
# every method runs sanitized in its own tests. Only tcbench and its
# library are built, without the geometry module (the benchmark meshes
# nothing, and CGAL's compile was half of this stage): the benchmark
# programs were compiled, with the same warnings, by the sanitized build,
# and README command 1's build directory is left as it is.
cmake -S . -B build-check -DCMAKE_BUILD_TYPE=Release -DTCB_BUILD_TESTS=OFF -DTCB_MESHING=OFF >/dev/null
cmake --build build-check -j"$(nproc)" --target tcbench >/dev/null
stage "Release build (build-check)"
# The fuzz targets (fuzz/README.md), built by clang with libFuzzer: each
# searches for 5 seconds from its seeds, after the suite (TCB_FUZZ_SMOKE_S:
# 10 by default; 5 keeps the suite within CI's 20 minutes, and longer
# searches are fuzz/README.md's). The sanitized build above replays their
# seeds and regressions.
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTCB_FUZZ=ON -DTCB_BUILD_TESTS=OFF \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" -DTCB_FUZZ_SMOKE_S=5 >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_targets >/dev/null
stage "fuzz targets (build-fuzz, clang)"
export TCBENCH_RELEASE="$PWD/build-check/tcbench"
export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
# Each suite's log is kept so that its ten slowest tests are printed at the
# end, passed or not: the next test that makes the suite slow is visible.
log=$(mktemp -d)
trap 'rm -rf "$log"' EXIT
slowest() {
    echo "ten slowest tests ($1):"
    sed -nE 's/^ *[0-9]+\/[0-9]+ Test +#[0-9]+: ([^ ]+) [ .*]*[A-Za-z]+ +([0-9.]+) sec$/\2 \1/p' "$log/$1" |
        sort -rn | head -10 | awk '{ printf "  %8.1f s  %s\n", $1, $2 }'
}
status=0
# One test more than cores: the Slurm, preemption and fault tests spend part
# of their time waiting on daemons and signals, and another test uses it.
(cd build-test && ctest --output-on-failure -j"$(($(nproc) + 1))" "$@") 2>&1 | tee "$log/tests" || status=1
stage "tests (build-test)"
slowest tests
[ "$status" = 0 ] || { print_stages; exit 1; }
(cd build-fuzz && ctest --output-on-failure -j"$(nproc)" "$@") 2>&1 | tee "$log/fuzz" || status=1
stage "fuzz searches (build-fuzz)"
slowest fuzz
print_stages
exit "$status"

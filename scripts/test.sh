#!/usr/bin/env bash
# README command 2: install what is missing, build with AddressSanitizer and
# UndefinedBehaviorSanitizer, and run the whole test suite (unit tests,
# CLI integration tests, the regression check of the quick config, and the
# real-data tests when ../shared/data is present).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh --tests
cmake -S . -B build-test -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTCB_SANITIZE=ON >/dev/null
cmake --build build-test -j"$(nproc)" >/dev/null
cd build-test
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j"$(nproc)" "$@"

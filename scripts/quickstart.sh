#!/usr/bin/env bash
# README command 1: install what is missing, build, run the default benchmark
# (embedded synthetic sequences, no download) and write its report.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTCB_BUILD_TESTS=OFF >/dev/null
cmake --build build -j"$(nproc)" >/dev/null
build/tcbench run configs/quick.json
build/tcbench report runs/quick

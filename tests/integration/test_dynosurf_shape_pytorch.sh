#!/usr/bin/env bash
# DynoSurf's shape network (methods/dynosurf/shape.c) against the
# reference's Decoder rebuilt in PyTorch with the same weights: outputs,
# the template's read-out and every weight gradient, to 1e-4
# (tests/pytorch/dynosurf_shape_check.py). Skipped (77) without torch.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip "DynoSurf shape network"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_shape.c" "$tmp/dynosurf_shape"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_shape_check.py" "$tmp/dynosurf_shape" "$tmp/work"

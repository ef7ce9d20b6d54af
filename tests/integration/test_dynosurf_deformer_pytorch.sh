#!/usr/bin/env bash
# DynoSurf's deformer (methods/dynosurf/deformer.c) against the reference's
# ControlPts_deformer rebuilt in PyTorch, float64, with the same weights:
# blend weights, transforms, deformed points, the gradient in the control
# points and both networks, and the blend pretraining's loss and gradient,
# to 1e-4 (tests/pytorch/dynosurf_deformer_check.py). Skipped (77) without
# torch.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip "DynoSurf deformer"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_deformer.c" "$tmp/dynosurf_deformer"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_deformer_check.py" "$tmp/dynosurf_deformer" "$tmp/work"

#!/usr/bin/env bash
# One step of DynoSurf's stage 2 (methods/dynosurf/motion.c) against the
# reference's rebuilt in PyTorch, float64, with the same weights, template,
# frames, grid picks and surface draws: the five terms, the deformer's
# gradient and Adam's step, to 1e-4 (tests/pytorch/dynosurf_motion_check.py).
# Skipped (77) without torch.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip "DynoSurf stage 2"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_motion_step.c" "$tmp/dynosurf_motion_step"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_motion_check.py" "$tmp/dynosurf_motion_step" "$tmp/work"

#!/usr/bin/env bash
# DynoSurf's template objectives (methods/dynosurf/template.c) against the
# reference's rebuilt in PyTorch with the same weights, grid, points and
# surface draws: the SDF pretraining's loss and gradient, stage 1's three
# terms, gradient and Adam step, to 1e-4
# (tests/pytorch/dynosurf_template_check.py). Skipped (77) without torch.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip "DynoSurf template"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_template_step.c" "$tmp/dynosurf_template_step"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/dynosurf_template_check.py" "$tmp/dynosurf_template_step" "$tmp/work"

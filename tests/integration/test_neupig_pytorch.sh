#!/usr/bin/env bash
# Neu-PiG's loss and every gradient (methods/neupig/model.c) against a
# PyTorch autograd reference written from the method's description
# (tests/pytorch/neupig_step_check.py), on a small random problem: three
# grid levels and the normal grid solved densely, the MLP, the quaternion
# motion, the robust Chamfer with the frames' confidence, the edge term.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip Neu-PiG

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/neupig_step.c" "$tmp/neupig_step"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/neupig_step_check.py" "$tmp/neupig_step" "$tmp/work"

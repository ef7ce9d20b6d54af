#!/usr/bin/env bash
# PDG's loss and every gradient (one step of methods/pdg/train.c) against a
# PyTorch autograd reference written from the method's description
# (tests/pytorch/pdg_step_check.py), on a small random problem: three field
# levels per transition solved densely, the input term, both chains from the
# keyframe with their catch-up weights and edge term, the template's
# Large-Steps parameters pulled to the keyframe; with each rotation
# (released: translations alone; cayley: the Cayley rotation solved in
# autograd as torch.linalg.solve(I - K, I + K)).
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

source "$TCB_SOURCE_DIR/tests/integration/step_helper.sh"
torch_or_skip PDG

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_step_helper "$TCB_SOURCE_DIR/tests/pytorch/pdg_step.c" "$tmp/pdg_step"
mkdir "$tmp/work"
cd "$TCB_SOURCE_DIR/tests/pytorch"
/usr/bin/python3 pdg_step_check.py "$tmp/pdg_step" "$tmp/work"

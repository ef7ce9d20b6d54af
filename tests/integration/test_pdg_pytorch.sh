#!/usr/bin/env bash
# PDG's loss and every gradient (one step of methods/pdg/train.c) against a
# PyTorch autograd reference written from the method's description
# (tests/pytorch/pdg_step_check.py), on a small random problem: three field
# levels per transition solved densely, the input term, both chains from the
# keyframe with their catch-up weights and edge term, the template's
# Large-Steps parameters pulled to the keyframe.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

if ! /usr/bin/python3 -c "import torch, numpy" 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 cannot import torch and numpy; install python3-torch to run the PDG PyTorch cross-check" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The helper uses the library's internal headers; a sanitized library needs
# a sanitized helper.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
"$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
  -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/pytorch/pdg_step.c" \
  -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$tmp/pdg_step"
mkdir "$tmp/work"
cd "$TCB_SOURCE_DIR/tests/pytorch"
/usr/bin/python3 pdg_step_check.py "$tmp/pdg_step" "$tmp/work"

#!/usr/bin/env bash
# Neu-PiG's loss and every gradient (methods/neupig/model.c) against a
# PyTorch autograd reference written from the method's description
# (tests/pytorch/neupig_step_check.py), on a small random problem: three
# grid levels and the normal grid solved densely, the MLP, the quaternion
# motion, the robust Chamfer with the frames' confidence, the edge term.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

if ! /usr/bin/python3 -c "import torch, numpy" 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 cannot import torch and numpy; install python3-torch to run the Neu-PiG PyTorch cross-check" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The helper uses the library's internal headers; a sanitized library needs
# a sanitized helper.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
"$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
  -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/pytorch/neupig_step.c" \
  -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$tmp/neupig_step"
mkdir "$tmp/work"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/neupig_step_check.py" "$tmp/neupig_step" "$tmp/work"

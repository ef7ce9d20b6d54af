#!/usr/bin/env bash
# The C atlas family (methods/atlas) against the same in PyTorch
# (tests/pytorch/atlas_torch.py), on weights and inputs that C helpers export:
#   atlas_export → atlas_net_check.py: the network, φ, φ_u, φ_v and the
#     gradients of a random objective of all three;
#   atlas_step_export → atlas_step_check.py: one training step of atlasnet,
#     dsr and mca: total loss, gradient, Adam update.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

if ! /usr/bin/python3 -c "import torch" 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 cannot import torch; install python3-torch to run the PyTorch cross-check" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The helpers use the library's internal headers; a sanitized library needs
# sanitized helpers.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
for pair in atlas_export:atlas_net_check atlas_step_export:atlas_step_check; do
  helper=${pair%%:*} check=${pair##*:}
  "$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
    -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/pytorch/$helper.c" \
    -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$tmp/$helper"
  mkdir "$tmp/$check"
  "$tmp/$helper" "$tmp/$check"
  /usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/$check.py" "$tmp/$check"
done

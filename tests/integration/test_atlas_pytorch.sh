#!/usr/bin/env bash
# The C atlas network (methods/atlas) against the same network in PyTorch:
# φ, φ_u, φ_v and the gradients of a random objective of all three, on
# weights and inputs exported by tests/pytorch/atlas_export.c.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

if ! /usr/bin/python3 -c "import torch" 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 cannot import torch; install python3-torch to run the PyTorch cross-check" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The helper uses the library's internal headers; a sanitized library needs
# a sanitized helper.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
"$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
  -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/pytorch/atlas_export.c" \
  -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$tmp/atlas_export"

"$tmp/atlas_export" "$tmp"
/usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/atlas_net_check.py" "$tmp"

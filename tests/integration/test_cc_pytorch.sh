#!/usr/bin/env bash
# The C CC method (methods/cycle) against the CC code's network and
# training step in PyTorch (tests/pytorch/cc_torch.py, a port of
# ThibaultGROUEIX/CycleConsistentDeformation), on weights and inputs that
# C helpers export:
#   cc_export → cc_net_check.py: the network in training mode (output,
#     gradients of a random objective, running statistics after the
#     forward) and in evaluation mode;
#   cc_step_export → cc_step_check.py: one tcb_cc_train_step during the
#     warm-up (eight network calls, self-reconstruction) and after it (six):
#     loss and terms, loss gradient, parameter gradient, Adam update,
#     running statistics.
# Skipped (77) when /usr/bin/python3 has no torch (Debian: python3-torch).
set -euo pipefail
: "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"

if ! /usr/bin/python3 -c "import torch, numpy" 2>/dev/null; then
  echo "SKIPPED: /usr/bin/python3 cannot import torch and numpy; install python3-torch to run the CC PyTorch cross-check" >&2
  exit 77
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The helpers use the library's internal headers; a sanitized library needs
# sanitized helpers.
sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
for pair in cc_export:cc_net_check cc_step_export:cc_step_check; do
  helper=${pair%%:*} check=${pair##*:}
  "$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
    -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/pytorch/$helper.c" \
    -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$tmp/$helper"
  mkdir "$tmp/$check"
  "$tmp/$helper" "$tmp/$check"
  /usr/bin/python3 "$TCB_SOURCE_DIR/tests/pytorch/$check.py" "$tmp/$check"
done

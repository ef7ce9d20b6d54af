# Sourced by the PyTorch cross-checks of a method's training step
# (test_neupig_pytorch.sh, test_pdg_pytorch.sh).

# torch_or_skip WHAT: exit 77 (ctest's skip) when /usr/bin/python3 has no
# torch, saying which cross-check did not run.
torch_or_skip() {
    if ! /usr/bin/python3 -c "import torch, numpy" 2>/dev/null; then
        echo "SKIPPED: /usr/bin/python3 cannot import torch and numpy; install python3-torch to run the $1 PyTorch cross-check" >&2
        exit 77
    fi
}

# build_step_helper SOURCE OUT: compiles a helper of tests/pytorch/ against
# this build's libtcbench. The helpers use the library's internal headers;
# a sanitized library needs a sanitized helper.
build_step_helper() {
    local sanitize
    sanitize=$(grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && echo "-fsanitize=address,undefined" || true)
    "${CC:-cc}" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE $sanitize \
        -I"$TCB_SOURCE_DIR" -I"$TCB_SOURCE_DIR/include" "$1" \
        -L"$TCB_BUILD_DIR" -Wl,-rpath,"$TCB_BUILD_DIR" -ltcbench -lm -o "$2"
}

# Sourced by the runner's integration tests: builds the test-only methods
# of harness_methods.c into a plug-in at the path given.
build_harness_methods() {
    local out=$1
    : "${TCB_SOURCE_DIR:?}" "${TCB_BUILD_DIR:?}" "${CC:=cc}"
    # Plug-ins of a sanitized tcbench need the sanitizer runtime too.
    local sanitize=""
    grep -q 'TCB_SANITIZE:BOOL=ON' "$TCB_BUILD_DIR/CMakeCache.txt" && sanitize="-fsanitize=address,undefined"
    "$CC" -std=c11 -O2 -Wall -Wextra -Werror -D_DEFAULT_SOURCE -shared -fPIC -fopenmp $sanitize \
        -I"$TCB_SOURCE_DIR/include" "$TCB_SOURCE_DIR/tests/integration/harness_methods.c" \
        -L"$TCB_BUILD_DIR" -ltcbench -lcjson -lm -o "$out"
}

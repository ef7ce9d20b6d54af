# Sourced by the integration tests that check exit codes and messages.

# expect STATUS TEXT CMD...: CMD exits with STATUS and, when TEXT is not
# empty, prints TEXT on stdout or stderr (kept in out.txt and err.txt of the
# current directory).
expect() {
    local want=$1 text=$2 rc=0
    shift 2
    "$@" > out.txt 2> err.txt || rc=$?
    if [ "$rc" -ne "$want" ]; then
        echo "FAIL: '$*' exited $rc, expected $want"; cat out.txt err.txt; exit 1
    fi
    if [ -n "$text" ] && ! grep -qF -- "$text" out.txt err.txt; then
        echo "FAIL: '$*' did not print '$text'"; cat out.txt err.txt; exit 1
    fi
}

#!/usr/bin/env bash
# Every command's --help, `tcbench help COMMAND`, and the general help are
# exactly the committed texts of tests/help/ (byte for byte), and every
# command the general help lists has one: the usage texts cannot get lost
# or change by accident (tests/help/README.md says how to change one).
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"
help="$TCB_SOURCE_DIR/tests/help"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

same() { # same EXPECTED ACTUAL WHAT
    if ! cmp -s "$1" "$2"; then
        echo "FAIL: $3 differs from $1:"; diff "$1" "$2" | head -40; exit 1
    fi
}

expect 0 "" "$TCBENCH" --help;  same "$help/tcbench.txt" out.txt "tcbench --help"
expect 0 "" "$TCBENCH" help;    same "$help/tcbench.txt" out.txt "tcbench help"
expect 2 "" "$TCBENCH";         same "$help/tcbench.txt" err.txt "tcbench (no command, stderr)"
[ ! -s out.txt ] || { echo "FAIL: tcbench alone wrote to stdout"; exit 1; }

# Each committed text is its command's, by all three ways of asking.
n=0
for f in "$help"/*.txt; do
    cmd=$(basename "$f" .txt)
    [ "$cmd" != tcbench ] || continue
    expect 0 "" "$TCBENCH" "$cmd" --help;  same "$f" out.txt "tcbench $cmd --help"
    expect 0 "" "$TCBENCH" "$cmd" -h;      same "$f" out.txt "tcbench $cmd -h"
    expect 0 "" "$TCBENCH" help "$cmd";    same "$f" out.txt "tcbench help $cmd"
    n=$((n + 1))
done
[ "$n" -ge 10 ] || { echo "FAIL: only $n texts in $help"; exit 1; }

# The general help lists exactly the commands that have a text.
listed=$(sed -n '/^commands:/,/^$/s/^  \([a-z]*\) .*/\1/p' "$help/tcbench.txt" | sort)
texts=$(ls "$help" | sed -n 's/\.txt$//p' | grep -vx tcbench | sort)
if [ "$listed" != "$texts" ]; then
    echo "FAIL: the general help's commands and tests/help/ differ:"
    diff <(echo "$listed") <(echo "$texts"); exit 1
fi
echo "ok: $n commands' help as committed"

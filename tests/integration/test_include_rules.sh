#!/usr/bin/env bash
# The include rules of ARCHITECTURE.md hold on the tree (scripts/
# check_includes.py), and the check fails, naming file, line and rule, on
# each kind of violation planted in a copy of the tree: a method importing
# the engine, reports/ importing the command line, a room's private header
# used outside it, the umbrella header in library code, an import cycle
# between rooms through an installed header, a header that does not exist.
set -euo pipefail
: "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"
check="$TCB_SOURCE_DIR/scripts/check_includes.py"
command -v python3 >/dev/null || { echo "SKIP: no python3"; exit 77; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

expect 0 "" python3 "$check" "$TCB_SOURCE_DIR"

# A copy of the tree's sources (what the check reads), for planting.
fresh() {
    rm -rf tree && mkdir tree
    (cd "$TCB_SOURCE_DIR" && git ls-files -z -- '*.c' '*.h' '*.cpp' | xargs -0 cp --parents -t "$tmp/tree")
    expect 0 "" python3 "$check" tree
}
plant() { # plant FILE LINE: FILE gets LINE after its first line
    sed -i "1a $2" "tree/$1"
}

fresh; plant methods/baselines/nearest.c '#include "harness/harness.h"'
expect 1 'methods/baselines/nearest.c:2: includes harness/harness.h: methods/ may not import harness/' python3 "$check" tree

fresh; plant reports/aggregate.c '#include "cli/cli.h"'
expect 1 'reports/aggregate.c:2: includes cli/cli.h: reports/ may not import cli/' python3 "$check" tree

fresh; plant store/cell_read.c '#include "tcb/runner.h"'
expect 1 'store/cell_read.c:2: includes tcb/runner.h: store/ may not import harness/' python3 "$check" tree

fresh; plant views/inspect.c '#include "harness/harness_internal.h"'
expect 1 'views/inspect.c:2: includes harness/harness_internal.h: private to harness/' python3 "$check" tree

fresh; plant bench/train_step.c '#include "config/config_internal.h"'
expect 1 'bench/train_step.c:2: includes config/config_internal.h: private to config/' python3 "$check" tree

fresh; plant metrics/chamfer.c '#include "tcb/tcb.h"'
expect 1 'metrics/chamfer.c:2: includes tcb/tcb.h: library code names the headers it uses' python3 "$check" tree

fresh; plant include/tcb/sequence.h '#include "tcb/results.h"'
expect 1 'include/tcb/sequence.h:2: includes tcb/results.h: datasets/ may not import store/' python3 "$check" tree

fresh; plant core/error.c '#include "core/no_such.h"'
expect 1 'core/error.c:2: includes core/no_such.h: no such header' python3 "$check" tree

# The tests may look inside a room.
fresh; plant tests/unit/test_core.c '#include "harness/harness_internal.h"'
expect 0 "" python3 "$check" tree
echo "ok: the include rules hold, and each planted violation is found"

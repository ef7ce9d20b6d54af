#!/usr/bin/env bash
# The paper's configs (configs/paper/*.json) without their data: each one
# dry-runs, listing its cells and saying how to give the missing roots;
# with a root (--root or TCBENCH_ROOT_<NAME>) the dry run sizes the
# sequence and estimates every cell. Variants choose the seeds, the params
# and the run directory, and a real run lands where the variant says.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
. "$(dirname "${BASH_SOURCE[0]}")/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
for v in $(env | sed -n 's/^\(TCBENCH_ROOT_[A-Z0-9_]*\)=.*/\1/p'); do unset "$v"; done

n=0
for cfg in "$TCB_SOURCE_DIR"/configs/paper/*.json; do
    for variant in cpu paper; do
        expect 0 "cells: " "$TCBENCH" run "$cfg" --variant "$variant" --dry-run --out "$tmp/run"
        grep -qF "no root given (--root " out.txt || { echo "FAIL: $cfg: no hint for the missing root"; cat out.txt; exit 1; }
        [ ! -e "$tmp/run" ] || { echo "FAIL: a dry run of $cfg wrote $tmp/run"; exit 1; }
    done
    n=$((n + 1))
done
[ "$n" -ge 9 ] || { echo "FAIL: only $n paper configs"; exit 1; }

# A stand-in for AMA's crane: the synthetic walk, 8 frames.
"$TCBENCH" datasets synth --out synth --sequence quadruped_walk --frames 8 2> /dev/null
mkdir ama && ln -s "$tmp/synth/quadruped_walk" ama/crane
t5="$TCB_SOURCE_DIR/configs/paper/table5-nricp.json"
# nricp's units measured here, into the run directory's calibration, which
# the dry run reads first (the built-in's coverage: test_calibrate.sh)
expect 0 "wrote $tmp/run/calibration.json" "$TCBENCH" calibrate --only nricp --quick --threads 1 --budget 2 \
    --out "$tmp/run/calibration.json"
expect 0 "ama/crane: 8 frames, " "$TCBENCH" run "$t5" --root ama="$tmp/ama" --dry-run --out "$tmp/run"
grep -qE "^ +3  propagate_deform +0  missing +0(\.0)? s +[0-9.]+ (s|min)  propagate_deform: " out.txt ||
    { echo "FAIL: no estimate for cell 3"; cat out.txt; exit 1; }
grep -qF "cells: 4, 0 finished, 4 to run: about " out.txt || { cat out.txt; exit 1; }
grep -qF "what is unknown" out.txt && { echo "FAIL: unknown estimates with the data present"; cat out.txt; exit 1; }
TCBENCH_ROOT_AMA="$tmp/ama" expect 0 "ama/crane: 8 frames, " "$TCBENCH" run "$t5" --dry-run --only random
[ "$(grep -c " missing " out.txt)" -eq 1 ] || { echo "FAIL: --only listed other cells"; cat out.txt; exit 1; }

# Bad choices are usage errors naming the word.
expect 2 "--variant gpu: unknown (the config has cpu, paper)" "$TCBENCH" run "$t5" --variant gpu --dry-run
expect 2 "--root amma=...: the config has no dataset 'amma'" "$TCBENCH" run "$t5" --root amma=x --dry-run
expect 2 "--root: expected DATASET=DIR, got 'ama'" "$TCBENCH" run "$t5" --root ama --dry-run
expect 2 "--only: $t5 has no method labelled 'nope'" "$TCBENCH" run "$t5" --only nope --dry-run

# A variant's run: its seeds, its params, its own directory.
cat > v.json <<'JSON'
{ "name": "v", "output": "out",
  "evaluation": { "pairs": 20 },
  "variants": { "quick": { "seeds": [0] }, "wide": { "seeds": [1, 2] } },
  "datasets": [ { "name": "ama", "source": "objdir", "sequences": [ { "name": "crane", "role": "validation" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest", "datasets": ["ama"] } ] }
JSON
expect 2 "v.json: datasets[0] (ama): no root given (--root ama=DIR or TCBENCH_ROOT_AMA)" "$TCBENCH" run v.json --quiet
expect 0 "cells: 4 in all, 4 computed" "$TCBENCH" run v.json --variant wide --root ama="$tmp/ama" --quiet
ls out/wide/cells/ama/crane/nearest/seed_1.json out/wide/cells/ama/crane/oracle/seed_2.json > /dev/null
grep -qF '"root":	"'"$tmp/ama"'"' out/wide/config.json || { cat out/wide/config.json; exit 1; }
expect 0 "cells: 2, 0 finished, 2 to run" "$TCBENCH" run v.json --root ama="$tmp/ama" --dry-run
grep -qE "^ +1  nearest +0  missing" out.txt || { cat out.txt; exit 1; }
echo "paper configs test passed"

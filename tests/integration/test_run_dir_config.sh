#!/usr/bin/env bash
# One run directory, one config (issue 18): a run of a config whose cells
# would differ from those of the config the directory holds is refused
# before it writes anything, naming both configs and the first setting that
# differs; the same config still runs there from another data root, under
# another name or thread count, by cells or shards; --force hands the
# directory over; of two configs started at once on a new directory,
# exactly one runs.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/expect.sh"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
"$TCBENCH" datasets synth --out data --sequence quadruped_walk --frames 4 2> /dev/null
cp -a data moved

config() { # NAME THREADS PAIRS FRAMES [MORE KEYS]
    cat <<JSON
{ "name": "$1", "splits_dir": "splits_$3", "cache_dir": "", "seeds": [0, 1], "threads": $2,
  "evaluation": { "pairs": $3, "pool_size": 200, "input_points": 100 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": $4,
                  "sequences": [ { "name": "quadruped_trot", "role": "test" } ] },
                { "name": "files", "source": "objdir", "root": "data",
                  "sequences": [ { "name": "quadruped_walk", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ]${5:-} }
JSON
}
config a 1 3 4 > a.json
config b 1 2 4 > b.json
config c 1 3 5 > c.json
config renamed 2 3 4 > renamed.json
config v 1 3 4 ', "variants": { "one": { "seeds": [0] }, "two": { "seeds": [0, 1] } }' > v.json
"$TCBENCH" run a.json --out run --quiet 2> /dev/null
cp run/config.json a.saved

expect 2 "run/config.json: the run directory holds the cells of another config than b.json (evaluation.pairs: 3 there, 2 here); cells of different settings are not mixed: give this config another --out (or 'tcbench run --force' to recompute" \
    "$TCBENCH" run b.json --out run --quiet
expect 2 "(datasets[0].frames: 4 there, 5 here)" "$TCBENCH" run c.json --out run --cell 0 --quiet
cmp -s run/config.json a.saved || { echo "FAIL: a refused run changed config.json"; exit 1; }
[ "$(find run -newer a.saved -type f | wc -l)" -eq 0 ] || { echo "FAIL: a refused run wrote"; find run -newer a.saved; exit 1; }

# The same cells: another root, name and thread count; cells, shards.
expect 0 "0 computed, 8 already done" "$TCBENCH" run renamed.json --out run --root files=moved --quiet
expect 0 "0 computed, 1 already done" "$TCBENCH" run a.json --out run --cell 3 --quiet
expect 0 "0 computed, 4 already done" "$TCBENCH" run a.json --out run --shard 1/2 --quiet

# Variants are configs of their own.
expect 0 "" "$TCBENCH" run v.json --variant one --out variants --quiet
expect 2 "(seeds: [0] there, [0,1] here)" "$TCBENCH" run v.json --variant two --out variants --quiet

# --force hands the directory over; the other config is then refused.
expect 0 "8 computed" "$TCBENCH" run b.json --out run --force --quiet
expect 2 "than a.json (evaluation.pairs: 2 there, 3 here)" "$TCBENCH" run a.json --out run --quiet

# Two configs at once on a new directory: one claims it, the other is refused.
rc_a=0 rc_b=0
"$TCBENCH" run a.json --out race --quiet 2> race_a.log & pa=$!
"$TCBENCH" run b.json --out race --quiet 2> race_b.log & pb=$!
wait $pa || rc_a=$?
wait $pb || rc_b=$?
[ $((rc_a + rc_b)) -eq 2 ] && [ $((rc_a * rc_b)) -eq 0 ] && grep -qF "another config" race_a.log race_b.log ||
    { echo "FAIL: two configs at once exited $rc_a and $rc_b"; cat race_a.log race_b.log; exit 1; }
echo "run directory config test passed"

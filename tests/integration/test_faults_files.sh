#!/usr/bin/env bash
# Damaged and foreign files in a run (issue 18): a model checkpoint cut
# short, with a flipped bit, another cell's or another config's; a training
# state with a flipped bit or another sequence's; a sequence cache cut
# short, with a flipped bit or another sequence's. Each is refused with a
# warning naming it and recomputed, never used: every cell ends equal to an
# uninterrupted run's.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

enter_temp_dir

for s in quadruped_walk quadruped_trot; do
    "$TCBENCH" datasets synth --out data --sequence $s --frames 4 2> /dev/null
done
config() { # NAME POOL_SIZE ITERATIONS
    cat <<JSON
{ "name": "$1", "splits_dir": "splits", "cache_dir": "cache", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 2, "pool_size": $2, "input_points": 150, "surface_samples": 500 },
  "datasets": [ { "name": "files", "source": "objdir", "root": "data",
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" },
                                 { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "mca", "params": { "preset": "tiny", "iterations": $3, "checkpoint_every": 0 } } ] }
JSON
}
config grid 400 60 > grid.json
config other 500 60 > other.json
"$TCBENCH" run grid.json --out full --quiet
cp -a full run

flip() { /usr/bin/python3 -c 'import sys
b = bytearray(open(sys.argv[1], "rb").read()); b[len(b) // 2] ^= 1; open(sys.argv[1], "wb").write(b)' "$1"; }
cut_half() { truncate -s $(($(stat -c %s "$1") / 2)) "$1"; }
work() { echo "run/work/files/$1/$2/seed_0"; } # SEQUENCE METHOD
cache() { compgen -G "cache/$1-*.h5"; }        # SEQUENCE
# rerun LOG WARNING...: the grid's missing cells recomputed, every warning
# said, and every cell equal to the uninterrupted run's.
rerun() {
    local log=$1 w
    shift
    "$TCBENCH" run grid.json --out run --quiet 2> "$log"
    for w in "$@"; do
        grep -qF -- "warning: $w" "$log" || { echo "FAIL: no warning '$w'"; cat "$log"; exit 1; }
    done
    same_cells full run
}
uncell() { rm "run/cells/files/$1/$2/seed_0.json"; } # SEQUENCE METHOD

# Cut short, a flipped bit: the models' records see both; a cache cut short,
# another sequence's cache.
walk_cache=$(cache quadruped_walk) trot_cache=$(cache quadruped_trot)
walk_mca=$(work quadruped_walk mca) trot_mca=$(work quadruped_trot mca)
uncell quadruped_walk mca; uncell quadruped_trot mca
cut_half "$walk_mca/model.ckpt"
flip "$trot_mca/model.ckpt"
cp "$walk_cache" "$trot_cache"
cut_half "$walk_cache"
rerun damaged.log \
    "$walk_mca/model.ckpt: not reused ($walk_mca/model.ckpt: " \
    "$trot_mca/model.ckpt: not reused ($trot_mca/model.ckpt: its bytes do not hash" \
    "sequence cache not reused: $walk_cache: not a valid tcbench sequence cache" \
    "sequence cache not reused: $trot_cache: stale cache"
grep -qF "bytes, its record $walk_mca/model.ckpt.fit.json says" damaged.log || { cat damaged.log; exit 1; }

# Another cell's model, another config's (another pool size: other input
# clouds), a cache with a flipped bit.
"$TCBENCH" run other.json --out other --cell 1 --quiet
uncell quadruped_walk mca; uncell quadruped_trot mca
cp "$trot_mca/model.ckpt" "$walk_mca/model.ckpt"
cp "$trot_mca/model.ckpt.fit.json" "$walk_mca/model.ckpt.fit.json"
cp other/work/files/quadruped_trot/mca/seed_0/model.ckpt* "$trot_mca/"
flip "$walk_cache"
rerun foreign.log \
    "$walk_mca/model.ckpt: not reused ($walk_mca/model.ckpt.fit.json: made for cell files/quadruped_trot/mca/seed 0, this cell has files/quadruped_walk/mca/seed 0)" \
    "$trot_mca/model.ckpt: not reused (another sequence or other dataset settings: $trot_mca/model.ckpt.fit.json: made for sequence " \
    "sequence cache not reused: $walk_cache: not a valid tcbench sequence cache (checksum mismatch"

# A training state with a flipped bit, another sequence's.
CI= "$TCBENCH" run grid.json --out stopped 2> stop.log &
pid=$!
for _ in $(seq 3000); do grep -qF "mca: " stop.log && break; sleep 0.02; done
kill -TERM "$pid"
rc=0
wait "$pid" || rc=$?
pid=""
state=stopped/work/files/quadruped_walk/mca/seed_0/train.ckpt
foreign=stopped/work/files/quadruped_trot/mca/seed_0/train.ckpt
[ "$rc" -eq 75 ] && [ -s "$state" ] || { echo "FAIL: no training state (exit $rc)"; cat stop.log; exit 1; }
mkdir -p "$(dirname "$foreign")"
cp "$state" "$foreign"
flip "$state"
"$TCBENCH" run grid.json --out stopped --quiet 2> states.log
for w in "mca: not resumed ($state: checksum mismatch (corrupted file)); training from the start" \
         "mca: not resumed ($foreign: made by another training: sequence fingerprint is "; do
    grep -qF -- "warning: $w" states.log || { echo "FAIL: no warning '$w'"; cat states.log; exit 1; }
done
same_cells full stopped
echo "damaged and foreign files test passed"

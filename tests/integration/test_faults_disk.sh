#!/usr/bin/env bash
# A full disk and a read-only run directory (issue 18), on a small tmpfs
# mounted by the test (root only; skipped, saying why, where mounting is
# not permitted):
# - a disk that fills up mid-run stops the run with an error naming the
#   file it could not write; every cell file present is whole and right;
#   given room, the rerun finishes equal to an uninterrupted run;
# - a disk too small for a training's checkpoints costs only the
#   checkpoints (warnings): the training goes on and its cell is right;
# - a read-only run directory, or only its cells/, stops the run naming the
#   path and leaves it as it was; made writable, the rerun finishes.
set -euo pipefail
: "${TCBENCH:?}" "${TCB_SOURCE_DIR:?}"
source "$TCB_SOURCE_DIR/tests/integration/cells.sh"

tmp=$(mktemp -d)
trap 'umount "$tmp/mnt/run/cells" 2>/dev/null || true; umount "$tmp/mnt" 2>/dev/null || true; rm -rf "$tmp"' EXIT
cd "$tmp"
mkdir mnt
if [ "$(id -u)" -ne 0 ] || ! mount -t tmpfs -o size=1m tmpfs mnt 2> mount.err; then
    echo "SKIP: no tmpfs can be mounted here (uid $(id -u): $(cat mount.err)); the full and read-only disks are not tested"
    exit 77
fi

cat > cells.json <<'JSON'
{ "name": "disk", "splits_dir": "splits", "cache_dir": "", "seeds": [0, 1], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 400, "input_points": 150, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 4,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" },
                                 { "name": "quadruped_trot", "role": "test" } ] } ],
  "methods": [ { "name": "oracle" }, { "name": "nearest" } ] }
JSON
cat > train.json <<'JSON'
{ "name": "disk_train", "splits_dir": "splits", "cache_dir": "", "seeds": [0], "threads": 1,
  "evaluation": { "pairs": 4, "pool_size": 400, "input_points": 150, "surface_samples": 500 },
  "datasets": [ { "name": "synth", "source": "synthetic", "frames": 4,
                  "sequences": [ { "name": "quadruped_walk", "role": "validation" } ] } ],
  "methods": [ { "name": "mca", "params": { "preset": "tiny", "iterations": 20, "checkpoint_every": 5 } } ] }
JSON
# The uninterrupted runs, on the tmpfs: what their files take there.
"$TCBENCH" run cells.json --out mnt/run --quiet
"$TCBENCH" run train.json --out mnt/train --quiet
cells_kb=$(du -sk mnt/run | cut -f1)
cell_kb=$(du -sk mnt/train/cells | cut -f1)
ckpt_kb=$(du -sk mnt/train/work | cut -f1)
cp -a mnt/run full
cp -a mnt/train full_train
umount mnt

# A disk that fills up midway.
mount -t tmpfs -o size=$((cells_kb / 2))k tmpfs mnt
rc=0
"$TCBENCH" run cells.json --out mnt/run --quiet 2> full.log || rc=$?
[ "$rc" -eq 2 ] && grep -q "^tcbench: mnt/run/.*No space left on device" full.log ||
    { echo "FAIL: a full disk: exit $rc, expected 2 and a message naming the file"; cat full.log; exit 1; }
cells_within full mnt/run
[ -z "$(find mnt -name '*.tmp-*' -o -name '*.lock*')" ] || { echo "FAIL: debris on the full disk"; find mnt; exit 1; }
mount -o remount,size=$((2 * cells_kb))k mnt
"$TCBENCH" run cells.json --out mnt/run --quiet 2> room.log
grep -qF "already done" room.log || { cat room.log; exit 1; }
same_cells full mnt/run
umount mnt

# Room for the cell and the run's small files, not for a checkpoint.
mount -t tmpfs -o size=$((cell_kb + 64))k tmpfs mnt
[ "$ckpt_kb" -gt $((cell_kb + 64)) ] || { echo "FAIL: the checkpoints ($ckpt_kb KiB) would fit"; exit 1; }
"$TCBENCH" run train.json --out mnt/train 2> train.log
grep -qF "warning: mca: training state not saved: " train.log && grep -qF "warning: checkpoint not saved: " train.log ||
    { echo "FAIL: the lost checkpoints were not said"; cat train.log; exit 1; }
same_cells full_train mnt/train
umount mnt

# Read-only: the whole run directory, then only its cells.
mount -t tmpfs -o size=$((2 * cells_kb))k tmpfs mnt
cp -a full mnt/run
rm mnt/run/cells/synth/quadruped_trot/nearest/seed_*.json
before=$(cd mnt && find run -type f -exec md5sum {} + | sort)
mount -o remount,ro mnt
rc=0
"$TCBENCH" run cells.json --out mnt/run --quiet 2> ro.log || rc=$?
[ "$rc" -eq 2 ] && grep -q "^tcbench: mnt/run/.*Read-only file system" ro.log ||
    { echo "FAIL: a read-only run directory: exit $rc, expected 2 and a message naming the path"; cat ro.log; exit 1; }
mount -o remount,rw mnt
mount --bind mnt/run/cells mnt/run/cells
mount -o remount,bind,ro mnt/run/cells
rc=0
"$TCBENCH" run cells.json --out mnt/run --quiet 2> ro_cells.log || rc=$?
[ "$rc" -eq 2 ] && grep -q "^tcbench: mnt/run/cells/synth/quadruped_trot/nearest/.*Read-only file system" ro_cells.log ||
    { echo "FAIL: read-only cells: exit $rc, expected 2 and a message naming the path"; cat ro_cells.log; exit 1; }
umount mnt/run/cells
[ "$before" = "$(cd mnt && find run -type f -exec md5sum {} + | sort)" ] ||
    { echo "FAIL: the read-only runs changed the run directory"; exit 1; }
"$TCBENCH" run cells.json --out mnt/run --quiet 2> rw.log
grep -qF "2 computed" rw.log || { cat rw.log; exit 1; }
same_cells full mnt/run
echo "full and read-only disk test passed"

#!/usr/bin/env python3
"""A command for the external method's tests (test_external.sh): MODE STEP
MANIFEST, and in every mode but the failing ones it is nearest (frame i's
vertices as float32 points), so its cells can be compared with nearest's.

  oracle          ids 0..V-1 as int64: oracle's predictions
  recon           nearest, plus reconstructions: 300 pool samples per frame
  partial_recon   reconstructions for every pair but pair 2
  fail            fit prints 15 lines, odd ones to stderr, and exits 2
  diverge         fit exits 3 (the protocol's "diverged")
  sleep           fit starts `sleep 60` and waits (pids in model/pids)
  stubborn        the same, both ignoring SIGTERM
  stop_fit        the first fit waits as `sleep`, and on SIGTERM writes
                  model/saved and exits; later fits finish at once
  stop_transfer   the first transfer waits as `sleep`
  malformed       pair 0's file is text, not .npy
  missing         pair 3 has no file
"""
import json
import os
import signal
import subprocess
import sys

mode, step, manifest = sys.argv[1:4]
with open(manifest) as f:
    m = json.load(f)
model = m["model_dir"]


def first_time(name):
    path = os.path.join(model, name)
    first = not os.path.exists(path)
    open(path, "a").close()
    return first


def wait_in_child():
    child = subprocess.Popen(["sleep", "60"])
    with open(os.path.join(model, "pids"), "w") as f:
        f.write("%d %d\n" % (os.getpid(), child.pid))
    print("waiting", flush=True)
    child.wait()


def on_term(*_):
    open(os.path.join(model, "saved"), "w").close()
    sys.exit(1)


def fit():
    if mode == "fail":
        for n in range(1, 16):
            print("line %d" % n, file=sys.stderr if n % 2 else sys.stdout)
        sys.exit(2)
    if mode == "diverge":
        print("loss is nan")
        sys.exit(3)
    if mode == "stubborn":
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    if mode == "stop_fit" and first_time("fit_started"):
        signal.signal(signal.SIGTERM, on_term)
    elif mode not in ("sleep", "stubborn"):
        return
    wait_in_child()


def transfer():
    import numpy as np  # here, not above: fit starts fast, before the tests' time limits

    if mode == "stop_transfer" and first_time("transfer_started"):
        wait_in_child()
    frames = np.load(m["frames"])
    pools = np.load(m["pools"])
    out = m["out_dir"]
    for k, i, j in np.load(m["pairs"]):
        path = os.path.join(out, "%d.npy" % k)
        if mode == "missing" and k == 3:
            continue
        if mode == "malformed" and k == 0:
            with open(path, "w") as f:
                f.write("not an array\n")
            continue
        np.save(path, np.arange(frames.shape[1], dtype=np.int64) if mode == "oracle" else frames[i])
        if mode == "recon" or (mode == "partial_recon" and k != 2):
            np.save(os.path.join(out, "recon_%d_i.npy" % k), pools[i][:300])
            np.save(os.path.join(out, "recon_%d_j.npy" % k), pools[j][:300])


fit() if step == "fit" else transfer()

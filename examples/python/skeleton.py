#!/usr/bin/env python3
"""The smallest tcbench method in Python: copy this file and fill in fit()
and predict() (docs/adding-a-method.md, "A method in any language").

tcbench runs it twice per cell, as  COMMAND... fit MANIFEST  and then
COMMAND... transfer MANIFEST  (the last two arguments; your own may come
before them in the config's "command" list). MANIFEST is a JSON file naming
the sequence's .npy files, the seed, the thread budget, a model directory,
and for transfer the pairs and where the predictions go. A non-zero exit
fails the cell (exit 3: the training diverged); what you print goes to the
cell's external.log, and its last lines into the failure's message.

List it as  "command": ["path/to/skeleton.py"]: a .py command runs under
the params' "python", else $TCBENCH_PYTHON (say, the venv with your torch),
else python3 from PATH; the log and every failure name the one that ran.

As it stands it is tcbench's `nearest` baseline: every vertex of frame i
stays where it is, and tcbench projects it onto frame j's nearest vertex.
The test suite checks that its cell is bit-identical to nearest's.
"""
import json
import os
import sys

import numpy as np


def fit(m, frames, faces):
    """Learn from the whole sequence; keep what you learn in m["model_dir"].

    frames: (F, V, 3) float32, tcbench's normalized coordinates; faces:
    (T, 3) int32; np.load(m["pools"]) (when not None): (F, P, 3) float32
    surface samples per frame, of which a method draws m["input_points"].
    Vertex ids correspond across frames, but a method must not use that:
    it is what the benchmark measures. With PyTorch, for example:
        torch.manual_seed(m["seed"]); torch.set_num_threads(m["threads"])
        ... train ...
        torch.save(net.state_dict(), os.path.join(m["model_dir"], "net.pt"))
    On SIGTERM (a stop request or the timeout), save and exit; the next fit
    may continue from model_dir.
    """


def predict(m, frames, i, j):
    """Frame i's vertices carried onto frame j: (V, 3) points (float32 or
    float64), or (V,) integer vertex ids of frame j. With PyTorch: load
    net.pt from m["model_dir"] once, outside the loop, and run it here."""
    return frames[i]


def main():
    step, manifest = sys.argv[-2], sys.argv[-1]
    with open(manifest) as f:
        m = json.load(f)
    frames = np.load(m["frames"])
    faces = np.load(m["faces"])
    if step == "fit":
        fit(m, frames, faces)
    elif step == "transfer":
        # Rows (k, i, j): pair k of the split maps frame i to frame j.
        for k, i, j in np.load(m["pairs"]):
            np.save(os.path.join(m["out_dir"], "%d.npy" % k), predict(m, frames, i, j))
    else:
        sys.exit("unknown step %r" % step)


if __name__ == "__main__":
    main()

"""What bench_train_step's PyTorch peers share: torch and their reference
module from tests/pytorch (exit 77, and a message on stderr, when either
cannot be imported: the bench then prints n/a), and the timing they
print, one line "<mean ms per step> <peak RSS of this process in KiB>"."""
import importlib
import os
import resource
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def import_reference(name):
    """(torch, the module tests/pytorch/<name>.py)."""
    sys.path.insert(0, os.path.join(HERE, "..", "tests", "pytorch"))
    try:
        import torch

        return torch, importlib.import_module(name)
    except ImportError as exc:
        print(f"unavailable: {exc}", file=sys.stderr)
        sys.exit(77)


def time_steps(step, warmup, iters):
    """`warmup` untimed calls of step(), then `iters` timed ones; prints
    the line."""
    for _ in range(warmup):
        step()
    t0 = time.perf_counter()
    for _ in range(iters):
        step()
    ms = (time.perf_counter() - t0) * 1e3 / iters
    print(f"{ms:.3f} {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}")

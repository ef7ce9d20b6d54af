"""What bench_train_step's PyTorch peers share: torch and their reference
modules from tests/pytorch (exit 77, and a message on stderr, when one
cannot be imported: the bench then prints n/a), the allocator's setting,
a mesh's edges, and the timing they print, one line "<mean ms per step> <peak RSS of this process
in KiB>"."""
import ctypes
import importlib
import os
import resource
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def import_reference(*names):
    """(torch, the modules `names`): tests/pytorch/<name>.py, or any other
    module a peer needs (scipy's)."""
    sys.path.insert(0, os.path.join(HERE, "..", "tests", "pytorch"))
    try:
        import torch

        return (torch,) + tuple(importlib.import_module(name) for name in names)
    except ImportError as exc:
        print(f"unavailable: {exc}", file=sys.stderr)
        sys.exit(77)


def keep_freed_memory():
    """Has glibc keep freed memory for reuse. It hands every freed block
    over 32 MiB back to the kernel, so that each new distance matrix of a
    nearest-neighbour search (tens to hundreds of MB) is faulted in page by
    page again: most of an epoch on a loaded 2-core machine. PyTorch's CPU
    tuning guide swaps in a caching allocator (jemalloc, tcmalloc) for
    this; mallopt does it without one."""
    libc = ctypes.CDLL("libc.so.6")
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    libc.mallopt(M_MMAP_THRESHOLD, 1 << 30)
    libc.mallopt(M_TRIM_THRESHOLD, 1 << 30)


def start(torch, threads, seed=None):
    """What every peer does first: torch on `threads` threads, freed memory
    kept (keep_freed_memory), torch's generator seeded unless seed is None."""
    torch.set_num_threads(threads)
    keep_freed_memory()
    if seed is not None:
        torch.manual_seed(seed)


def edges(faces):
    """The undirected edges [ne][2] (smaller index first, each once) of
    the triangles faces [nf][3] (a long tensor)."""
    return faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2).sort(1).values.unique(dim=0)


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

"""Checks the Python integration tests share (python_env.sh puts this
directory on their PYTHONPATH)."""

import numpy as np


def same(a, b, at="$"):
    """Equal JSON values, floats to the bit (nan for null in the arrays);
    numpy arrays of one dtype and shape, bit for bit."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        bits = {4: np.uint32, 8: np.uint64}[a.dtype.itemsize]
        assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a.view(bits), b.view(bits)), at
    elif isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, (int, float)) and isinstance(b, (int, float)), (at, a, b)
        assert float(a).hex() == float(b).hex(), (at, a, b)
    elif isinstance(a, dict):
        assert sorted(a) == sorted(b), (at, sorted(a), sorted(b))
        for k in a:
            same(a[k], b[k], f"{at}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), (at, len(a), len(b))
        for k, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{at}[{k}]")
    else:
        assert type(a) == type(b) and a == b, (at, a, b)


def raises(kind, text, f, *args, **kw):
    """f(*args, **kw) raises kind with text in its message; the exception."""
    try:
        f(*args, **kw)
    except kind as e:
        assert text in str(e), (str(e), text)
        return e
    raise AssertionError(f"no {kind.__name__}: {text}")

"""Finding and loading libtcbench, and calling it.

The library is found, in order:

1. ``TCBENCH_LIB``: the path of the shared library; when set, nothing else
   is tried (a wrong path is an error, not a fallback to another build).
2. The bundled copy: ``libtcbench.so`` beside these modules, which
   ``pip install .`` puts there (setup.py builds it).
3. A package installed by ``cmake --install`` has a generated ``_installed``
   module naming the library relative to the package: the library that was
   installed with it. A package without one is a source checkout's
   python/tcbench, whose library is ``build/libtcbench.so`` beside
   ``python/`` (CMake's default build directory).
4. ``ctypes.util.find_library("tcbench")``: the system's library path.

The library that comes with the package (2, 3) goes before any other, so
an installed package never picks up a stray build; a checkout's build/ is
tried only for a package that came with none.

Only tcb_error is mirrored as a ctypes struct, checked against the layout
the library reports (tcb_binding_info); everything else crosses as JSON
text, named arrays and plain pointers (include/tcb/binding.h says why).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import json
import os
from pathlib import Path

import numpy as np

ENV_VAR = "TCBENCH_LIB"
# The bundled copy's name (setup.py's BUNDLED).
BUNDLED = "libtcbench.so"
ERRMSG_MAX = 1024


class TcbError(RuntimeError):
    """An error reported by libtcbench: its message, and its status name
    (``code``: "input", "io", "nomem", ...)."""

    def __init__(self, message: str, code: str) -> None:
        super().__init__(message)
        self.code = code


class _Error(ctypes.Structure):
    _fields_ = [("code", ctypes.c_int), ("msg", ctypes.c_char * ERRMSG_MAX)]


def _candidates() -> list[tuple[str, Path | str]]:
    """(how it was found, path) in the order tried."""
    explicit = os.environ.get(ENV_VAR)
    if explicit:
        return [(ENV_VAR, Path(explicit))]
    here = Path(__file__).resolve().parent
    out: list[tuple[str, Path | str]] = [("bundled", here / BUNDLED)]
    try:
        from . import _installed  # written by `cmake --install`
        out.append(("installed", here / _installed.LIBRARY))
    except ImportError:
        out.append(("build tree", here.parent.parent / "build" / "libtcbench.so"))
    system = ctypes.util.find_library("tcbench")
    if system:
        out.append(("system", system))
    return out


def _prototype(lib: ctypes.CDLL, name: str, restype, *argtypes) -> None:
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)


def _declare(lib: ctypes.CDLL) -> None:
    err = ctypes.POINTER(_Error)
    f32 = np.ctypeslib.ndpointer(np.float32, flags="C_CONTIGUOUS")
    i32 = np.ctypeslib.ndpointer(np.int32, flags="C_CONTIGUOUS")
    f64 = np.ctypeslib.ndpointer(np.float64, flags="C_CONTIGUOUS,WRITEABLE")
    text, ptr, c_int = ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int
    _prototype(lib, "tcb_binding_info", ptr)
    _prototype(lib, "tcb_binding_free", None, ptr)
    _prototype(lib, "tcb_status_name", text, c_int)
    _prototype(lib, "tcb_pck_threshold", ctypes.c_double, c_int)
    _prototype(lib, "tcb_binding_pair_metrics", c_int, f32, c_int, i32, f64, f64, f64, c_int, f64, c_int, err)
    _prototype(lib, "tcb_binding_split_json", ptr, text, err)
    _prototype(lib, "tcb_binding_cell_json", ptr, text, err)
    _prototype(lib, "tcb_binding_sequence_load", ptr, text, text, text, text, err)
    _prototype(lib, "tcb_binding_sequence_free", None, ptr)
    _prototype(lib, "tcb_binding_sequence_json", ptr, ptr, err)
    _prototype(lib, "tcb_binding_sequence_copy", c_int, ptr, text, ptr, ctypes.c_size_t, err)


class Library:
    """The loaded libtcbench: its path, its info (tcb_binding_info) and the
    C functions, with the error handling every call shares."""

    def __init__(self, lib: ctypes.CDLL, path: str) -> None:
        self.c = lib
        self.path = path
        _declare(lib)
        self.info = json.loads(self.take_text(lib.tcb_binding_info()))
        layout = self.info["tcb_error"]
        mine = {"size": ctypes.sizeof(_Error), "msg_offset": _Error.msg.offset, "msg_size": ERRMSG_MAX}
        if layout != mine:
            raise ImportError(f"{path}: tcb_error is {layout}, this binding mirrors {mine}")

    def take_text(self, pointer: int | None) -> str:
        """The C string at pointer, released; None means out of memory."""
        if not pointer:
            raise MemoryError("libtcbench: out of memory")
        try:
            return ctypes.string_at(pointer).decode()
        finally:
            self.c.tcb_binding_free(pointer)

    def fail(self, err: _Error) -> TcbError:
        return TcbError(err.msg.decode(errors="replace"), self.c.tcb_status_name(err.code).decode())

    def call(self, name: str, *args):
        """Calls a function that reports through a trailing tcb_error: its
        result, or TcbError with the C message when it returned non-zero
        (an int) or NULL (a pointer)."""
        err = _Error()
        f = getattr(self.c, name)
        result = f(*args, ctypes.byref(err))
        failed = not result if f.restype is ctypes.c_void_p else result != 0
        if failed:
            raise self.fail(err)
        return result

    def text(self, name: str, *args) -> str:
        """A function returning malloc'ed JSON text, parsed."""
        return json.loads(self.take_text(self.call(name, *args)))


@functools.lru_cache(maxsize=None)
def library() -> Library:
    """The library, loaded once per process."""
    tried = []
    for how, path in _candidates():
        is_path = isinstance(path, Path)
        if is_path and not path.exists():
            tried.append(f"{how}: {path} (no such file)")
            continue
        try:
            return Library(ctypes.CDLL(str(path)), str(path))
        except OSError as e:
            if how == ENV_VAR:
                raise ImportError(f"{ENV_VAR}={path}: {e}") from e
            tried.append(f"{how}: {path} ({e})")
    raise ImportError("libtcbench not found; tried " + "; ".join(tried) +
                      f". Set {ENV_VAR} to the path of libtcbench.so.")


def path_bytes(p: str | os.PathLike) -> bytes:
    return os.fsencode(os.fspath(p))

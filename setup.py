"""`pip install .` from the repository root: the Python binding (python/tcbench)
with its own copy of libtcbench, as pycocotools ships its compiled C core
inside its package. The build step runs CMake (the library target only, a
Release build, no tests) and puts libtcbench.so beside the package's modules,
where python/tcbench/_lib.py looks for it; the installed package then needs
no checkout, PYTHONPATH or TCBENCH_LIB.

Offline, with Debian's setuptools and numpy (python/README.md):

    python3 -m venv --system-site-packages venv
    venv/bin/pip install --no-build-isolation .

TCBENCH_CMAKE_BUILD_DIR: build the library in this CMake build directory of
tcbench's sources instead of the pip build's own (build/pip/); when it is
configured already its settings are kept and only the library target is
brought up to date (the test suite reuses its build this way).
"""

import os
import re
import shutil
import subprocess
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
# The file name _lib.py looks for beside the package's modules.
BUNDLED = "libtcbench.so"
BUILD_DIR_VAR = "TCBENCH_CMAKE_BUILD_DIR"


def version() -> str:
    """The version CMake's project() declares: one number for both."""
    m = re.search(r"project\(tcbench VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not m:
        raise RuntimeError("CMakeLists.txt: no `project(tcbench VERSION x.y.z)`")
    return m.group(1)


def build_library(build_dir: Path) -> Path:
    """libtcbench built in build_dir (configured first when it is not)."""
    if not (build_dir / "CMakeCache.txt").exists():
        subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                        "-DTCB_BUILD_TESTS=OFF"], check=True)
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
    subprocess.run(["cmake", "--build", str(build_dir), "--target", "tcbench_lib", "--parallel", jobs], check=True)
    lib = build_dir / "libtcbench.so"
    if not lib.exists():
        raise RuntimeError(f"{lib}: CMake's tcbench_lib target did not make it")
    return lib


class BuildPyWithLibrary(build_py):
    """The package's modules, then the library copied in beside them (the
    file itself, not the symlink chain libtcbench.so -> .so.0 -> .so.0.1.0)."""

    def run(self) -> None:
        super().run()
        explicit = os.environ.get(BUILD_DIR_VAR)
        build_dir = Path(explicit) if explicit else Path(self.get_finalized_command("build").build_temp) / "cmake"
        lib = build_library(build_dir.resolve())
        target = Path(self.build_lib) / "tcbench" / BUNDLED
        shutil.copyfile(lib, target)
        target.chmod(0o755)


class BinaryDistribution(Distribution):
    """The wheel carries a compiled library: tagged for this platform and
    Python, installed to platlib (a pure wheel would claim any)."""

    def has_ext_modules(self) -> bool:
        return True


setup(
    version=version(),
    cmdclass={"build_py": BuildPyWithLibrary},
    distclass=BinaryDistribution,
    # pip's in-tree build under build/pip/, beside (not into) the CMake build/.
    options={"build": {"build_base": "build/pip"}},
)

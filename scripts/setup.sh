#!/usr/bin/env bash
# Install the Debian packages tcbench needs, if any are missing. Safe to rerun:
# it only calls apt-get when something is absent.
#   scripts/setup.sh           what building and running tcbench needs
#   scripts/setup.sh --tests   also the references the test suite compares
#                              against (PyTorch for the atlas cross-checks)
set -euo pipefail

packages=(
  gcc make cmake pkg-config git           # toolchain
  libcjson-dev                            # configs and results (JSON)
  libflann-dev liblz4-dev                 # k-NN (FLANN's C API; its headers want lz4)
  libhdf5-dev                             # binary sequence cache
  libcairo2-dev fonts-dejavu-core         # PNG plots with text
  zlib1g-dev                              # .npz results files (deflate, CRC-32)
  libopenblas-openmp-dev                  # dense linear algebra (the OpenMP build: one thread pool)
  libopen3d-dev                           # meshing/: screened Poisson, quadric decimation, normals (Open3D 0.16)
  libsuitesparse-dev                      # meshing/: CHOLMOD's sparse Cholesky (Large-Steps systems)
  libcgal-dev                             # meshing/: CGAL's isotropic remeshing (PDG's template)
  tetgen                                  # meshing/: the tetgen program fills DynoSurf's grid (a subprocess)
  libcmocka-dev                           # unit-test framework
  python3 python3-numpy python3-scipy     # tests: JSON comparisons, scipy reference for linear assignment
  python3-pip python3-venv python3-setuptools python3-wheel  # `pip install .` of the Python binding, offline
)
if [ "${1:-}" = "--tests" ]; then
  packages+=(python3-torch)               # the atlas network and training step against PyTorch
  packages+=(slurm-wlm munge)             # the one-node Slurm cluster of tests/integration/test_slurm.sh
  packages+=(clang libclang-rt-dev libomp-dev) # the fuzz targets (fuzz/): clang's libFuzzer and sanitizers, its OpenMP
elif [ $# -gt 0 ]; then
  echo "usage: scripts/setup.sh [--tests]" >&2; exit 2
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "tcbench setup: installing ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "tcbench setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null

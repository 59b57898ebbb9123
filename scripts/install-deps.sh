#!/usr/bin/env bash
# Installs motionfield's build and test dependencies from Debian's packages.
# Idempotent: it installs only what is missing and runs `apt-get update` only then.
set -euo pipefail

packages=(
  build-essential cmake ccache pkg-config xz-utils tar
  libtorch-dev          # libtorch 1.13, CPU
  libgloo-dev           # gloo headers: libtorch's c10d ProcessGroupGloo.hpp includes them (data-parallel training, training/data_parallel.h)
  libceres-dev          # Ceres solver (L-BFGS driver for the latent solvers)
  libeigen3-dev
  libgtest-dev
  nlohmann-json3-dev    # JSON: rig map and rig anatomy files
  libcli11-dev          # CLI11 (header-only): argument parsing of the trainer, the benchmarks and the tools
  libarchive-dev        # libarchive: reads the training archives (.tar, .tar.xz, .tar.gz) without spawning tar
  libopenblas0-pthread  # BLAS for libtorch and Eigen: ~3x faster than ATLAS here (docs/BLAS.md)
  python3 python3-numpy # the Python binding's tests
  python3-venv python3-pip python3-setuptools python3-wheel  # `pip install ./python` into a venv without network (README, capi_python_venv test)
  python3-distributed   # Dask: `python3 -m motionfield.dask` runs batch files on a cluster (python_dask_batch test)
  blender               # the Blender add-on's headless tests (capi_blender_addon*, integrations/blender); Debian's 3.4 runs on the system python3
  xvfb xauth            # a virtual display (xvfb-run): the add-on's panels drawn in a real Blender window and screenshotted (capi_blender_panel)
  libtinygltf-dev       # tinygltf 2.7: glTF 2.0 output (prior/motion/motion_gltf.cc) and reading it back in the tests
  libassimp-dev         # assimp 5.2: FBX input (prior/motion/fbx_reader.cc), Debian's maintained FBX reader
  nodejs                # runs the Khronos glTF validator (npm gltf-validator) in the gltf_validator_* tests
)
# npm installs that validator (scripts/install-gltf-validator.sh). NodeSource's
# nodejs package bundles its own npm and conflicts with Debian's: ask for
# Debian's only when there is no npm.
if ! command -v npm >/dev/null 2>&1; then packages+=(npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all dependencies present"
else
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# libtorch and Eigen call the libblas.so.3 alternative; make sure it is OpenBLAS
# (measured in docs/BLAS.md) and not the generic ATLAS/reference build.
openblas=/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3
current=$(readlink -f /etc/alternatives/libblas.so.3-x86_64-linux-gnu 2>/dev/null || true)
if [ -e "$openblas" ] && [ "$current" != "$(readlink -f $openblas)" ]; then
  echo "install-deps: selecting OpenBLAS as the libblas.so.3 alternative"
  SUDO=""; if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO update-alternatives --set libblas.so.3-x86_64-linux-gnu "$openblas"
  lapack=/usr/lib/x86_64-linux-gnu/openblas-pthread/liblapack.so.3
  if [ -e "$lapack" ]; then $SUDO update-alternatives --set liblapack.so.3-x86_64-linux-gnu "$lapack" || true; fi
fi

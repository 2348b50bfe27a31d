#!/usr/bin/env bash
# Install the PETSc/SLEPc backend of tmfem into a venv (default .venv).
#
# Debian bookworm ships PETSc 3.18.5 / SLEPc 3.18.2 prebuilt with MUMPS, SuperLU_dist,
# hypre and ScaLAPACK. Debian's own python3-petsc4py is built against numpy 1.24 and fails
# with numpy 2, so we build petsc4py==3.18.5 and slepc4py==3.18.2 against the Debian
# libraries in a separate build venv (setuptools<70 and cython<3, which the 3.18 sources
# need, never touch the project's venv), cache the wheels in ~/.cache/tmfem/wheels and
# install them --no-deps --ignore-installed. First set-up: apt + build, minutes; later
# set-ups: seconds (apt check + cached wheels).
#
# usage: scripts/install_petsc.sh [VENV]     (TMFEM_WHEEL_CACHE overrides the cache)
set -euo pipefail
VENV=${1:-.venv}
PETSC_VERSION=3.18.5
SLEPC_VERSION=3.18.2
MPI4PY_VERSION=3.1.6     # against the system Open MPI (mpicc), for rank-collective errors
PETSC_ARCH_DIR=/usr/lib/petscdir/petsc3.18/x86_64-linux-gnu-real
SLEPC_ARCH_DIR=/usr/lib/slepcdir/slepc3.18/x86_64-linux-gnu-real
CACHE=${TMFEM_WHEEL_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/tmfem/wheels}
PY=$VENV/bin/python
[ -x "$PY" ] || { echo "tmfem: install_petsc.sh: expected a venv at $VENV, found none" >&2; exit 1; }

# 1. Debian libraries (only the missing ones)
need=()
for pkg in libpetsc-real3.18-dev libslepc-real3.18-dev libopenblas0-pthread openmpi-bin; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "tmfem: the PETSc backend needs ${need[*]} (Debian bookworm) and there is no apt-get;" \
         "on other platforms see docs/guides/backends.md (conda-forge petsc4py slepc4py)" >&2
    exit 1
  fi
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "tmfem: installing PETSc/SLEPc libraries: ${need[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi
# MUMPS calls the BLAS that libblas.so.3 resolves to: make sure it is OpenBLAS, not the
# reference BLAS (4x slower factorisations)
blas=$(readlink -f "$(ldconfig -p | awk '/libblas\.so\.3 .*x86-64/ {print $NF; exit}')" || true)
case "$blas" in
  *openblas*) ;;
  *) echo "tmfem: warning: libblas.so.3 is $blas, not OpenBLAS; MUMPS will be slow" \
          "(update-alternatives --config libblas.so.3-x86_64-linux-gnu)" >&2 ;;
esac

# 2. wheels, built once per Python version and cached
pytag=$($PY -c 'import sys; print(f"cp{sys.version_info[0]}{sys.version_info[1]}")')
mkdir -p "$CACHE"
have() { ls "$CACHE"/"$1"-"$2"-"$pytag"-*.whl >/dev/null 2>&1; }
if ! have petsc4py $PETSC_VERSION || ! have slepc4py $SLEPC_VERSION || ! have mpi4py $MPI4PY_VERSION; then
  build=$CACHE/../buildenv-$pytag
  echo "tmfem: building petsc4py $PETSC_VERSION, slepc4py $SLEPC_VERSION and mpi4py $MPI4PY_VERSION wheels (about 5 min on 2 cores)"
  [ -x "$build/bin/python" ] || "$(readlink -f "$PY")" -m venv "$build"
  "$build/bin/python" -m pip install --quiet "setuptools<70" "cython<3" wheel \
      "numpy==$($PY -c 'import numpy; print(numpy.__version__)')"
  export PETSC_DIR=$PETSC_ARCH_DIR SLEPC_DIR=$SLEPC_ARCH_DIR PETSC_ARCH=
  if ! have petsc4py $PETSC_VERSION; then
    "$build/bin/python" -m pip wheel --quiet --no-build-isolation --no-deps \
        -w "$CACHE" "petsc4py==$PETSC_VERSION"
  fi
  if ! have mpi4py $MPI4PY_VERSION; then
    "$build/bin/python" -m pip wheel --quiet --no-build-isolation --no-deps --no-binary mpi4py \
        -w "$CACHE" "mpi4py==$MPI4PY_VERSION"
  fi
  # slepc4py compiles against petsc4py's headers
  "$build/bin/python" -m pip install --quiet --no-deps --ignore-installed \
      "$CACHE"/petsc4py-$PETSC_VERSION-$pytag-*.whl
  if ! have slepc4py $SLEPC_VERSION; then
    "$build/bin/python" -m pip wheel --quiet --no-build-isolation --no-deps \
        -w "$CACHE" "slepc4py==$SLEPC_VERSION"
  fi
fi

# 3. install into the project's venv (--ignore-installed: a Debian copy on sys.path must
# not make pip skip ours; --no-deps: numpy stays the venv's own)
"$PY" -m pip install --quiet --no-deps --ignore-installed \
    "$CACHE"/petsc4py-$PETSC_VERSION-$pytag-*.whl "$CACHE"/slepc4py-$SLEPC_VERSION-$pytag-*.whl \
    "$CACHE"/mpi4py-$MPI4PY_VERSION-$pytag-*.whl
"$PY" -c 'from mpi4py import MPI; from petsc4py import PETSc; from slepc4py import SLEPc
print("tmfem: PETSc backend ready: PETSc %d.%d.%d, SLEPc %d.%d.%d" % (PETSc.Sys.getVersion() + SLEPc.Sys.getVersion()))'

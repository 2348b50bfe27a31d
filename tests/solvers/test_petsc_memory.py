"""Memory that a run under the PETSc backend gives back to the system.

Source of the expected numbers: the size of the array itself (a freed 256 MB block must
leave the resident set, as it does in a process that has not loaded PETSc; a freed 8 MB block
stays under tmfem's thresholds and leaves under a user's 1 MB ``GLIBC_TUNABLES`` threshold, as
glibc documents for ``mmap_threshold``), measured on /proc/self/status in a fresh interpreter.
"""
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

try:
    import petsc4py  # noqa: F401
    import slepc4py  # noqa: F401
    HAVE_PETSC = True
except ImportError:
    HAVE_PETSC = False

PROBE = """
import numpy as np
from tmfem.solvers.petsc_loader import petsc_modules
petsc_modules()
def rss():
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith("VmRSS:")) / 1024
before = rss()
a = np.ones({values})          # touched
held = rss()
del a
print(before, held, rss())
"""


def _probe(values, tunables=None):
    """(before, held, after) [MB] of PROBE in a fresh interpreter: the resident memory before an
    array of ``values`` float64, while it is held, and after it is freed."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    env.pop("GLIBC_TUNABLES", None)
    if tunables:
        env["GLIBC_TUNABLES"] = tunables
    out = subprocess.run([sys.executable, "-c", PROBE.format(values=values)], capture_output=True,
                         text=True, env=env, timeout=120, check=True).stdout.split()
    return tuple(float(v) for v in out)


@pytest.mark.skipif(not HAVE_PETSC, reason="petsc4py/slepc4py not importable")
@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs /proc (Linux)")
def test_freed_arrays_leave_the_resident_set_after_petsc_has_loaded():
    before, held, after = _probe(32 * 2**20)        # 256 MB
    assert held - before > 200          # the block was resident
    assert after - before < 32          # ... and is gone once freed


@pytest.mark.skipif(not HAVE_PETSC, reason="petsc4py/slepc4py not importable")
@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs /proc (Linux)")
def test_the_users_glibc_tunables_hold_after_petsc_has_loaded():
    # 8 MB: below tmfem's 32 MB mapping threshold, the block comes from the heap, whose top
    # is kept up to 64 MB free
    before, held, after = _probe(2**20)
    assert held - before > 7 and after - before > 7
    # a 1 MB threshold of the user's: the block is mapped on its own and unmapped when freed
    before, held, after = _probe(2**20, "glibc.malloc.mmap_threshold=0x100000:glibc.malloc.trim_threshold=2097152")
    assert held - before > 7 and after - before < 2


def test_malloc_parameters_read_glibc_tunables_and_keep_tmfems_values_otherwise(caplog):
    from tmfem.solvers.petsc_loader import MALLOC_PARAMETERS, malloc_parameters
    assert malloc_parameters("") == list(MALLOC_PARAMETERS)
    values = [v for _, _, v in malloc_parameters("glibc.malloc.mmap_threshold=0x100000:glibc.malloc.arena_max=1")]
    assert values == [65536, 1 << 20, 64 << 20]
    values = [v for _, _, v in malloc_parameters("glibc.malloc.trim_threshold=2097152")]
    assert values == [65536, 32 << 20, 2 << 20]
    with caplog.at_level("WARNING", logger="tmfem.solvers.petsc_loader"):
        tunables = "glibc.malloc.trim_threshold=lots:glibc.malloc.mmap_max=-1:glibc.malloc.mmap_threshold=0x80000000"
        assert malloc_parameters(tunables) == list(MALLOC_PARAMETERS)
    for given in ("trim_threshold=lots", "mmap_max=-1", "mmap_threshold=0x80000000"):
        assert f"glibc.malloc.{given} is not an integer from 0 to 2147483647" in caplog.text


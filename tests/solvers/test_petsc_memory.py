"""Memory that a run under the PETSc backend gives back to the system.

Source of the expected numbers: the size of the array itself (a freed 256 MB block must
leave the resident set, as it does in a process that has not loaded PETSc), measured on
/proc/self/status in a fresh interpreter.
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
a = np.ones(32 * 2**20)          # 256 MB, touched
held = rss()
del a
print(before, held, rss())
"""


@pytest.mark.skipif(not HAVE_PETSC, reason="petsc4py/slepc4py not importable")
@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs /proc (Linux)")
def test_freed_arrays_leave_the_resident_set_after_petsc_has_loaded():
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=env,
                         timeout=120, check=True).stdout.split()
    before, held, after = (float(v) for v in out)
    assert held - before > 200          # the block was resident
    assert after - before < 32          # ... and is gone once freed

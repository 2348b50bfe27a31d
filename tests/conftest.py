"""Test configuration.

BLAS threads are pinned to one before numpy loads: the suite's dense problems are small,
and on the 2-core machines of CI threaded OpenBLAS made scipy's dense ``eigh`` up to 40x
slower under load. Slow studies are marked ``slow``; with ``TMFEM_SLOW_SCALE=reduced``
(set by ``.ci/run``) they run in a reduced size.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

"""Test configuration.

BLAS threads are pinned to one before numpy loads: the suite's dense problems are small,
and on the 2-core machines of CI threaded OpenBLAS made scipy's dense ``eigh`` up to 40x
slower under load. Slow studies are marked ``slow``; with ``TMFEM_SLOW_SCALE=reduced``
(set by ``.ci/run``) they run in a reduced size.
"""
import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402  (after the BLAS thread count is set)
import pytest  # noqa: E402

from tests.shared import Once, shared_dir  # noqa: E402


@pytest.fixture(scope="session", autouse=True)
def _isolated_cache(tmp_path_factory):
    """The suite's on-disk cache (tmfem.cache) is a directory of its own, shared by the session,
    its xdist workers and the commands it starts (the environment is inherited): never the
    user's cache. (Its entries are written atomically, so workers may share it; the tests of
    the cache itself give it a directory of their own.)"""
    with pytest.MonkeyPatch.context() as mp:
        cache = shared_dir(tmp_path_factory) / "tmfem-cache"
        cache.mkdir(exist_ok=True)
        mp.setenv("TMFEM_CACHE_DIR", str(cache))
        yield


@pytest.fixture(scope="session")
def once(tmp_path_factory):
    """``once(key, compute)``: ``compute()`` run by one process of this test run for ``key``
    and its (pickled) value shared by every xdist worker (tests.shared.Once): for runs that
    several tests read, such as a command's reference run."""
    return Once(shared_dir(tmp_path_factory))


@pytest.fixture(scope="session")
def design21(tmp_path_factory, once):
    """A 2 x 1 grid LPV design of the 2-3-lpv preset at gamma = 20 with the sampled-loop LMI at
    dt = 0.01 s, saved (shared by the LPV deployment tests of the library, the FE plants and the CLI;
    the plant and the design computed once per run, :func:`once`)."""

    def compute():
        from tmfem.control.lpv.plant import com_lpv_plant
        from tmfem.control.lpv.generalized_plant import interconnection_8_1
        from tmfem.control.lpv.synthesis import synthesize_state_feedback
        from tmfem.reference.tables import deployment_bases
        from tmfem.system import load_preset
        s = load_preset("2-3-lpv")
        pl = com_lpv_plant(s, theta=np.radians([63.0, 77.32]), psi=np.radians([8.36]), bases=deployment_bases(s))
        d = synthesize_state_feedback(interconnection_8_1(pl, tracked=s.q_names), solver="EIGOPT", gamma=20.0,
                                      sample_time=0.01)
        return pl, d
    pl, d = once("design21", compute)
    path = tmp_path_factory.mktemp("lpv") / "d21.npz"
    d.save(path)
    return pl, d, path

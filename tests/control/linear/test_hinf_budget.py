"""H-infinity synthesis of a plant too large for the machine is refused before any work
(tmfem.resources.check_synthesis_budget: the route, the states, the estimate and the limit).
The estimates against the measured CPU time of small syntheses: ``benchmarks/bench_hinf.py
--budget`` (a timing, not a test)."""
import time

import control
import numpy as np
import pytest

from tmfem.control.linear.hinf_synthesis import hinfsyn, hinfsyn_state
from tmfem.errors import ResourceLimit
from tmfem.resources import MAX_SYNTHESIS_S, synthesis_seconds


def plant(n, seed=1):
    """A stable random plant with w, u, z, y of two channels each, D12 = D21 = I (regular)."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    B = rng.standard_normal((n, 4))
    C = rng.standard_normal((4, n))
    D = np.zeros((4, 4))
    D[:2, 2:] = np.eye(2)
    D[2:, :2] = np.eye(2)
    return control.ss(A, B, C, D)


@pytest.mark.slow
def test_huge_plant_refused_at_once():
    P = plant(3000)
    Ps = control.ss(P.A, P.B, P.C[:2], P.D[:2])
    est = synthesis_seconds(route="riccati", n=3000)
    c0 = time.process_time()
    with pytest.raises(ResourceLimit, match=f"a plant of 3000 states by the riccati route takes "
                                            f"about {est:.0f} s of CPU; the limit is "
                                            f"{MAX_SYNTHESIS_S:.0f} s"):
        hinfsyn(P, 2, 2)
    with pytest.raises(ResourceLimit, match="hinfsyn_state: a plant of 3000 states"):
        hinfsyn_state(Ps, 2)
    # no PBH test, no Hamiltonian (an eigendecomposition of A alone takes about a minute)
    assert time.process_time() - c0 < 10


def test_lmi_route_refused_by_its_memory():
    # the LMI route's Schur complement: 500 n^4 bytes, 50 GB at n = 100
    with pytest.raises(ResourceLimit, match="100 states by the lmi route: the LMI synthesis"):
        hinfsyn(plant(100), 2, 2, method="lmi")

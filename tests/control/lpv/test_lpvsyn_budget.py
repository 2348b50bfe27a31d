"""A gridded LPV synthesis whose grid cannot fit the machine is refused before any point is
listed or any plant evaluated (tmfem.resources.check_lpv_budget), with the grid sizes, the
estimate and the limit."""
import time

import numpy as np
import pytest

from tests.control.lpv.test_lpvsyn import SADDLE, rotating_spring
from tmfem.control.lpv.gridded_synthesis import lpvsyn
from tmfem.errors import InputError, ResourceLimit
from tmfem.resources import memory_limit


def test_huge_grid_refused_at_once():
    # 10^7 design points of the one parameter, 2 rate vertices: the LMIs alone are far
    # beyond the limit (the verification grid has 4 (10^7 - 1) + 1 points)
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimit, match=r"lpvsyn: 10,000,000 design points x 2 rate vertices, "
                                            r"39,999,997 verification points, a plant of \d+ states"):
        lpvsyn(rotating_spring(**SADDLE), 2, 2, grid=np.linspace(-np.pi, np.pi, 10**7),
               rate_bounds=0.5)
    assert time.perf_counter() - t0 < 10


def test_bad_refinement_still_an_input_error():
    with pytest.raises(InputError, match="verification refinement"):
        lpvsyn(rotating_spring(**SADDLE), 2, 2, grid=np.linspace(-1, 1, 3), rate_bounds=0.5,
               verify_refine="x")


def test_the_limit_is_the_machine_s():
    assert memory_limit() > 1e9

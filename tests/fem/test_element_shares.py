"""The share protocol of the element sets that the distributed assembly splits over ranks
(:mod:`tmfem.fem.distributed`): any contiguous block of elements, the empty one included
(a rank with no element of a set: more ranks than shells), gives that block's rows of the
whole set's forces, tangents, masses (at the state: the shells' rotary inertia turns with
their triads) and energies. Source: the same kernel evaluated on all elements at once."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tmfem.fem.element import State
from tmfem.models.mtc.model import MTCModel
from tmfem.models.sbc.model import SBCModel
from tmfem.system import load_system

SYSTEM = Path(__file__).resolve().parents[1] / "data" / "systems" / "triangle-1-3.toml"


@pytest.mark.parametrize("model", ["mtc", "sbc"])
def test_blocks_of_elements_are_the_rows_of_the_whole_set(model):
    system = load_system(SYSTEM)
    if model == "sbc":
        m = SBCModel(system, mesh_n=2)
        state = m.start_state()
        state.x[2] += 1e-3 * np.sin(np.arange(state.x.shape[1]))     # a stretched, bent state
        turn = 0.05 * np.cos(np.outer(np.arange(state.R.shape[0]), [1.0, 2.0, 3.0]))
        state.R = Rotation.from_rotvec(turn).as_matrix()                 # turned triads
        assert not np.array_equal(m.shell.element_mass(state), m.shell.element_mass())
    else:
        m = MTCModel(system, mesh_n=2)
        state = State(x=m.initial_positions("design"))
    sets = [e for e in m.elements if hasattr(e, "element_arrays")]
    assert sets
    for e in sets:
        ne, nd = np.shape(e.element_dofs)
        f_all, K_all = e.element_arrays(state)
        for block in (slice(0, 0), slice(0, 1), slice(1, ne), slice(ne, ne)):
            f, K = e.element_arrays(state, elements=block)
            rows = range(ne)[block]
            assert f.shape == (len(rows), nd) and K.shape == (len(rows), nd, nd)
            assert np.allclose(f, f_all[block], rtol=1e-13, atol=0)
            assert np.allclose(K, K_all[block], rtol=1e-13, atol=0)
            assert np.allclose(e.element_mass(state, elements=block), e.element_mass(state)[block],
                               rtol=1e-13, atol=0)
            energies = [e.energy(state, elements=slice(i, i + 1)) for i in rows]
            assert e.energy(state, elements=block) == pytest.approx(sum(energies), rel=1e-12,
                                                                     abs=0)

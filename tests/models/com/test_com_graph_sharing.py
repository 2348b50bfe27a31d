"""Models of equal inputs share their casadi graphs (the last ``GRAPHS_MEMO_SIZE`` inputs are
kept, :mod:`tmfem.models.com.graphs`); a model of other inputs gets its own, and its numbers are
those of a model built with nothing kept (source: the fresh build, bitwise)."""
import numpy as np
import pytest

from tmfem import ControlOrientedModel
from tmfem.cache import MemoryMemo
from tmfem.models.com import graphs
from tmfem.system import load_preset


def _fresh(system, **kw):
    """The model built with no graphs kept."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(graphs, "_graphs_memo", MemoryMemo(0))
        return ControlOrientedModel(system, **kw)


@pytest.mark.slow
def test_equal_inputs_share_the_graphs_and_other_inputs_get_their_own():
    s = load_preset("1-4")
    a = ControlOrientedModel(s, membrane_modes=4)
    assert ControlOrientedModel(s, membrane_modes=4).graphs is a.graphs
    for kw in (dict(damping=0.02), dict(prestress_scale=1.1)):
        other = ControlOrientedModel(s, membrane_modes=4, **kw)
        assert other.graphs is not a.graphs
        ref = _fresh(s, membrane_modes=4, **kw)
        np.testing.assert_array_equal(other.linearize().A, ref.linearize().A)
        np.testing.assert_array_equal(other.modes(k=4).freq_hz, ref.modes(k=4).freq_hz)

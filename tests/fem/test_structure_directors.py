"""The director convention of shells and ``orient`` (tmfem.fem.structure.model.oriented_quads).

Sources: the right-hand rule on the element node order (the director convention), and a
pressure p pushing along the directors: a simply supported plate deflects to the directors'
side by 0.00406 p a^4 / D (Timoshenko & Woinowsky-Krieger, table 8).
"""
import numpy as np
import pytest
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure


def test_directors_follow_the_node_order_and_orient_flips_them():
    m = MeshQuad.init_tensor(np.linspace(0, 1, 9), np.linspace(0, 1, 9))
    sec = ShellSection(E=1e7, nu=0.3, thickness=0.01)
    default = Structure.shell(m, section=sec)
    # scikit-fem's init_tensor numbers its quads clockwise seen from +z: g_1 x g_2 along -z
    assert np.allclose(default.frames[:, :, 2], [0, 0, -1])
    up = Structure.shell(m, section=sec, orient=(0, 0, 1))
    assert np.allclose(up.frames[:, :, 2], [0, 0, 1])
    for s, side in ((default, -1.0), (up, 1.0)):
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0)
                            | np.isclose(y, 1)), "uz")
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 0) & np.isclose(y, 0)), ["ux", "uy"])
        s.fix(s.nodes_where(lambda x, y, z: np.isclose(x, 1) & np.isclose(y, 0)), ["uy"])
        s.pressure(1.0, follower=False)
        c = s.nodes_where(lambda x, y, z: np.isclose(x, 0.5) & np.isclose(y, 0.5))
        w = s.displacements(s.solve_linear())[2, c][0]
        D = 1e7 * 0.01**3 / (12 * (1 - 0.3**2))
        assert w == pytest.approx(side * 0.00406 / D, rel=0.02)


def test_orient_by_a_field_on_a_cylinder():
    m = MeshQuad.init_tensor(np.linspace(0, 2, 5), np.linspace(0, np.pi, 9))
    x, th = m.p
    p = np.vstack([x, np.cos(th), np.sin(th)])
    t = m.t.copy()
    t[:, ::2] = t[[0, 3, 2, 1]][:, ::2]            # every other element reversed: inconsistent
    with pytest.raises(InputError, match="consistently oriented"):
        Structure.shell((p, t), section=ShellSection(E=1, nu=0, thickness=0.1))
    s = Structure.shell((p, t), section=ShellSection(E=1, nu=0, thickness=0.1),
                        orient=lambda x, y, z: np.vstack([0 * x, y, z]))
    Vn = s.frames[:, :, 2]
    # averaged element normals: within half an element's angle (pi/16) of the radius
    assert np.all(np.einsum("ni,ni->n", Vn, np.column_stack([0 * x, np.cos(th), np.sin(th)])) > np.cos(np.pi / 15))
    with pytest.raises(InputError, match="off the element planes"):
        Structure.shell((p, t), section=ShellSection(E=1, nu=0, thickness=0.1), orient=(1, 0, 0))

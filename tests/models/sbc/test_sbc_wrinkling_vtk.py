"""The shell lamina's wrinkling states in the SBC model's ParaView files (docs/guides/wrinkling.md,
"The SBC shell's states in ParaView").

Sources: the element states computed by the tension-field law
(:meth:`tmfem.fem.mitc4.MITC4Shell.wrinkling`, the criterion of Roddeman et al. 1987 /
Kang & Im 1997 in :meth:`tmfem.fem.tension_field.MembraneLaw.state`) and, independently of the
shell's strain code, the same criterion applied to the mid-surface Green-Lagrange strain of
the bilinear surface through the written node positions (E = (g_a.g_b - G_a.G_b) / 2 at the
element centre; the MITC4 in-plane strain at r_3 = 0 is exactly this, eq. 4.14).
"""

import meshio
import numpy as np

from tmfem.cli import main
from tmfem.models.sbc.model import SBCModel
from tmfem.system import load_preset

#: 1-4 on the 4 x 4 x 4 mesh: 56 taut and 8 wrinkled elements with the tension-field law
MESH = 4


def _block(mesh, kind_code):
    """Index of the cell block whose ``kind`` is kind_code."""
    kinds = [int(k[0]) for k in mesh.cell_data["kind"]]
    return kinds.index(kind_code)


def _centre_states(law, X, x, conn):
    """Law states of the mid-surface strain at the element centres of the bilinear surface
    with reference nodes X and current nodes x (3, n) (module docstring)."""
    # bilinear shape derivatives at the centre of the unit square, nodes counter-clockwise
    # from (0, 0): any two tangents of the surface do, taken alike for G and g
    dh = 0.5 * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    G = np.einsum("ka,ike->eai", dh, X[:, conn])                     # (ne, 2, 3)
    g = np.einsum("ka,ike->eai", dh, x[:, conn])
    E_cov = 0.5 * (np.einsum("eai,ebi->eab", g, g) - np.einsum("eai,ebi->eab", G, G))
    e1 = G[:, 0] / np.linalg.norm(G[:, 0], axis=1, keepdims=True)   # an orthonormal frame
    e2 = G[:, 1] - np.sum(G[:, 1] * e1, axis=1, keepdims=True) * e1
    e2 /= np.linalg.norm(e2, axis=1, keepdims=True)
    A = np.stack([np.einsum("eai,ei->ea", G, e) for e in (e1, e2)], axis=1)   # A_ma = e_m.G_a
    Ainv = np.linalg.inv(A)
    E = np.einsum("eam,eab,ebn->emn", Ainv, E_cov, Ainv)          # Cartesian components
    return law.state(np.moveaxis(E, 0, -1))


def test_static_vtk_carries_the_shell_states(tmp_path):
    path = tmp_path / "sbc.vtu"
    assert main(["static", "--model", "sbc", "--preset", "1-4", "--mesh", str(MESH),
                 "--membrane-law", "tension-field", "--vtk", str(path), "--json"]) == 0
    m = meshio.read(path)
    shell = _block(m, 2)
    written = np.asarray(m.cell_data["membrane_state"][shell]).ravel()
    direction = np.asarray(m.cell_data["wrinkle_direction"][shell])
    # the same model, solved again: the states the law computes at its equilibrium
    model = SBCModel(load_preset("1-4"), mesh_n=MESH, membrane_law="tension-field")
    state = model.equilibrium().state
    wr = model.shell.wrinkling(state)
    np.testing.assert_array_equal(written, wr["state"])
    counts = np.bincount(written, minlength=3)
    assert counts[0] > 0 and counts[1] > 0, counts          # the case has taut and wrinkled
    # independently: the law on the mid-surface strain of the written positions
    conn = m.cells[shell].data.T
    X = m.points.T - np.asarray(m.point_data["displacement"]).T
    law_states = _centre_states(model.shell.law, X, m.points.T, conn)
    np.testing.assert_array_equal(written, law_states)
    # wrinkled: a unit tension direction in the reference surface; elsewhere zero
    wr_el = written == 1
    np.testing.assert_allclose(np.linalg.norm(direction[wr_el], axis=1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(direction[~wr_el], 0.0)
    n = np.cross(X[:, conn[1]] - X[:, conn[0]], X[:, conn[3]] - X[:, conn[0]], axis=0).T
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.max(np.abs(np.sum(direction[wr_el] * n[wr_el], axis=1))) < 1e-6
    # beams and tendons carry no lamina state
    for b in range(len(m.cells)):
        if b != shell:
            assert np.all(np.asarray(m.cell_data["membrane_state"][b]) == -1)


def test_vibration_series_carries_the_shell_states(tmp_path):
    out = tmp_path / "series"
    assert main(["vibrate", "--model", "sbc", "--preset", "1-4", "--mesh", str(MESH),
                 "--membrane-law", "tension-field", "--t-end", "0.02", "--vtk", str(out),
                 "--vtk-every", "1", "--json"]) == 0
    frames = sorted(out.glob("*.vtu"))
    assert len(frames) == 3
    first = meshio.read(frames[0])
    quad = [i for i, c in enumerate(first.cells) if c.type == "quad"][0]
    written = np.asarray(first.cell_data["membrane_state"][quad]).ravel()
    model = SBCModel(load_preset("1-4"), mesh_n=MESH, membrane_law="tension-field")
    expected = model.shell.wrinkling(model.equilibrium().state)["state"]
    # the first frame is the equilibrium (the perturbation is a rate)
    np.testing.assert_array_equal(written, expected)
    lines = [i for i, c in enumerate(first.cells) if c.type == "line"]
    assert all(np.all(np.isnan(first.cell_data["membrane_state"][i])) for i in lines)

"""The worked examples of docs/guides/shells.md.

Sources: the thin hinged cylindrical roof (h = 6.35) of Sze, Liu & Lo, Finite Elem. Anal.
Des. 40 (2004) 1551, test 3.8 (MBDyn tests/plates/sze2004/sze38/sze38_ref_d.dat: limit loads
0.1953 and -0.1288 P_max, P_max = 3000, the deflection turning back between them); the
stiffened strip's composite-beam closed form is checked in tests/fem/test_structure_gmsh.py.
"""
import numpy as np
import pytest

from tmfem.reference.benchmarks.shell_hinged_roof import model


@pytest.mark.slow
def test_thin_roof_snaps_back_through_two_limit_points():
    s, c = model(n=8, h=6.35)
    path = s.solve_arc_length(dl=0.5, dl_max=1.0, max_steps=800, lam_max=1.0)
    assert path.reason == "completed"
    W = np.array([-(st.x[2, c] - s.X[2, c]) for st in path])
    lam = path.lam
    (i, _), (j, _) = path.events
    assert [e for _, e in path.events] == ["limit point", "limit point"]
    assert lam[:i + 1].max() == pytest.approx(0.1953, rel=0.02)
    assert lam[i:j + 1].min() == pytest.approx(-0.1288, rel=0.02)
    # snap-back: between the limit points the deflection turns back (reference: from 17.01 to
    # 14.45) and then grows again
    k = int(np.argmax(W[i:j])) + i
    assert W[k] == pytest.approx(17.01, rel=0.02) and W[k:].min() == pytest.approx(14.45, rel=0.02)
    assert W[-1] > W[k]
    # one negative pivot exactly on the branch between the two limit points
    piv = np.array([st.negative_pivots for st in path])
    assert np.all(piv[:i] == 0) and np.all(piv[i + 1:j] == 1) and np.all(piv[j + 1:] == 0)

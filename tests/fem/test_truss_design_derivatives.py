"""Rest-length derivatives of the truss kernel against central finite differences of
truss_internal (step 1e-6 of the rest lengths)."""
import dataclasses

import numpy as np

from tmfem.fem.truss import TrussSet, truss_axial_force_derivatives, truss_internal, \
    truss_rest_length_derivatives


def test_force_and_axial_force_derivatives_match_finite_differences():
    rng = np.random.default_rng(3)
    x = rng.normal(size=(3, 5))
    conn = np.array([[0, 1, 2, 3, 0], [1, 2, 3, 4, 4]])
    l = np.linalg.norm(x[:, conn[1]] - x[:, conn[0]], axis=0)
    L = l * np.array([0.9, 0.95, 1.1, 0.97, 0.92])          # one tendon slack (L > l)
    t = TrussSet(conn=conn, L=L, EA=1e4 * (1 + rng.random(5)), rhoA=1.0,
                 tension_only=np.array([True, True, True, False, True]))
    dF = truss_rest_length_derivatives(x, t).toarray()
    N, dN_dl, dN_dL, e = truss_axial_force_derivatives(x, t)
    assert np.allclose(N, truss_internal(x, t, tangent=False).N, rtol=1e-13)
    for j in range(5):
        h = 1e-6 * L[j]
        fp, fm = (truss_internal(x, dataclasses.replace(t, L=L + s * h * np.eye(5)[j]), tangent=False)
                  for s in (1, -1))
        assert np.allclose(dF[:, j], (fp.f - fm.f) / (2 * h), rtol=1e-6, atol=1e-6 * np.abs(dF).max())
        assert np.isclose(dN_dL[j], (fp.N[j] - fm.N[j]) / (2 * h), rtol=1e-6, atol=1e-9)
    # dN/dl along the chord: move node 1 of element 0 by h along e
    h = 1e-6
    xp, xm = x.copy(), x.copy()
    xp[:, 1] += h * e[:, 0]
    xm[:, 1] -= h * e[:, 0]
    fd = (truss_internal(xp, t, tangent=False).N[0] - truss_internal(xm, t, tangent=False).N[0]) / (2 * h)
    assert np.isclose(dN_dl[0], fd, rtol=1e-6)
    assert not dF[:, 2].any() and dN_dL[2] == 0 and dN_dl[2] == 0   # the slack tendon

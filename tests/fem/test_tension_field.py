"""Tension-field membrane law (tmfem.fem.tension_field) and its use in the membrane element.

Sources: the consistent tangent is checked against central finite differences of the stress
(an independent formulation) in every state and next to the state boundaries; the energy
against the stress (S = dW/dE by finite differences); the simple-shear strip against the
closed form of a homogeneous tension field (docs/guides/wrinkling.md: S = E e1 n1 n1^T,
n1 at 45 degrees, effective shear modulus E/4 in the small-strain limit, Wagner's tension
field, e.g. Mansfield 1989 "The bending and stretching of plates", 2nd ed., ch. 9).
"""
import numpy as np
import pytest
import skfem

from tmfem.errors import InputError
from tmfem.fem.membrane import MembraneTL
from tmfem.fem.membrane_problem import solve_membrane
from tmfem.fem.tension_field import (SLACK, TAUT, WRINKLED, SVKLaw, TensionFieldLaw,
                                     membrane_law)
from tmfem.mesh import polygon_quad_mesh
from tmfem.system.materials import MembraneMaterial

MAT = MembraneMaterial(E=1.0e6, nu=0.3, rho=1.0, h=1.0e-3)
VOIGT = ((0, 0), (1, 1), (0, 1))


def strain(e1, e2, theta):
    """Symmetric 2x2 strain with principal values e1, e2 and major direction theta."""
    c, s = np.cos(theta), np.sin(theta)
    Q = np.array([[c, -s], [s, c]])
    return Q @ np.diag([e1, e2]) @ Q.T


def fd_tangent(law, E, h=1e-10):
    """Central differences of S with respect to the Voigt strain [E11, E22, 2 E12]."""
    D = np.zeros((3, 3))
    for w, (a, b) in enumerate(VOIGT):
        dE = np.zeros((2, 2))
        if a == b:
            dE[a, a] = h
        else:
            dE[0, 1] = dE[1, 0] = 0.5 * h
        Sp, _ = law.stress((E + dE)[:, :, None], tangent=False)
        Sm, _ = law.stress((E - dE)[:, :, None], tangent=False)
        d = (Sp - Sm)[:, :, 0] / (2 * h)
        D[:, w] = [d[0, 0], d[1, 1], d[0, 1]]
    return D


# strains in each state and within 1e-6 (relative) of each state boundary; FD step 1e-10
nu = MAT.nu
CASES = {
    "taut": (2e-3, 1e-3, 0.3),
    "wrinkled": (2e-3, -1e-3, 0.7),
    "wrinkled-large-angle-term": (1e-3, -0.3e-3 * 1.01, -1.2),
    "slack": (-1e-3, -2e-3, 2.0),
    "near taut|wrinkled, taut side": (1e-3, -nu * 1e-3 + 1e-9, 0.4),
    "near taut|wrinkled, wrinkled side": (1e-3, -nu * 1e-3 - 1e-9, 0.4),
    "near wrinkled|slack, wrinkled side": (1e-9, -1e-3, 1.1),
    "near wrinkled|slack, slack side": (-1e-9, -1e-3, 1.1),
}
EXPECTED = {"taut": TAUT, "wrinkled": WRINKLED, "wrinkled-large-angle-term": WRINKLED,
            "slack": SLACK, "near taut|wrinkled, taut side": TAUT,
            "near taut|wrinkled, wrinkled side": WRINKLED,
            "near wrinkled|slack, wrinkled side": WRINKLED, "near wrinkled|slack, slack side": SLACK}


@pytest.mark.parametrize("eta", [0.0, 1e-6])
@pytest.mark.parametrize("case", list(CASES))
def test_tangent_matches_finite_differences(case, eta):
    law = TensionFieldLaw(MAT, eta=eta)
    E = strain(*CASES[case])
    assert law.state(E[:, :, None])[0] == EXPECTED[case]
    _, D = law.stress(E[:, :, None])
    Dfd = fd_tangent(law, E)
    assert np.abs(D[:, :, 0] - Dfd).max() <= 1e-5 * MAT.E


def test_states_and_closed_form_stresses():
    law = TensionFieldLaw(MAT, eta=0.0)
    # wrinkled: uniaxial tension E e1 along n1, zero minor stress (Pipkin's relaxed energy)
    e1, e2, th = 2e-3, -1e-3, 0.7
    S, _ = law.stress(strain(e1, e2, th)[:, :, None], tangent=False)
    n = np.array([np.cos(th), np.sin(th)])
    assert np.allclose(S[:, :, 0], MAT.E * e1 * np.outer(n, n), rtol=1e-12, atol=1e-9)
    # taut: SVK
    E = strain(2e-3, 1e-3, 0.3)[:, :, None]
    assert np.allclose(law.stress(E)[0], SVKLaw(MAT).stress(E)[0], rtol=1e-12)
    # slack: zero; with eta the SVK stress times eta
    E = strain(-1e-3, -2e-3, 2.0)[:, :, None]
    assert np.all(law.stress(E)[0] == 0.0)
    assert np.allclose(TensionFieldLaw(MAT, eta=1e-6).stress(E)[0], 1e-6 * SVKLaw(MAT).stress(E)[0])


@pytest.mark.parametrize("case", ["near taut|wrinkled, taut side", "near wrinkled|slack, slack side"])
def test_stress_continuous_across_state_boundaries(case):
    law = TensionFieldLaw(MAT, eta=1e-6)
    e1, e2, th = CASES[case]
    d = 2e-9
    a = law.stress(strain(e1, e2, th)[:, :, None], tangent=False)[0]
    b = law.stress(strain(e1 - d, e2 - d, th)[:, :, None], tangent=False)[0]   # other side
    assert np.abs(a - b).max() <= 2 * d * MAT.E


@pytest.mark.parametrize("case", ["taut", "wrinkled", "slack"])
def test_stress_is_the_derivative_of_the_energy(case):
    law = TensionFieldLaw(MAT, eta=1e-6)
    E = strain(*CASES[case])
    S, _ = law.stress(E[:, :, None], tangent=False)
    h = 1e-9
    for a, b in VOIGT:
        dE = np.zeros((2, 2))
        dE[a, b] += 0.5 * h
        dE[b, a] += 0.5 * h
        dW = (law.energy_density((E + dE)[:, :, None]) - law.energy_density((E - dE)[:, :, None]))[0]
        assert dW / (2 * h) == pytest.approx(S[a, b, 0], rel=1e-5, abs=1e-6 * MAT.E * 1e-3)


def test_membrane_tangent_and_forms_with_the_tension_field_law():
    mesh = polygon_quad_mesh(np.array([[0, 1, 1, 0], [0, 0, 1, 1.0]]), 3)
    mem = MembraneTL(mesh=mesh, material=MAT, law="tension-field")
    rng = np.random.default_rng(1)
    x = mem.X + 1e-3 * rng.normal(size=mem.X.shape)
    x[0] += 2e-3 * mem.X[0]
    w = mem.wrinkling(x)
    assert all(w["fractions"][k] > 0 for k in ("taut", "wrinkled", "slack"))   # all three states
    f, K = mem.internal(x)
    f2, K2 = mem.internal_forms(x)
    assert np.abs(f - f2).max() <= 1e-12 * np.abs(f).max()
    assert abs(K - K2).max() <= 1e-12 * abs(K).max()
    h = 1e-8
    v = rng.normal(size=f.size)
    fp, _ = mem.internal(x + h * v.reshape(-1, 3).T, tangent=False)
    fm, _ = mem.internal(x - h * v.reshape(-1, 3).T, tangent=False)
    assert np.abs((fp - fm) / (2 * h) - K @ v).max() <= 1e-6 * np.abs(K @ v).max()
    # energy is the potential of the internal force
    e_p, e_m = mem.strain_energy(x + h * v.reshape(-1, 3).T), mem.strain_energy(x - h * v.reshape(-1, 3).T)
    assert (e_p - e_m) / (2 * h) == pytest.approx(f @ v, rel=1e-5)


def test_bad_law_is_refused():
    with pytest.raises(InputError, match="expected one of"):
        membrane_law("wrinkly", MAT)
    with pytest.raises(InputError, match="eta"):
        TensionFieldLaw(MAT, eta=1.5)


def _shear_strip(law, gamma=1e-3, H=0.1, L=1.0):
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0, L, 81), np.linspace(0, H, 9))
    p = mesh.p
    nn = p.shape[1]
    fixed = np.zeros((3, nn), bool)
    fixed[2] = True                       # in-plane problem (tension-field theory is in-plane)
    bot, top = np.isclose(p[1], 0), np.isclose(p[1], H)
    fixed[:2, bot | top] = True
    disp = np.zeros((3, nn))
    disp[0, top] = gamma * H              # top edge slides by gamma H: simple shear
    sol = solve_membrane(mesh=mesh, material=MAT, law=law, fixed=fixed, displacement=disp, tol=1e-7)
    st = sol.membrane.stresses(sol.x)
    mid = (st.points[0] > 0.3 * L) & (st.points[0] < 0.7 * L)   # away from the free ends
    return sol, st, mid


def test_simple_shear_strip_tension_field_closed_form():
    gamma = 1e-3
    sol, st, mid = _shear_strip("tension-field", gamma)
    # closed form (docs/guides/wrinkling.md): S12 = E e1 cos(t) sin(t) -> E gamma / 4, t -> 45 deg
    assert st.S[2][mid].mean() == pytest.approx(MAT.E * gamma / 4, rel=2e-3)
    w = sol.wrinkling()
    qp = sol.membrane.law.state(sol.membrane.strain(sol.x)[1])
    assert np.all(qp[mid] == WRINKLED)
    em = mid.all(axis=1)
    ang = np.degrees(np.arctan2(w["direction"][1, em], w["direction"][0, em]))
    # exact angle for the Green strain of simple shear (E11 - E22 = -gamma^2 / 2, E12 = gamma / 2):
    # 45 + atan(gamma / 2) / 2 degrees
    assert ang.mean() == pytest.approx(45 + np.degrees(np.arctan(gamma / 2)) / 2, abs=0.05)
    # the SVK strip carries compression and has the taut shear modulus G = E / (2 (1 + nu))
    _, st_svk, mid_svk = _shear_strip("svk", gamma)
    assert st_svk.S[2][mid_svk].mean() == pytest.approx(MAT.E / (2 * (1 + MAT.nu)) * gamma, rel=2e-3)

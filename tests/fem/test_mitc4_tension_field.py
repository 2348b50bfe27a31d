"""MITC4 shell with the tension-field lamina law (docs/guides/wrinkling.md, docs/guides/shells.md).

Sources: finite differences of the residual (the consistent tangent) and of the strain
energy, in taut, wrinkled and slack states; another model: the total-Lagrangian membrane
element with the same law (:class:`tmfem.fem.membrane.MembraneTL`), whose in-plane forces a
flat shell with in-plane displacements must reproduce (thickness x membrane forces, the
strain being constant through the thickness); the closed-form simple-shear strip of
tension-field theory (tests/fem/test_tension_field.py: S_12 = E gamma / 4 (shear stiffness
E / 4 instead of the taut G), tension direction at 45 deg + atan(gamma / 2) / 2).
"""
import numpy as np
import pytest
from skfem import MeshQuad

from tmfem.errors import InputError
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State
from tmfem.fem.membrane import MembraneTL
from tmfem.fem.membrane_problem import quad_mesh
from tmfem.fem.mitc4 import MITC4Shell, ShellSection
from tmfem.fem.structure import Structure
from tmfem.fem.tension_field import SLACK, TAUT, WRINKLED, TensionFieldLaw
from tmfem.system.materials import MembraneMaterial

from tests.fem.test_mitc4 import _fd_tangent   # central differences along the finite-rotation update

SEC = ShellSection(E=1e3, nu=0.3, thickness=0.02, rho=2.0)
# homogeneous in-plane stretches (lam_x, lam_y) that put the lamina in one state
STATES = {"taut": (1.02, 1.01, TAUT), "wrinkled": (1.02, 0.98, WRINKLED), "slack": (0.98, 0.97, SLACK)}


def _flat_patch(nx=3, ny=2, seed=0):
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 0.7, ny + 1), indexing="ij")
    xs = xs + 0.04 * rng.standard_normal(xs.shape)
    X = np.vstack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    conn = np.array([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return X, conn


def _stretched(X, conn, case, rot=0.0, seed=1, law="tension-field", noise=1e-3):
    dm = DofMap(np.full(X.shape[1], 5))
    sh = MITC4Shell(X=X, conn=conn, section=SEC, dofmap=dm, law=law)
    s0 = State.reference(X, dm, frames=sh.frames)
    lx, ly, _ = STATES[case]
    rng = np.random.default_rng(seed)
    du = np.zeros((X.shape[1], 5))
    du[:, 0], du[:, 1] = (lx - 1) * X[0], (ly - 1) * X[1]
    du[:, :3] += noise * rng.standard_normal((X.shape[1], 3))
    du[:, 3:] = rot * rng.standard_normal((X.shape[1], 2))
    return sh, dm, s0.advanced(du.ravel(), dm)


@pytest.mark.parametrize("case", sorted(STATES))
def test_tangent_and_force_are_derivatives_in_every_state(case):
    X, conn = _flat_patch()
    sh, dm, s = _stretched(X, conn, case, rot=0.02)
    # the lamina points are in the intended state (the small rotations bend the lamina only a little)
    assert np.all(sh.wrinkling(s)["state_qp"] == STATES[case][2])
    f, K = sh.internal(s)
    K = K.toarray()
    Kfd = _fd_tangent(lambda t: sh.internal(t, tangent=False)[0], s, dm)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()
    assert np.abs(K - K.T).max() <= 1e-10 * np.abs(K).max()
    g = _fd_tangent(lambda t: np.array([sh.energy(t)]), s, dm)[0]
    assert np.abs(g - f).max() <= 1e-6 * np.abs(f).max()


def test_tangent_with_mixed_states_at_large_rotations():
    X, conn = _flat_patch(seed=2)
    sh, dm, s = _stretched(X, conn, "wrinkled", rot=0.5, seed=3, noise=0.02)
    st = sh.wrinkling(s)["state_qp"]
    assert len(np.unique(st)) == 3                       # taut, wrinkled and slack points
    K = sh.internal(s)[1].toarray()
    Kfd = _fd_tangent(lambda t: sh.internal(t, tangent=False)[0], s, dm)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()


def test_svk_law_keeps_the_constant_lamina_matrix():
    X, conn = _flat_patch()
    sh, dm, s = _stretched(X, conn, "wrinkled", rot=0.3, law="svk")
    fe, Ke = sh.element_arrays(s)
    pts = sh._gauss
    c = sh._strains(pts, *sh._nodal(s)[:3])[0]
    S_ref = np.einsum("eqzab,eqzb->eqza", pts.C, c)          # eq. 4.10 before the law option
    S, C = sh._lamina(pts, c)
    assert np.array_equal(S, S_ref) and C is pts.C
    # the SVK lamina law object gives the same numbers through the general path
    sh_g = MITC4Shell(X=X, conn=conn, section=SEC, dofmap=dm, law=TensionFieldLaw(SEC, eta=0.0))
    sh_g.law.state = lambda E: np.zeros(np.shape(E)[2:], dtype=np.int8)   # force "taut": SVK
    fe_g, Ke_g = sh_g.element_arrays(s)
    assert np.abs(fe_g - fe).max() <= 1e-12 * np.abs(fe).max()
    assert np.abs(Ke_g - Ke).max() <= 1e-12 * np.abs(Ke).max()


def test_flat_shell_in_plane_forces_equal_the_membrane_element():
    X, conn = _flat_patch(nx=4, ny=3, seed=5)
    dm = DofMap(np.full(X.shape[1], 5))
    sh = MITC4Shell(X=X, conn=conn, section=SEC, dofmap=dm, law="tension-field")
    mem = MembraneTL(mesh=quad_mesh(X[:2], conn), law="tension-field",
                     material=MembraneMaterial(E=SEC.E, nu=SEC.nu, rho=SEC.rho, h=SEC.thickness))
    rng = np.random.default_rng(6)
    du = np.zeros((X.shape[1], 5))
    du[:, :2] = 0.02 * rng.standard_normal((X.shape[1], 2))        # in-plane: mixed states
    s = State.reference(X, dm, frames=sh.frames).advanced(du.ravel(), dm)
    # the Gauss points (the same for both elements) are in all three states
    assert set(np.unique(mem.law.state(mem.strain(s.x)[1])).tolist()) == {TAUT, WRINKLED, SLACK}
    f_sh, K_sh = sh.internal(s)
    f_m, K_m = mem.internal(s.x)
    tr = dm.translation_dofs(np.arange(X.shape[1]))[:, :2].ravel()
    mdofs = (3 * np.arange(X.shape[1])[:, None] + np.arange(2)).ravel()
    assert np.abs(f_sh[tr] - f_m[mdofs]).max() <= 1e-10 * np.abs(f_m).max()
    Ks, Km = K_sh.toarray()[np.ix_(tr, tr)], K_m.toarray()[np.ix_(mdofs, mdofs)]
    assert np.abs(Ks - Km).max() <= 1e-10 * np.abs(Km).max()


def test_simple_shear_strip_closed_form():
    gamma, H, L = 1e-3, 0.1, 1.0
    sec = ShellSection(E=1e9, nu=0.3, thickness=1e-4)
    res = {}
    for law in ("tension-field", "svk"):
        st = Structure.shell(MeshQuad.init_tensor(np.linspace(0, L, 41), np.linspace(0, H, 5)),
                             section=sec, law=law)
        y = st.X[1]
        bot, top = np.flatnonzero(np.isclose(y, 0)), np.flatnonzero(np.isclose(y, H))
        st.fix(np.arange(st.n_nodes), ["uz", "r1", "r2"])   # in-plane problem: flat, directors normal
        st.fix(np.concatenate([bot, top]), "uy")
        st.fix(bot, "ux")
        st.prescribe(top, "ux", gamma * H)                  # top edge slides: simple shear
        out = st.solve(steps=2)[-1]
        sh = st.shells[0]
        xc = st.X[:, sh.conn].mean(axis=1)
        mid = (xc[0] > 0.3 * L) & (xc[0] < 0.7 * L)
        res[law] = (sh, out, mid)
    sh, out, mid = res["tension-field"]
    # results frame of MITC4Shell.stresses (eq. 4.16): e_1 = e_y x e_3, e_2 = e_3 x e_1
    e3 = sh.frames[0][:, 2]
    e1 = np.cross([0.0, 1.0, 0.0], e3)
    Ef = np.stack([e1, np.cross(e3, e1)])                   # rows e_1, e_2 (+-e_x, +-e_y here)
    sign = Ef[0, 0] * Ef[1, 1]
    N12 = sign * sh.stresses(out.state)["N"][:, 2]          # N_xy
    assert N12[mid].mean() / sec.thickness == pytest.approx(sec.E * gamma / 4, rel=2e-3)
    w = sh.wrinkling(out.state)
    assert np.all(w["state_qp"][mid] == WRINKLED)
    n = Ef.T @ w["direction"][:2, mid]                       # tension direction in x, y, z
    ang = np.degrees(np.arctan2(n[1], n[0])) % 180.0
    assert ang.mean() == pytest.approx(45 + np.degrees(np.arctan(gamma / 2)) / 2, abs=0.05)
    sh_svk, out_svk, mid_svk = res["svk"]
    G = sec.E / (2 * (1 + sec.nu))
    assert sign * sh_svk.stresses(out_svk.state)["N"][mid_svk, 2].mean() / sec.thickness == \
        pytest.approx(G * gamma, rel=2e-3)


def test_law_object_must_carry_the_section():
    X, conn = _flat_patch()
    dm = DofMap(np.full(X.shape[1], 5))
    other = ShellSection(E=2e3, nu=0.3, thickness=0.02)
    with pytest.raises(InputError, match="differs"):
        MITC4Shell(X=X, conn=conn, section=SEC, dofmap=dm, law=TensionFieldLaw(other))
    with pytest.raises(InputError, match="expected one of"):
        MITC4Shell(X=X, conn=conn, section=SEC, dofmap=dm, law="wrinkly")

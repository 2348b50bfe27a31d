"""Beams with trusses and membranes in one model; pinned bars (spin) and interior attachments.

Sources: closed forms of linear springs in parallel (a Timoshenko cantilever tip,
k_b = 1 / (L^3 / (3 EI) + L / (kappa G A)), a truss k_t = EA / L_t, a membrane strip in
uniaxial stretch with nu = 0, k_m = E h w / l), of a simply supported Timoshenko beam with
an elastic support at x = a (flexibility a^2 b^2 / (3 EI L) + a b / (kappa G A L)), of the
pinned-pinned Timoshenko beam's modes and of free-free torsion (omega_n = n pi / L
sqrt(G / rho) for a circle); the unconstrained spectrum minus its zero (spin) mode.
"""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.fem.beam import (BeamElement, BeamSection, BeamSet, line_mesh, locate_on_line,
                            point_on_bar, spin_constraint)
from tmfem.fem.constraints import ConstraintMap
from tmfem.fem.dofmap import DofMap
from tmfem.fem.element import State, assemble
from tmfem.fem.membrane import MembraneElement, MembraneTL
from tmfem.fem.truss import TrussElement, TrussSet
from tmfem.mesh.polygon import MembraneMesh
from tmfem.solvers import lowest_modes
from tmfem.solvers.newton import newton
from tmfem.system.materials import MembraneMaterial

E, NU, RHO = 2e9, 0.3, 1500.0
G = E / (2 * (1 + NU))


def _solve(elements, dm, cm, fext, X):
    res = newton(lambda s: (cm.residual(assemble(elements, s)[0] - fext), cm.tangent(assemble(elements, s)[1])),
                 State.reference(X, dm), free=cm.free, tol=1e-9, line_search=False,
                 atol=1e-7 * np.abs(fext).max(),
                 update=lambda s, du: s.advanced(cm.full(du), dm))
    assert res.converged
    return res.u


def _strip(l, w):
    """A membrane strip l x w in 2 x 2 bilinear quads (floating-frame coordinates)."""
    xs, ys = np.meshgrid(np.linspace(0, l, 3), np.linspace(0, w, 3), indexing="ij")
    p = np.stack([xs.ravel(), ys.ravel()])
    idx = np.arange(9).reshape(3, 3)
    t = np.array([[idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]]
                  for i in range(2) for j in range(2)]).T
    return MembraneMesh(p=p, t=t, corners=np.array([0, 6, 8, 2]), n=2)


@pytest.mark.parametrize("membrane_dependent", [True])
def test_cantilever_with_a_truss_on_its_node_and_a_membrane_pinned_to_it(membrane_dependent):
    """Beam tip (6 dofs) = truss end (shared node, translations only) and the master of the
    three edge nodes of a membrane strip (3-dof nodes, ConstraintMap weight 1): the tip
    deflection under P is P / (k_b + k_t + k_m)."""
    L, sec = 2.0, BeamSection.rectangle(a=0.05, b=0.04)
    Xb, conn = line_mesh([0, 0, 0], [L, 0, 0], n_elements=2)
    nb = Xb.shape[1]
    tip = nb - 1
    l, w, h = 0.5, 0.2, 1e-5
    mesh = _strip(l, w)
    # strip hanging below the tip in the x-z plane: global (L + y_f - w/2, 0, -x_f)
    Xm = np.stack([L + mesh.p[1] - w / 2, np.zeros(9), -mesh.p[0]])
    anchor = np.array([[L], [0.0], [-1.0]])
    X = np.hstack([Xb, Xm, anchor])
    m0, a = nb, nb + 9
    dm = DofMap([6] * nb + [3] * 10)
    beam = BeamElement(BeamSet(conn=conn, section=sec, E=E, nu=NU, rho=RHO), dm, X=X)
    Lt, EAt = 1.0, 2e4
    truss = TrussElement(TrussSet(conn=np.array([[tip], [a]]), L=Lt, EA=EAt, rhoA=0.0,
                                  tension_only=False), dm)
    membrane = MembraneElement(MembraneTL(mesh=mesh, material=MembraneMaterial(E=E, nu=0.0, rho=RHO, h=h)),
                               m0 + np.arange(9), dm)
    edge = m0 + np.flatnonzero(mesh.p[0] == 0.0)
    far = m0 + np.flatnonzero(mesh.p[0] == l)
    cm = ConstraintMap.build(dm, dependent=[(n, [tip], [1.0]) for n in edge],
                             fixed_nodes=np.concatenate([far, [a]]),
                             fixed_dofs=dm.node_dofs([0]).ravel())
    P = 1e-2
    fext = np.zeros(dm.ndof)
    fext[dm.translation_dofs([tip])[0, 2]] = P
    s = _solve([beam, truss, membrane], dm, cm, fext, X)
    kb = 1.0 / (L**3 / (3 * E * sec.I_s) + L / (sec.shear_coefficient(NU) * G * sec.A))
    km, kt = E * h * w / l, EAt / Lt
    delta = s.x[2, tip]
    assert delta == pytest.approx(P / (kb + kt + km), rel=1e-5)
    assert np.allclose(s.x[2, edge], delta, rtol=0, atol=1e-15)            # pinned: edge follows the tip
    # the beam node keeps its own rotation; the membrane nodes have none
    assert s.R[tip] is not None and dm.counts[edge].tolist() == [3, 3, 3]


def _pinned_bar(n_elements=4, L=1.5, d=0.03, axis=(0.3, -0.2, 1.0)):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    X, conn = line_mesh([0, 0, 0], L * a, n_elements=n_elements)
    dm = DofMap(np.full(X.shape[1], 6))
    sec = BeamSection.circle(d=d)
    beam = BeamElement(BeamSet(conn=conn, section=sec, E=E, nu=NU, rho=RHO), dm, X=X)
    return X, conn, dm, sec, beam


def test_pinned_bar_spin_is_removed_without_touching_the_elastic_spectrum():
    """A bar pinned at both ends (translations fixed, rotations free): unconstrained, the
    lowest frequency is the zero of the spin; with :func:`spin_constraint` the spectrum is the
    unconstrained one without it: pinned-pinned Timoshenko bending (twice, circle) and
    free-free torsion pi/L sqrt(G/rho)."""
    L = 1.5
    X, conn, dm, sec, beam = _pinned_bar(L=L, n_elements=8)
    n = X.shape[1]
    K, M = beam.internal(State.reference(X, dm))[1], beam.mass()
    plain = ConstraintMap.build(dm, fixed_nodes=[0, n - 1])
    spun = ConstraintMap.build(dm, fixed_nodes=[0, n - 1],
                               dependent_dofs=[spin_constraint(beam, nodes=np.arange(n))])
    m0 = lowest_modes(plain.tangent(K), plain.tangent(M), k=14, free=plain.free)
    m1 = lowest_modes(spun.tangent(K), spun.tangent(M), k=13, free=spun.free)
    assert abs(m0.omega[0]) < 1e-5 * m0.omega[1]
    np.testing.assert_allclose(m1.omega, m0.omega[1:], rtol=1e-9)
    from tests.fem.test_beam import _ss_timoshenko
    kap = sec.shear_coefficient(NU)
    bend = [_ss_timoshenko(j, L=L, E=E, G=G, rho=RHO, A=sec.A, I=sec.I_s, kappa=kap) for j in range(1, 7)]
    torsion = np.pi / L * np.sqrt(G / RHO)                          # below bending mode 7
    exact = np.sort(np.concatenate([np.repeat(bend, 2), [torsion]]))
    np.testing.assert_allclose(m1.omega, exact, rtol=3e-3)
    np.testing.assert_allclose(m1.omega[:6], exact[:6], rtol=5e-5)


def _bar_with_tendon(n_elements, *, L=1.5, kH=0.4):
    """1-N(D)-like bar along z: pinned at A (base) and B, a tendon pinned at H (k_H = 0.4,
    inside an element: a dependent node on the four element nodes with the weights h_k(r1)
    of eq. 4.20) pulls it sideways against a load at H. Returns the deflection at H, its
    closed form and the reduced tangents without and with the spin constraint."""
    X, conn, _, sec, _ = _pinned_bar(L=L, axis=(0, 0, 1), n_elements=n_elements)
    nb = X.shape[1]
    H, anchor = nb, nb + 1
    Lt = 0.8
    X = np.hstack([X, [[0.0], [0.0], [kH * L]], [[Lt], [0.0], [kH * L]]])
    dm = DofMap([6] * nb + [3, 3])
    beam = BeamElement(BeamSet(conn=conn, section=sec, E=E, nu=NU, rho=RHO), dm, X=X)
    e, r1 = locate_on_line(kH, n_elements=n_elements)
    masters, w = point_on_bar(beam, element=e, r1=r1)
    assert np.allclose(w @ X[:, masters].T, X[:, H]) and w.sum() == pytest.approx(1.0)
    EAt = 5e3
    tendon = TrussElement(TrussSet(conn=np.array([[H], [anchor]]), L=Lt, EA=EAt, rhoA=0.0,
                                   tension_only=True), dm)
    P = -0.1                                                        # pulls H away from the anchor
    fext = np.zeros(dm.ndof)
    fext[dm.translation_dofs([H])[0, 0]] = P
    common = dict(dependent=[(H, masters, w)], fixed_nodes=[0, nb - 1, anchor])
    cm = ConstraintMap.build(dm, **common, dependent_dofs=[spin_constraint(beam, nodes=np.arange(nb))])
    tangents = [c.tangent(beam.internal(State.reference(X, dm))[1]).toarray()[np.ix_(c.free, c.free)]
                for c in (ConstraintMap.build(dm, **common), cm)]
    s = _solve([beam, tendon], dm, cm, fext, X)
    a, b = kH * L, (1 - kH) * L
    flex = a**2 * b**2 / (3 * E * sec.I_s * L) + a * b / (sec.shear_coefficient(NU) * G * sec.A * L)
    return s.x[0, H], P / (1.0 / flex + EAt / Lt), tangents


def test_pinned_bar_with_a_tendon_at_an_interior_point():
    """The statics is singular without the spin constraint and follows the Timoshenko beam
    on an elastic support with it; the point load inside an element (a slope kink the cubic
    cannot represent there) converges with the mesh."""
    w4, exact, (K_plain, K_spin) = _bar_with_tendon(4)
    for Kr, singular in [(K_plain, True), (K_spin, False)]:
        ev = np.abs(np.linalg.eigvalsh(0.5 * (Kr + Kr.T)))
        assert (ev.min() < 1e-10 * ev.max()) == singular
    assert w4 == pytest.approx(exact, rel=1e-3)
    w8, _, _ = _bar_with_tendon(8)
    assert abs(w8 / exact - 1) < abs(w4 / exact - 1) / 4


def test_spin_and_point_helpers_refuse_bad_input():
    X, conn, dm, sec, beam = _pinned_bar()
    with pytest.raises(InputError, match=">= 2 nodes"):
        spin_constraint(beam, nodes=[0])
    with pytest.raises(InputError, match="r1"):
        point_on_bar(beam, element=0, r1=1.5)
    with pytest.raises(InputError, match="0 <= k <= 1"):
        locate_on_line(1.2, n_elements=3)
    with pytest.raises(InputError, match="dependent dofs"):
        ConstraintMap.build(dm, dependent_dofs=[(3, [4], [1.0]), (3, [5], [1.0])])

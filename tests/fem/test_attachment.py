"""Distributed corner attachment of the plane-stress membrane and of the ch. 3 design.

Sources of the reference numbers:
- convergence: with the corner displacement imposed on a fixed patch through the affine
  (RBE3-type) coupling of tmfem.fem.attachment, the load is a smooth body-force density and
  the corner force, an energy-conjugate reaction of bilinear quads, converges at O(h^2)
  asymptotically; the point attachment is the Flamant wedge, 1/F_Delta linear in ln n (its
  closed-form slope is tested in tests/fem/test_plane_stress.py), so successive differences of
  F_Delta decay only like 1/log^2: observed order well below 1.
- patch -> 0: an affine fit through exactly three non-collinear nodes, evaluated at one of
  them, is that node's value (weights 1, 0, 0), so a patch holding only the corner and its two
  edge neighbours is the point attachment, to round-off.
- MTC vs design: independent formulation (nonlinear Total-Lagrangian membrane + node balance
  of MTCModel.consistent_rest_lengths vs linear plane stress + eq. 3.16 null vector). The
  two membranes differ at first order in the strain, so the relative difference of the
  forces is bounded by the peak membrane strain sigma_p1,max / E.
"""
import json

import numpy as np
import pytest

from tmfem.equilibrium.design import design_equilibrium
from tmfem.errors import InputError
from tmfem.fem.attachment import attachment_weights, coupling_matrix, default_patch_radius
from tmfem.fem.plane_stress import PlaneStressMembrane, symmetric_corner_force
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def s14():
    return load_preset("1-4")      # Table 6.2 design, r_mb = 1.4142 m, Kapton (Table 6.1)


def _order(ns, F):
    """Observed convergence order: slope of log|F_{k+1} - F_k| against log h (h ~ 1/n)."""
    d = np.abs(np.diff(F))
    return np.polyfit(np.log(1.0 / np.asarray(ns[1:], dtype=float)), np.log(d), 1)[0], d


def test_F_Delta_converges_with_distributed_corners_point_keeps_falling(s14):
    ns = [5, 10, 20, 40]
    patch = 0.4 * s14.r_mb        # holds >= 6 nodes already at n = 5
    Fd = np.array([symmetric_corner_force(s14, n=n, attachment="distributed", patch=patch)
                   for n in ns])
    Fp = np.array([symmetric_corner_force(s14, n=n) for n in ns])
    pd, dd = _order(ns, Fd)
    pp, dp = _order(ns, Fp)
    assert pd > 1.2                               # at least linear, towards 2 (see header)
    assert dd[-1] / dd[-2] < 0.35                 # last local order > 1.5
    assert pp < 0.6                               # 1/log: differences barely shrink
    assert np.all(np.diff(Fp) < 0) and dp[-1] > 0.7 * dp[-2]
    # geometric tail of the distributed sequence: the n = 40 value is within 1 % of the limit
    r = dd[-1] / dd[-2]
    assert dd[-1] * r / (1 - r) < 1e-2 * Fd[-1]


def test_design_passes_attachment_through(s14):
    d = design_equilibrium(s14, mesh_n=20, attachment="distributed")
    F = symmetric_corner_force(s14, n=20, attachment="distributed")
    assert d.F_Delta == pytest.approx(F, rel=1e-10)
    assert d.membrane_model.patch == pytest.approx(0.1 * s14.r_mb)   # default: 10 % of r_mb
    dp = design_equilibrium(s14, mesh_n=20)
    assert abs(d.F_Delta / dp.F_Delta - 1) > 0.2     # the attachment matters (3.63 vs 2.82 N)
    # rest lengths from eqs. 3.8-3.9 with the distributed forces
    EA = s14.tendon_EA
    np.testing.assert_allclose(d.rest_lengths, EA * d.tendon_lengths / (d.tendon_forces + EA),
                               rtol=1e-12)


def test_corner_stiffness_and_patch_resultant(s14):
    m = PlaneStressMembrane(corners=s14.membrane_corners, material=s14.membrane, n=12,
                            attachment="distributed", patch=0.25 * s14.r_mb)
    S = m.corner_stiffness()
    ev = np.linalg.eigvalsh(S)
    assert np.allclose(S, S.T, atol=1e-9 * np.abs(S).max())
    assert np.sum(np.abs(ev) < 1e-8 * ev.max()) == 3 and ev.min() > -1e-8 * ev.max()
    rng = np.random.default_rng(3)
    delta = 1e-3 * rng.standard_normal((2, 4))
    sol = m.solve(delta)
    np.testing.assert_allclose(sol.corner_forces.T.ravel(), S @ delta.T.ravel(),
                               atol=1e-9 * np.abs(sol.corner_forces).max())
    # the patch carries the corner force: nodal forces K x = C^T mu sum to it on each patch
    x = m.displacement(delta)
    f = m.K @ x
    nd = m.basis.nodal_dofs
    for j, (nodes, w) in enumerate(m.weights):
        assert np.allclose(f[nd[:, nodes]].sum(axis=1), sol.corner_forces[:, j],
                           atol=1e-9 * np.abs(sol.corner_forces).max())
        assert np.allclose(f[nd[:, nodes]], np.outer(sol.corner_forces[:, j], w),
                           atol=1e-9 * np.abs(sol.corner_forces).max())
    # the imposed corner displacement is the weighted patch value
    np.testing.assert_allclose(m.coupling @ x, delta.T.ravel(), atol=1e-14)


def test_patch_to_zero_approaches_point(s14):
    n = 40
    h = s14.r_mb * np.sin(np.pi / 4) / n            # element size: half edge / n (N = 4)
    Fp = symmetric_corner_force(s14, n=n)
    # a patch with only the corner and its two edge neighbours would be the point attachment
    # in disguise (an affine fit through 3 nodes interpolates): it is refused, not used
    with pytest.raises(InputError, match="holds 3 membrane nodes"):
        symmetric_corner_force(s14, n=n, attachment="distributed", patch=1.2 * h)
    Fs = [symmetric_corner_force(s14, n=n, attachment="distributed", patch=f * s14.r_mb)
          for f in (0.4, 0.2, 0.1, 0.05)]
    assert np.all(np.diff(Fs) < 0) and Fs[-1] > Fp          # decreasing towards the point value
    assert Fs[-1] - Fp < 0.5 * (Fs[0] - Fp)


def test_mtc_distributed_consistent_rest_lengths_agree_with_design(s14):
    from tmfem.models.mtc.model import MTCModel
    n, patch = 10, 0.3 * s14.r_mb
    d = design_equilibrium(s14, mesh_n=n, attachment="distributed", patch=patch)
    m = MTCModel(s14, mesh_n=n, tendon_elements=1, attachment="distributed", patch=patch,
                 rest_lengths=d.rest_lengths)
    c = m.consistent_rest_lengths()
    strain = d.membrane_max_principal / s14.membrane.E       # peak membrane strain (~0.5 %)
    rel = np.abs(c["tendon_force"] / d.tendon_forces - 1).max()
    assert rel < strain
    # eq. 3.8 rest lengths: dr / r = -dT / (T + EA), so bounded by strain * T / (T + EA)
    # (the Green-strain truss law of c["rest_lengths"] differs at O(T/EA) = 2 %: not compared)
    T, EA = d.tendon_forces, s14.tendon_EA
    np.testing.assert_allclose(c["rest_lengths_linear"], d.rest_lengths,
                               rtol=strain * np.max(T / (T + EA)))
    assert c["equilibrium_residual"] < 1e-3
    # discriminating: the point attachment at this mesh gives forces ~ 1/3 smaller
    dp = design_equilibrium(s14, mesh_n=n)
    assert np.abs(c["tendon_force"] / dp.tendon_forces - 1).min() > 20 * strain


def test_shared_weights_and_bad_input(s14):
    from tmfem.models.fe.topology import build_topology
    topo = build_topology(s14, mesh_n=20, tendon_elements=1, attachment="distributed")
    w = attachment_weights(topo.mesh, attachment="distributed",
                           patch=default_patch_radius(s14.membrane_corners, s14.r_mb))
    m = PlaneStressMembrane(corners=s14.membrane_corners, material=s14.membrane, n=20,
                            attachment="distributed")
    for (a, wa), (b, wb), (c, wc) in zip(topo.weights, w, m.weights):
        assert np.array_equal(a, b) and np.array_equal(a, c)
        assert np.array_equal(wa, wb) and np.array_equal(wa, wc)
    C = coupling_matrix(w, topo.mesh.p.shape[1], 3)
    p3 = np.vstack([topo.mesh.p, np.zeros(topo.mesh.p.shape[1])])
    # affine exactness: the weighted patch centroid of the reference positions is the corner
    np.testing.assert_allclose((C @ p3.T.ravel()).reshape(-1, 3).T,
                               p3[:, topo.mesh.corners], atol=1e-12)
    with pytest.raises(InputError, match="attachment"):
        PlaneStressMembrane(corners=s14.membrane_corners, material=s14.membrane, attachment="glued")
    with pytest.raises(InputError, match="holds 1 membrane nodes"):
        design_equilibrium(s14, mesh_n=5, attachment="distributed")


def test_cli_attachment(s14, capsys):
    from tmfem.cli import main
    rc = main(["equilibrium", "--preset", "1-4", "--mesh", "20", "--attachment", "distributed",
               "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc in (0, None)
    assert out["attachment"] == "distributed" and out["patch"] == pytest.approx(0.1 * s14.r_mb)
    assert out["F_Delta"] == pytest.approx(
        symmetric_corner_force(s14, n=20, attachment="distributed"), rel=1e-10)
    assert main(["equilibrium", "--preset", "1-4", "--patch", "0.2"]) != 0
    assert "--patch" in capsys.readouterr().err


def test_mtc_default_rest_lengths_come_from_the_design_on_its_own_mesh_and_attachment(s14):
    # the MTC model without given rest lengths takes those of the ch. 3 design (eqs. 3.8-3.9)
    # computed with the same membrane mesh and corner attachment, so both see the same corner
    # stiffness; the point design on mesh 10 would give 1.50891 m instead (docs/validation/errata.md)
    from tmfem.models.mtc.model import MTCModel
    m = MTCModel(s14, mesh_n=20, tendon_elements=1, attachment="distributed")
    d = design_equilibrium(s14, mesh_n=20, attachment="distributed")
    np.testing.assert_array_equal(m.rest_lengths, d.rest_lengths)
    assert m.rest_lengths_source == "design"
    assert abs(m.rest_lengths[0] - design_equilibrium(s14).rest_lengths[0]) > 1e-3

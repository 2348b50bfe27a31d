"""Control-oriented model of a deployable 1-N(D) system (tendons SL, SU through H_1j; ch. 7
presets): design equilibrium, partitioning paths and the DAE with multipliers agree."""
import numpy as np
import pytest

from tmfem.models.com.dae import dae_terms, matrices_newton
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel
from tmfem.system import load_preset


@pytest.fixture(scope="module")
def m4d():
    return ControlOrientedModel(load_preset("1-4D"), membrane_modes=2)


def test_design_and_stability(m4d):
    s = m4d.system
    assert s.deployable and [t.family for t in s.tendons][:1] == ["SL"]
    assert m4d.design.residual < 1e-6 and np.all(m4d.design.tendon_forces > 0)
    # tmfem.equilibrium's design (null vector of eq. 3.40 scaled to F_Delta) gives the same forces
    from tmfem.equilibrium.design import design_equilibrium
    d = design_equilibrium(s, mesh_n=10)
    assert np.allclose(m4d.design.tendon_forces, d.tendon_forces, rtol=1e-5)
    assert np.all(linearize(m4d).frequencies_hz() > 0)


def test_paths_agree(m4d):
    rng = np.random.default_rng(5)
    z = m4d.z0 + 0.01 * rng.standard_normal(m4d.nz)
    zd = 0.1 * rng.standard_normal(m4d.nz)
    for a, b in zip(m4d.matrices(z, zd), matrices_newton(m4d, z, zd)):
        assert np.allclose(a, b, rtol=1e-10, atol=1e-10 * np.abs(a).max())
    d = dae_terms(m4d, z, zd)
    nx, nc = d["M"].shape[0], d["Phi_x"].shape[0]
    A = np.block([[d["M"], d["Phi_x"].T], [d["Phi_x"], np.zeros((nc, nc))]])
    xdd = np.linalg.solve(A, np.concatenate([-d["F"] - d["B"] @ m4d.u0, -d["gamma"]]))[:nx]
    assert np.allclose(xdd[:m4d.nz], m4d.acceleration(z, zd), rtol=1e-8, atol=1e-10)

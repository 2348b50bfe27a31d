"""The smoothed wrinkled area A_w = sum_g H_w(-sigma_2,g) dA_g: its limit as the width w -> 0
against the tension-field law's wrinkled-and-slack area (the mixed criterion of
:mod:`tmfem.fem.tension_field` on the same strains, weighted by the Gauss points' areas), and
its derivative against Richardson-extrapolated central differences of the re-solved
equilibrium (as in test_responses.py)."""
import numpy as np
import pytest

from tmfem.design import design_sensitivities
from tmfem.design.optimizer import optimize, parse_constraint
from tmfem.errors import InputError
from tmfem.fem.membrane import q1_gauss_arrays
from tmfem.fem.tension_field import TAUT, TensionFieldLaw
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_preset
from tests.design import test_responses


def test_wrinkled_area_tends_to_the_tension_field_area_as_the_width_shrinks():
    # the 1-4 design wrinkles along its free edges and at its corners (1/8 of the membrane);
    # |A_w - A_TF| <= sum_g dA_g exp(-|sigma_2,g| / w), a bound that shrinks with w
    system = load_preset("1-4")
    m = MTCModel(system, mesh_n=6)
    eq = m.equilibrium(tol=1e-12)
    xm = eq.state[:, :m.topology.n_mesh]
    _, E = m.membrane.strain(xm)
    dA = q1_gauss_arrays(np.asarray(m.topology.mesh.p, dtype=float), np.asarray(m.topology.mesh.t))[2]
    a_tf = float(np.sum(dA * (TensionFieldLaw(system.membrane).state(E) != TAUT)))
    assert 0.05 < a_tf / dA.sum() < 0.5
    sigma_2 = np.abs(m.membrane.stresses(xm).principal[1])
    bounds, errors = [], []
    for w in (1e3, 1e2, 1e1, 1.0):
        s = design_sensitivities(m, equilibrium=eq, variables=["S1"], k=1, wrinkle_width=w)
        errors.append(abs(s.value("wrinkled_area") - a_tf))
        bounds.append(float(np.sum(dA * np.exp(-sigma_2 / w))))
    assert np.all(np.array(errors) <= np.array(bounds)), (errors, bounds)
    assert np.all(np.diff(bounds) < 0) and errors[-1] < 1e-6 * a_tf


def test_wrinkled_area_derivatives_match_finite_differences(monkeypatch):
    # width 10 kPa: the area changes smoothly over the difference steps, and its derivative
    # stays clear of the equilibrium's round-off (which H_w' / w amplifies in the wrinkled
    # regions: at 1 kPa, d A_w / d r_mb moved by 3e-5 between equilibria re-solved at the
    # round-off floor, at 10 kPa by 3e-7)
    monkeypatch.setitem(test_responses.OPTIONS, "wrinkle_width", 1e4)
    exact, fd, f0, p0 = test_responses.fd_check(load_preset("1-4"), ["S1", "h_membrane", "d_bar", "d_S", "r_mb"],
                                                ["wrinkled_area"])
    assert f0[0] > 0.1 and np.all(np.abs(exact) > 0)
    err = test_responses.rel_err(exact, fd, f0, p0)
    assert np.all(err < 1e-5), err


def test_wrinkled_area_is_an_active_constraint_of_the_optimizer():
    # 1-4, mesh 4: shortening S1 raises f_1 (by 2.5 Hz/m) and, from the start design to 1 cm
    # shorter, the wrinkled area from 0.5406 to 0.5448 m^2 (re-solved equilibria); a bound of
    # 0.5445 m^2 between them stops the shortening there, with the constraint active
    system = load_preset("1-4")
    c = parse_constraint("wrinkled_area<=0.5445")
    assert (c.response, c.sense, c.bound) == ("wrinkled_area", "<=", 0.5445)
    r0 = MTCModel(system, mesh_n=4).rest_lengths.mean()
    res = optimize(system, objective="max:freq_1", constraints=[c], variables={"S1": (r0 - 0.05, r0 + 0.01)},
                   mesh_n=4, k=1)
    assert res.success
    assert -0.01 < res.optimum[0] - r0 < 0
    assert res.optimum_responses["wrinkled_area"] == pytest.approx(0.5445, rel=1e-6)
    assert res.optimum_responses["freq_1"] > res.start_responses["freq_1"]
    assert [a["constraint"] for a in res.active] == ["wrinkled_area<=0.5445"] and res.active[0]["multiplier"] > 0


def test_bad_wrinkle_width_is_refused():
    m = MTCModel(load_preset("1-4"), mesh_n=2)
    for w in (0.0, -1.0, "1"):
        with pytest.raises(InputError, match="wrinkle_width"):
            design_sensitivities(m, k=1, wrinkle_width=w)

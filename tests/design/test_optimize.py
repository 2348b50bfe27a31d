"""The three design examples of docs/guides/design.md in a reduced size, each with an
independent check of its optimum: the KKT conditions evaluated with central finite
differences of the re-solved equilibrium (step 1e-4 of each variable) instead of the exact
gradients the optimiser used; the multipliers are the non-negative least-squares solution of
grad f = -sum mu_i grad g_i over the active constraints and bounds. Example (1), a vertex
(four active constraints in four variables), also by a brute-force grid over two variables."""
import numpy as np
import pytest
from scipy.optimize import nnls

from tmfem.design import design_sensitivities, optimize
from tmfem.design.optimizer import parse_constraint, parse_objective
from tmfem.design.variables import apply_design, parse_variables
from tmfem.errors import ConvergenceError, InputError
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_preset, load_system

TRIANGLE = "tests/data/systems/triangle-1-3.toml"


def fd_gradients(result, responses, *, mesh_n, aperture=None):
    """Central differences (n_responses, n_var) of the scalar responses at the optimum."""
    system0 = result.system
    vs = parse_variables(system0, result.names)
    r = system0.rest_lengths
    p = result.optimum
    out = np.zeros((len(responses), p.size))
    for j in range(p.size):
        h = 1e-4 * abs(p[j])
        vals = []
        for sgn in (1, -1):
            q = p.copy()
            q[j] += sgn * h
            sj, rj = apply_design(system0, r, vs, q)
            m = MTCModel(sj, mesh_n=mesh_n, rest_lengths=rj)
            eq = m.equilibrium(x0=result.state, tol=1e-12)
            s = design_sensitivities(m, equilibrium=eq, variables=result.names, aperture=aperture)
            vals.append([s.value(n) for n in responses])
        out[:, j] = (np.array(vals[0]) - np.array(vals[1])) / (2 * h)
    return out


def kkt_residual(grad_f, active_grads, bound_rows):
    """Relative residual of grad f + sum mu_i grad g_i = 0, mu >= 0 (g_i <= 0 active)."""
    A = np.array(list(active_grads) + list(bound_rows)).T
    mu, _ = nnls(A, -grad_f)
    return np.linalg.norm(grad_f + A @ mu) / np.linalg.norm(grad_f), mu


def bound_rows(result, tol=1e-6):
    rows = []
    for j, (lo, hi, v) in enumerate(zip(result.lower, result.upper, result.optimum)):
        e = np.zeros(result.optimum.size)
        if v <= lo + tol * (hi - lo):
            e[j] = -1.0
            rows.append(e)
        elif v >= hi - tol * (hi - lo):
            e[j] = 1.0
            rows.append(e)
    return rows


def test_example_1_maximises_the_first_frequency_of_1_4_within_the_tendon_stress():
    # per-tendon rest lengths; the tendons' stress limit yield / 1.5 and the wrinkling
    # indicator inside half the inradius (the coarse mesh's corners wrinkle further in)
    system = load_preset("1-4")
    limit = system.tendon_sections["S"].yield_stress / 1.5
    res = optimize(system, objective="max:freq", constraints=[f"tendon_stress<={limit}",
                                                              "membrane_min_principal>=0", "mass<=start"],
                   variables={t: (1.40, 1.52) for t in system.tendon_names()}, mesh_n=4, k=4, aperture=0.5)
    assert res.success
    f0, f1 = res.start_responses["freq"][0], res.optimum_responses["freq"][0]
    assert f1 > 1.25 * f0
    assert np.allclose(res.optimum_responses["tendon_stress"], limit, rtol=1e-5)
    assert res.kkt_residual < 1e-6
    # independent: finite-difference gradients of f_1 and the four tendon stresses
    names = ["freq_1"] + [f"tendon_stress_{i}" for i in range(1, 5)]
    G = fd_gradients(res, names, mesh_n=4, aperture=0.5)
    resid, mu = kkt_residual(-G[0], G[1:], bound_rows(res))       # maximise: minimise -f_1
    assert resid < 1e-4 and np.all(mu[:4] > 0), (resid, mu)
    # brute force: a 5 x 5 grid of S_11, S_13 (+-2 mm) at the optimal S_12, S_14 has no
    # feasible design with a higher first frequency
    vs = parse_variables(res.system, res.names)
    best = res.optimum_responses["freq"][0]
    feasible = 0
    for a in np.linspace(-2e-3, 2e-3, 5):
        for b in np.linspace(-2e-3, 2e-3, 5):
            sj, rj = apply_design(res.system, res.system.rest_lengths, vs, res.optimum + [a, 0, b, 0])
            m = MTCModel(sj, mesh_n=4, rest_lengths=rj)
            s = design_sensitivities(m, equilibrium=m.equilibrium(x0=res.state), variables=res.names, aperture=0.5)
            if np.all(s.value("tendon_stress") <= limit * (1 + 1e-9)):
                feasible += 1
                assert s.value("freq_1") <= best * (1 + 1e-9), (a, b)
    assert feasible >= 9                  # the quadrant of longer tendons, at least


def test_example_2_minimises_the_mass_of_a_1_3_system_with_buckling_and_slack_limits():
    # bar and tendon diameters and the membrane thickness at the file's rest lengths
    system = load_system(TRIANGLE)
    res = optimize(system, objective="min:mass",
                   constraints=["freq>=0.25", "tendon_stress<=6.32e7", "bar_buckling<=0.5", "tendon_force>=1.0"],
                   variables={"d_bar": (0.002, 0.03), "d_S": (0.2e-3, 1.0e-3), "h_membrane": (20e-6, 100e-6)},
                   mesh_n=4)
    assert res.success
    assert res.optimum_responses["mass"] < 0.05 * res.start_responses["mass"]
    active = {a["constraint"].split(" ")[0] for a in res.active if a["multiplier"] > 0}
    assert active == {"bar_buckling_1<=0.5", "tendon_force_1>=1", "h_membrane"}
    assert res.kkt_residual < 1e-8
    names = ["mass", "bar_buckling_1", "tendon_force_1"]
    G = fd_gradients(res, names, mesh_n=4)
    resid, mu = kkt_residual(G[0], [G[1], -G[2]], bound_rows(res))
    assert resid < 1e-5 and np.all(mu > 0), (resid, mu)


@pytest.mark.slow
def test_example_3_maximises_the_first_frequency_of_the_two_stage_2_3():
    system = load_preset("2-3")
    r0 = MTCModel(system, mesh_n=4).rest_lengths
    groups = list(dict.fromkeys(t.group for t in system.tendons))
    mean = {g: float(np.mean([r for t, r in zip(system.tendons, r0) if t.group == g])) for g in groups}
    res = optimize(system.replace(rest_lengths=r0), objective="max:freq",
                   constraints=["tendon_stress<=6.32e7", "tendon_force>=1.0"],
                   variables={g: (v - 0.05, v + 0.05) for g, v in mean.items()}, mesh_n=4, k=4)
    assert res.success
    assert res.optimum_responses["freq"][0] > 1.25 * res.start_responses["freq"][0]
    assert res.kkt_residual < 1e-5
    act = [a["constraint"].split(" ")[0] for a in res.active if a["multiplier"] > 0 and "bound" not in a["constraint"]]
    names = ["freq_1"] + [a.split("<=")[0].split(">=")[0] for a in act if a != "freq_1"]
    G = fd_gradients(res, names, mesh_n=4)
    signs = [1.0 if "<=" in a else -1.0 for a in act if a != "freq_1"]
    resid, mu = kkt_residual(-G[0], [s * g for s, g in zip(signs, G[1:])], bound_rows(res))
    assert resid < 1e-3, (resid, mu, act)


def test_objectives_and_constraints_that_do_not_parse_are_refused():
    for text in ("maximise freq", "max:lift", "max"):
        with pytest.raises(InputError, match="objective"):
            parse_objective(text)
    for text in ("freq>0.1", "freq>=x", "lift<=1"):
        with pytest.raises(InputError, match="constraint"):
            parse_constraint(text)
    system = load_preset("1-4")
    with pytest.raises(InputError, match="outside the bounds"):
        optimize(system, objective="max:freq", variables={"S1": (1.0, 1.2)}, mesh_n=2)
    with pytest.raises(InputError, match="expected design variables"):
        optimize(system, objective="max:freq", mesh_n=2)


def test_a_failed_warm_start_falls_back_to_the_undeformed_membrane(monkeypatch):
    # every warm-started solve fails: the run restarts each design from the undeformed
    # membrane and reaches the same optimum as example 1's group form (the stress bound)
    solve = MTCModel.equilibrium

    def failing(self, *args, **kwargs):
        if kwargs.get("x0") is not None:
            raise ConvergenceError("no equilibrium from this start")
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(MTCModel, "equilibrium", failing)
    system = load_preset("1-4")
    res = optimize(system, objective="max:freq", constraints=["tendon_stress<=6.32e7"],
                   variables={"S1": (1.40, 1.52)}, mesh_n=4)
    assert res.success
    assert res.optimum_responses["tendon_stress"] == pytest.approx([6.32e7] * 4, rel=1e-6)


def test_membrane_radius_optimum_written_back_reads_as_the_same_design(tmp_path):
    # the first frequency of 1-4 by S1 and r_mb within the tendon stress limit; the optimal
    # system written as a file and read back gives the optimiser's first frequency
    from tmfem.system import dump_system
    system = load_preset("1-4")
    res = optimize(system, objective="max:freq", constraints=["tendon_stress<=6.32e7"],
                   variables={"S1": (1.40, 1.52), "r_mb": (1.36, 1.46)}, mesh_n=4)
    assert res.success and res.optimum[1] != res.start[1]
    dump_system(res.system, tmp_path / "opt.toml")
    back = load_system(tmp_path / "opt.toml")
    assert back.r_mb == pytest.approx(res.optimum[1], rel=1e-12)
    m = MTCModel(back, mesh_n=4)
    assert m.modes(k=1, at=m.equilibrium()).freq_hz[0] == pytest.approx(res.optimum_responses["freq"][0], rel=1e-6)


@pytest.mark.slow
def test_sbc_membrane_radius_optimum_reads_back_as_the_same_design(tmp_path):
    # the same problem on the SBC model: its optimal system, read back, gives the optimiser's
    # first frequency on a fresh SBC model (with the refined modes of the sensitivities: the
    # ARPACK modes as they come are 1e-6 off on the SBC model)
    from tmfem.design import design_sensitivities
    from tmfem.models.sbc.model import SBCModel
    from tmfem.system import dump_system
    system = load_preset("1-4")
    res = optimize(system, objective="max:freq", constraints=["tendon_stress<=6.32e7"], model="sbc",
                   variables={"S1": (1.40, 1.52), "r_mb": (1.36, 1.46)}, mesh_n=4)
    assert res.success and res.optimum[1] != res.start[1]
    assert res.optimum_responses["freq"][0] > res.start_responses["freq"][0]
    dump_system(res.system, tmp_path / "opt.toml")
    s = design_sensitivities(SBCModel(load_system(tmp_path / "opt.toml"), mesh_n=4), variables=["S1"], k=1)
    assert s.value("freq_1") == pytest.approx(res.optimum_responses["freq"][0], rel=1e-7)

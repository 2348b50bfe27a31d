"""Modes that no input reaches: the reachable part of a generalized plant (SLICOT TB01PD) keeps
every transfer function, an H-infinity design on it equals the design on the plant built
without those modes, and the deployed design leaves them out only when asked, naming them."""
import json

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.control import hinfsyn
from tmfem.control.linear.hinf_riccati import invariant_zeros
from tmfem.control.linear.generalized_plant import generalized_plant
from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tests.cli.test_own_system import SYSTEMS


def plant(hidden: bool) -> GeneralizedPlant:
    """A two-state mixed-sensitivity-like plant; with ``hidden``, an undamped oscillator at
    5 rad/s that no input drives, coupled into the first state and into the measurement."""
    A = np.array([[-1.0, 2.0], [0.0, -3.0]])
    B1, B2 = np.array([[1.0], [0.5]]), np.array([[0.0], [1.0]])
    C1, C2 = np.array([[1.0, 0.0], [0.0, 0.0]]), np.array([[1.0, 1.0]])
    if hidden:
        A = np.block([[A, np.array([[1.0, 0.0], [0.0, 0.0]])], [np.zeros((2, 2)), np.array([[0.0, 5.0], [-5.0, 0.0]])]])
        B1, B2 = np.vstack([B1, np.zeros((2, 1))]), np.vstack([B2, np.zeros((2, 1))])
        C1, C2 = np.hstack([C1, np.zeros((2, 2))]), np.hstack([C2, np.array([[1.0, 0.0]])])
    n = A.shape[0]
    return GeneralizedPlant(A=A, B1=B1, B2=B2, C1=C1, C2=C2, D11=np.zeros((2, 1)), D12=np.array([[0.0], [1.0]]),
                            D21=np.array([[1.0]]), D22=np.zeros((1, 1)), state_names=[f"s{i}" for i in range(n)],
                            w_names=["w"], u_names=["u"], p_names=["p1", "p2"], y_names=["y"])


def frequency_response(P: GeneralizedPlant, s: complex) -> np.ndarray:
    B, C = np.hstack([P.B1, P.B2]), np.vstack([P.C1, P.C2])
    D = np.block([[P.D11, P.D12], [P.D21, P.D22]])
    return C @ np.linalg.solve(s * np.eye(P.A.shape[0]) - P.A, B) + D


def test_reachable_part_keeps_every_transfer_function_and_drops_the_hidden_modes():
    P = plant(hidden=True)
    R = P.reachable_part()
    assert R.A.shape == (2, 2)
    assert np.allclose(np.sort(np.linalg.eigvals(R.A).real), [-3.0, -1.0], atol=1e-12)
    for s in (0.1j, 2.0j, 5.0j + 1e-3, 40.0j):
        assert np.allclose(frequency_response(R, s), frequency_response(P, s), atol=1e-12)


def test_design_on_the_reachable_part_equals_the_design_without_the_modes():
    # the same optimum as the plant written without the oscillator (an independent formulation)
    a = hinfsyn(plant(hidden=True).reachable_part(), 1, 1)
    b = hinfsyn(plant(hidden=False), 1, 1)
    assert a.gamma == pytest.approx(b.gamma, rel=1e-6)
    assert a.info["verified_norm"] == pytest.approx(b.info["verified_norm"], rel=1e-6)


def test_invariant_zeros_where_slycots_default_workspace_is_too_small():
    # (s + 2)/(s + 1) beside a static 5 x 5 identity channel: n = 1 < min(p, m) - 1 = 5, where
    # slycot's default workspace (n + 3 max(m, p) = 19) is below SLICOT's minimum (23); the one
    # invariant zero is that of the first-order channel, s = -2 (closed form)
    A, B, C = np.array([[-1.0]]), np.zeros((1, 6)), np.zeros((6, 1))
    B[0, 0], C[0, 0] = 1.0, 1.0
    z = invariant_zeros(A, B, C, np.eye(6))
    assert z.size == 1 and z[0] == pytest.approx(-2.0, abs=1e-12)


@pytest.mark.slow
def test_deployed_design_names_unreachable_modes_and_leaves_them_out_on_request(capsys):
    """kapton-1-4 (user system): two membrane modes no tendon reaches (4.644 and 6.457 Hz);
    `control hinf` refuses naming them and the option; with --exclude-uncontrollable it designs
    on the reachable part, verified (gamma >= ||T_pw||), and lists the modes in the JSON."""
    f = str(SYSTEMS / "kapton-1-4.toml")
    assert main(["control", "hinf", f]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "4.644 Hz, 6.457 Hz are not reached by any tendon" in err and "--exclude-uncontrollable" in err
    assert main(["control", "hinf", f, "--exclude-uncontrollable", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    hz = sorted(m["frequency_hz"] for m in r["excluded_modes"])
    assert hz == pytest.approx([4.644, 4.644, 6.457, 6.457], abs=1e-3)      # each pair +- j omega
    assert r["gamma"] >= r["closed_loop_hinf_norm"] and r["closed_loop_max_real_part"] < -r["alpha"]
    assert main(["control", "pbh", f, "--exclude-uncontrollable"]) == 2       # applies to hinf only


def test_design_on_the_reachable_part_leaves_the_excluded_modes_open_loop():
    """square-1-4D (user 1-4(D), K = 4) with `[control] uncontrollable = "exclude"` in the
    System: the controller designed on the reachable part, closed around the *full* plant of
    Fig. 7.1 (u = K y, D22 = 0), has the excluded pair +- j 2 pi 4.276 Hz as eigenvalues
    (undamped, unexcited: the open-loop A's own) and every other pole left of -alpha_1."""
    from tmfem.control.linear.deployed_design import deployed_hinf, with_uncontrollable
    from tmfem.system import load_system
    system = with_uncontrollable(load_system(SYSTEMS / "square-1-4D.toml"), "exclude")
    d = deployed_hinf(system)
    hidden = np.array(d.excluded_modes)
    assert hidden.size == 2 and np.allclose(hidden.real, 0, atol=1e-9)
    assert np.abs(hidden[0]) / (2 * np.pi) == pytest.approx(4.2756, abs=1e-4)
    full = generalized_plant(d.plant, u_m=d.u_m)
    K = d.design.controller
    A = np.block([[full.A + full.B2 @ K.D @ full.C2, full.B2 @ K.C], [K.B @ full.C2, K.A]])
    ev = np.linalg.eigvals(A)
    near = [np.min(np.abs(ev - h)) for h in hidden]
    assert max(near) < 1e-6 * np.abs(hidden[0])
    rest = ev[np.min(np.abs(ev[:, None] - hidden[None, :]), axis=1) > 1e-6 * np.abs(hidden[0])]
    assert rest.size == ev.size - 2 and np.max(rest.real) < -d.design.alpha


def test_exclude_on_a_fully_reachable_plant_is_the_same_design():
    """The 1-4D preset (every mode reached, 7.4's PBH verdict): "exclude" is a policy with
    nothing to exclude, and gives the same controller as "refuse" (as `control hinf
    --exclude-uncontrollable` there)."""
    from tmfem.control.linear.deployed_design import deployed_hinf
    from tmfem.system import load_preset
    s = load_preset("1-4D")
    a, b = deployed_hinf(s), deployed_hinf(s, uncontrollable="exclude")
    assert b.excluded_modes == () and "excluded_modes" not in b.summary()
    for M in ("A", "B", "C", "D"):
        assert np.array_equal(getattr(a.design.controller, M), getattr(b.design.controller, M))

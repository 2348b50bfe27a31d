"""Stiffness-proportional plant damping on the current tangent (docs/guides/fe-plant.md
"Plant damping along the path"): C_n = alpha M + beta K_T(x_n) at every sample
(``damping_tangent="current"``) against C = alpha M + beta K_0 (``"initial"``)."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tmfem.cli import build_parser
from tmfem.cli.deploy import check_plant
from tmfem.control.fe_plant.state_estimate import deployment_plant
from tmfem.errors import InputError
from tmfem.models.sbc.dynamics import SBCDynamics
from tmfem.models.sbc.model import SBCModel
from tmfem.simulation.driver import simulate
from tmfem.system import load_preset

ALPHA, BETA = 0.2, 1e-3
THETA = np.deg2rad(15.0)


@pytest.fixture(scope="module")
def sbc():
    """The 1-4(D) SBC model (2 x 2 x 2 shell) at its static equilibrium."""
    m = SBCModel(load_preset("1-4D"), mesh_n=2)
    return m, m.equilibrium().state


def _plant(sbc, tangent, alpha=0.0):
    m, st = sbc
    return SBCDynamics(m, st, alpha=alpha, beta=BETA, damping_tangent=tangent)


def _rotated_bar(dyn, theta):
    """Free-dof state with bar b_11 turned rigidly by ``theta`` about its base A_11 (axis
    horizontal, normal to the bar): its chain nodes' translations A + Q (x_i - A) - x_i and
    rotation vectors theta n (the triads turned with it), written on the reduced dofs the
    chain nodes' translations and rotations are (the top B_11 follows the membrane corner);
    everything else at the equilibrium. Returns the state, the chain nodes and Q."""
    ch = dyn.model.numbering.bar_chain[0]
    X = dyn.state_eq.x[:, ch]
    A = X[:, 0]
    b0 = (X[:, -1] - A) / np.linalg.norm(X[:, -1] - A)
    n = np.cross(b0, [0.0, 0.0, 1.0])
    n /= np.linalg.norm(n)
    Q = Rotation.from_rotvec(theta * n).as_matrix()
    T = dyn.constraints.T.tocsr()
    red = np.zeros(T.shape[1])
    values = ((dyn.dofmap.translation_dofs(ch), (A[:, None] + Q @ (X - A[:, None]) - X).T),
              (dyn.dofmap.rotation_dofs(ch), np.tile(theta * n, (ch.size, 1))))
    for rows, val in values:
        for r, x in zip(rows.ravel(), val.ravel()):
            if T.indptr[r + 1] - T.indptr[r] == 1 and T.data[T.indptr[r]] == 1.0:
                red[T.indices[T.indptr[r]]] = x
    return red[dyn.free], ch, Q, b0


def _free_translation_rows(dyn, nodes):
    """Free-dof indices (len(nodes), 3) of the translations of ``nodes`` (independent)."""
    T = dyn.constraints.T.tocsr()
    cols = np.array([T.indices[T.indptr[r]] for r in dyn.translation_rows(nodes).ravel()])
    return (np.cumsum(dyn.free) - 1)[cols].reshape(-1, 3)


def test_current_damping_is_the_tangent_at_the_sample(sbc):
    """At a state 15 deg of bar rotation away from the equilibrium, after the sample hook:
    C_n v = alpha M v + beta K_T(x_n) v, with K_T v from a central difference of the model's
    internal force along a random v (an independent formulation of the tangent) to 1e-6
    relative, and C_n equals the plant's own alpha M + beta _tangent(x_n); the initial
    damping stays alpha M + beta K_0 and differs there."""
    cur, ini = _plant(sbc, "current", ALPHA), _plant(sbc, "initial", ALPHA)
    x, *_ = _rotated_bar(cur, THETA)
    cur.sample(x, cur.u0)
    ini.sample(x, ini.u0)
    v = np.random.default_rng(0).standard_normal(x.size)
    h = 1e-7

    def f_int(y):
        return cur.model.residual(cur.configuration(y), tangent=False)[0][cur.free]

    Kv = (f_int(x + h * v) - f_int(x - h * v)) / (2 * h)
    ref = ALPHA * (cur.M @ v) + BETA * Kv
    assert np.linalg.norm(cur.C @ v - ref) <= 1e-6 * np.linalg.norm(ref)
    D = cur.C - (ALPHA * cur.M + BETA * cur._tangent(x))
    assert abs(D).max() <= 1e-12 * abs(cur.C).max()
    assert abs(ini.C - (ALPHA * ini.M + BETA * ini.K0)).max() == 0.0
    assert np.linalg.norm(ini.C @ v - ref) > 1e-2 * np.linalg.norm(ref)


def test_rigid_bar_rotation_meets_no_axial_damping_on_the_current_tangent(sbc):
    """Bar b_11 turned rigidly by 15 deg about its base, and the velocity of that rotation at
    1 rad/s (central difference of the placement in the angle, built from the bar's node
    positions): the segment A_11-H_11 is rigid there (the internal forces at its interior
    beam nodes are those of the equilibrium, turned, ~1e-9 N), and the damping force C v at
    those nodes along the turned bar axis is ~0 on the current tangent (measured 5.9e-7 and
    6.9e-8 N, beta = 1e-3 s) and not on the initial one (0.091 and 0.357 N: K_0's axial bar
    stiffness along the packaged axis)."""
    cur, ini = _plant(sbc, "current"), _plant(sbc, "initial")
    x, ch, Q, b0 = _rotated_bar(cur, THETA)
    h = 1e-6
    v = (_rotated_bar(cur, THETA + h)[0] - _rotated_bar(cur, THETA - h)[0]) / (2 * h)
    inner = _free_translation_rows(cur, ch[1:3])          # the interior nodes of A_11-H_11
    f0 = cur.model.residual(cur.configuration(cur.state0()), tangent=False)[0][cur.free]
    f1 = cur.model.residual(cur.configuration(x), tangent=False)[0][cur.free]
    assert np.abs(f1[inner] - f0[inner] @ Q.T).max() < 1e-7          # rigid: no strain change
    b = Q @ b0
    axial = {}
    for name, dyn in (("current", cur), ("initial", ini)):
        dyn.sample(x, dyn.u0)
        axial[name] = np.abs((dyn.C @ v)[inner] @ b)
    assert axial["current"].max() < 1e-5
    assert axial["initial"].max() > 0.05
    assert axial["initial"].max() > 1e4 * axial["current"].max()


class _WithoutHook:
    """The plant as the driver saw it before the per-sample hook (no ``sample``)."""

    def __init__(self, dyn):
        self._dyn = dyn

    def __getattr__(self, name):
        if name == "sample":
            raise AttributeError(name)
        return getattr(self._dyn, name)


def test_initial_tangent_reproduces_the_constant_damping(sbc):
    """``"initial"`` (the default of the FE plants) integrates exactly as the constant
    C = alpha M + beta K_0 without the hook (bit for bit over 20 steps of a perturbed free
    vibration), and ``"current"`` does not (its C follows the state); every step of the
    current run is integrated with the C of the tangent at its sampled state."""
    m, st = sbc
    runs = {}
    for name in ("default", "initial", "current", "hookless"):
        tangent = {"default": None, "hookless": "initial"}.get(name, name)
        dyn = SBCDynamics(m, st, alpha=ALPHA, beta=BETA, damping_tangent=tangent,
                          perturb={"theta_11_dot": 0.05})
        plant = _WithoutHook(dyn) if name == "hookless" else dyn
        seen = []
        def rec(t, x, v, a, u, y, dyn=dyn, seen=seen):
            seen.append(abs(dyn.C - dyn.damping_matrix(dyn._tangent(x))).max())
        runs[name] = (simulate(plant, t_end=0.2, dt=0.01, outputs=False,
                               record=rec if name == "current" else None), dyn, seen)
    ref = runs["hookless"][0]
    for name in ("default", "initial"):
        r = runs[name][0]
        assert np.array_equal(r.x, ref.x) and np.array_equal(r.v, ref.v)
        assert runs[name][1].damping_tangent == "initial"
    assert not np.allclose(runs["current"][0].x, ref.x, rtol=0, atol=1e-12)
    assert max(runs["current"][2]) == 0.0


def test_damping_tangent_refusals(sbc):
    """The option does not apply without stiffness-proportional damping (beta = 0, with or
    without alpha), nor to the COM plant; an unknown tangent is named; on the CLI it needs
    --plant-damping and an FE plant."""
    m, st = sbc
    for alpha in (0.0, 0.5):
        with pytest.raises(InputError, match="beta > 0"):
            SBCDynamics(m, st, alpha=alpha, beta=0.0, damping_tangent="current")
    with pytest.raises(InputError, match="expected one of"):
        SBCDynamics(m, st, beta=BETA, damping_tangent="final")
    with pytest.raises(InputError, match="COM plant"):
        deployment_plant("com", None, None, beta=0.0, damping_tangent="current")
    parser = build_parser()
    base = ["deploy", "--preset", "2-3-deploy", "--plant-damping-tangent", "current"]
    with pytest.raises(InputError, match="--plant-damping-tangent belongs to"):
        check_plant(parser.parse_args(base + ["--plant", "sbc", "--plant-mesh", "2"]))
    with pytest.raises(InputError, match="--plant com"):
        check_plant(parser.parse_args(base + ["--plant-damping", "1e-3"]))


def test_deployment_plant_damping_tangent_default():
    """A damped deployment plant takes the current tangent unless told otherwise (the
    default chosen from the runs of docs/guides/fe-plant.md "Plant damping along the path"), an
    undamped one has no damping to take it for; the CLI reports the tangent in force with
    --plant-damping and passes --plant-damping-tangent through."""
    from tmfem.reference.deployment_plants import FEPlantOptions
    from tmfem.reference.deployments import setup
    s = setup("2-3-deploy", controller="adaptive", evaluation="reference")
    init = load_preset("2-3-deploy-initial")
    tangent = {}
    for name, kw in (("default", {"beta": BETA}), ("initial", {"beta": BETA,
                                                              "damping_tangent": "initial"}),
                     ("undamped", {})):
        tangent[name] = deployment_plant("mtc", s.model, init, mesh_n=2, **kw).dyn
    assert tangent["default"].damping_tangent == "current"
    assert tangent["initial"].damping_tangent == "initial"
    assert tangent["undamped"].damping_tangent == "initial" and tangent["undamped"].C is None
    parser = build_parser()
    base = ["deploy", "--preset", "2-3-deploy", "--plant", "mtc", "--plant-damping", "1e-3"]
    args = parser.parse_args(base)
    assert FEPlantOptions.of(args).arguments("mtc")["damping_tangent"] is None
    assert FEPlantOptions.of(args).summary("mtc", 2)["plant_damping_tangent"] == "current"
    args = parser.parse_args(base + ["--plant-damping-tangent", "initial"])
    assert FEPlantOptions.of(args).arguments("mtc")["damping_tangent"] == "initial"
    assert FEPlantOptions.of(args).summary("mtc", 2)["plant_damping_tangent"] == "initial"
    assert "plant_damping_tangent" not in FEPlantOptions.of(
        parser.parse_args(["deploy", "--preset", "2-3-deploy", "--plant", "mtc"])).summary("mtc", 2)

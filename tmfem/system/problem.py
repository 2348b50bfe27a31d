"""What a system file declares beyond the structure: the control, deployment and report data.

A system file describes the whole problem (docs/guides/system-file.md). Besides the structure
(``[symmetric]``/``[general]``, materials, rest lengths, ``[monitor]``, ``[models.com]``) it
may carry:

* ``[packaged]``: the packaged (initial) configuration of a deployment, as overrides of the
  file's own tables (``symmetric``, ``rest_lengths``, ...), merged like ``[as_printed]``;
* ``[control]``: the H-infinity design at the (deployed) configuration (7.3-7.4, Fig. 7.1):
  alpha_1 of eq. 5.66, u_m of W_u = I / u_m, W_e, W_d and the measured membrane points of
  eq. 5.18;
* ``[deployment]``: the deployment of 7.4: omega_r, xi_r of eq. 5.68, the PFL gains of
  Table 7.1 (eq. 5.69), the RBF and adaptation parameters, the controller's model error, the
  path and the rest-length limit;
* ``[lpv]``: the LPV design of 8.3 and deployment of 8.4 (the grid of (theta, psi), the
  rate bound, the scheduling values and omega_r of eq. 5.100, K, points, path);
* ``[report]``: what ``tmfem report`` adds for this system: the free-vibration perturbation,
  a second prestress case with its source, explanatory notes, and the deployment it runs;
* ``[design]``: the design variables of ``tmfem optimize`` with their bounds, and optionally
  its objective, constraints and wrinkling aperture (:mod:`tmfem.design.optimizer`).

Everything is read from the :class:`System` the library is given (``system.problem``); a file
that does not declare a table gets the documented defaults, which depend on the system only.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from tmfem.errors import InputError, shorten
from tmfem.resources import check_membrane_modes

#: keys of each table (anything else is refused)
KEYS = {
    "control": {"alpha", "u_m", "W_e", "W_d", "points", "coordinate_points", "uncontrollable"},
    "deployment": {"omega_r", "xi_r", "gains", "uncertainty", "path", "rbf_centres", "w_bar",
                   "gamma", "r_min", "tension_floor"},
    "lpv": {"omega_r", "membrane_modes", "points", "path", "theta_grid_deg", "psi_grid_deg", "theta0_deg",
            "theta_e_deg", "psi0_deg", "rate_bound_deg"},
    "report": {"perturbation", "implied_rest_lengths", "implied_source", "notes_design",
               "notes_models", "deployment", "com_prestress"},
    "report.deployment": {"system", "uncertainty", "t_end", "controller"},
    "design": {"variables", "objective", "constraints", "aperture"},
}
GAIN_KEYS = ("omega_0", "omega_e", "tau", "d_c")
UNCERTAINTIES = ("initial", "no-MG", "exact")
PATHS = ("delta", "auto", "table-7-7-bases", "linear")
#: default fraction of its path elongation an over-actuated system's tendon keeps
#: (``[deployment] tension_floor``, :mod:`tmfem.control.deployment.adaptive`)
TENSION_FLOOR = 0.5
#: the stage-base rules of an LPV grid (``[lpv] path``)
LPV_PATHS = ("table-7-7-bases", "auto")
#: Most angles on an axis of the [lpv] grid (as --grid and --map-grid: 60 points a side).
MAX_GRID_AXIS = 60
COM_PRESTRESS = ("designed", "printed-tendon-stress")
#: ``[control] uncontrollable``: what the H-infinity design does with modes no tendon reaches
UNCONTROLLABLE = ("refuse", "exclude")


def _keys(t, kind: str, where: str) -> dict:
    if not isinstance(t, dict):
        raise InputError(f"{where}: expected [{kind}] to be a table, found {t!r}")
    unknown = set(t) - KEYS[kind]
    if unknown:
        raise InputError(f"{where} [{kind}]: unknown keys {sorted(unknown)}; expected some of "
                         f"{sorted(KEYS[kind])}")
    return t


#: Upper plausibility bounds of the problem tables' numbers (docs/guides/system-file.md): a
#: reference or gain beyond them overflows the closed forms (exp(omega_r t)) or cannot be
#: resolved by the time step; every RBF centre is evaluated at every step.
UPPER = {"omega_r": 100.0, "omega_0": 1e6, "omega_e": 1e6, "tau": 1e6, "d_c": 1e6,
         "w_bar": 1e12, "gamma": 1e12, "r_min": 1e3, "rbf_centres": 1000, "alpha": 1e6,
         "u_m": 1e3, "W_e": 1e12, "W_d": 1e12, "rate_bound_deg": 1e4}


def _positive(t: dict, key: str, where: str, default=None, *, zero: bool = False):
    if key not in t:
        return default
    v = t[key]
    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
    if not ok or v < 0 or (v == 0 and not zero) or v > UPPER.get(key, math.inf):
        raise InputError(f"{where}: expected '{key}' to be a finite number {'>=' if zero else '>'} 0"
                         + (f" and <= {UPPER[key]:g}" if key in UPPER else "") + f", found {v!r}")
    return float(v)


def _points(t: dict, key: str, where: str):
    if key not in t:
        return None
    v = t[key]
    ok = isinstance(v, list) and all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                    and math.isfinite(x) for x in p) for p in v)
    if not ok:
        raise InputError(f"{where}: expected '{key}' as rows [x_f, y_f] in m, found {v!r}")
    return tuple((float(x), float(y)) for x, y in v)


def _choice(t: dict, key: str, where: str, choices, default=None):
    v = t.get(key, default)
    if v is not None and v not in choices:
        raise InputError(f"{where}: expected '{key}' to be one of {list(choices)}, found {v!r}")
    return v


def _strings(t: dict, key: str, where: str) -> tuple:
    v = t.get(key, [])
    if not (isinstance(v, list) and all(isinstance(s, str) for s in v)):
        raise InputError(f"{where}: expected '{key}' to be a list of strings, found {v!r}")
    return tuple(v)


@dataclass(frozen=True)
class HinfWeights:
    """``[control]``: the H-infinity design of 7.3-7.4 (Fig. 7.1).

    alpha : float or None
        alpha_1 of eq. 5.66 [1/s]: closed-loop poles left of -alpha_1. None: the default of
        :func:`tmfem.control.linear.deployed_design.default_alpha` (the system's own scale).
    u_m : float or None
        Rest-length scale of W_u = I / u_m [m]; None: :func:`default_u_m`.
    W_e, W_d : float
        Tracking-error weight (7.4: 0.5) and noise weight (7.4: 0.001).
    points : tuple of (x_f, y_f) or None
        Measured membrane points of eq. 5.18 [m]; None: ``[monitor] points``, else chosen
        inside the membrane (:func:`tmfem.control.linear.generalized_plant.point_coordinates`).
    coordinate_points : tuple of (x_f, y_f) or None
        Points that complete the coordinates v of eq. 5.18 to K after the measured ones [m];
        None: chosen greedily inside the membrane (the same function).
    uncontrollable : {"refuse", "exclude"}
        Modes no tendon reaches (PBH, eq. 5.71): ``"refuse"`` (default) the design naming
        them, or ``"exclude"`` them from it (they stay open loop, neither damped nor excited by
        the linear controller; :func:`tmfem.control.linear.deployed_design.deployed_hinf`).
    """

    alpha: float | None = None
    u_m: float | None = None
    W_e: float = 0.5
    W_d: float = 0.001
    points: tuple | None = None
    coordinate_points: tuple | None = None
    uncontrollable: str = "refuse"


@dataclass(frozen=True)
class DeploymentParameters:
    """``[deployment]``: the deployment of 7.4 (adaptive PFL, then the switch).

    omega_r, xi_r : reference trajectory of eq. 5.68 [rad/s] and its damping (only 1 is
        implemented: the critically damped closed form).
    gains : (omega_0, omega_e, tau, d_c) of eq. 5.69 (Table 7.1) [rad/s, rad/s, s, -].
    uncertainty : the controller's model error ("initial": eq. 5.72, "no-MG", "exact").
    path : "delta" (1-N(D): eq. 3.22 with Delta linear), "auto" (M >= 2: the automatic path
        through the symmetric equilibria, :mod:`tmfem.equilibrium.deployment_path`),
        "table-7-7-bases" (M = 2 with the stage-2 base rule of Table 7.7) or "linear"; None:
        "delta" for 1-N(D), "auto" for M >= 2, else "linear".
    rbf_centres, w_bar, gamma : RBF centres along the reference, the bound of the weights and
        the adaptation gain (eq. 5.58-5.60).
    r_min : smallest admissible rest length [m] (the rest-length limit of the PFL).
    tension_floor : float or None
        An over-actuated system's (more tendons than bar coordinates) fraction f in [0, 1) of
        each tendon's elongation on the path, L_d - u_d, that the PFL's inversion keeps (the
        upper rest-length limit |tendon| - f (L_d - u_d), :mod:`tmfem.control.deployment.adaptive`);
        None: :data:`TENSION_FLOOR` (0.5). A square system has no tendon to spare: the key is
        refused there (:func:`tmfem.reference.deployments.check_choices`).
    """

    omega_r: float = 0.5
    xi_r: float = 1.0
    gains: tuple = (4.0, 10.0, 20.0, 0.9)
    uncertainty: str = "no-MG"
    path: str | None = None
    rbf_centres: int = 10
    w_bar: float = 100.0
    gamma: float = 0.01
    r_min: float = 1e-3
    tension_floor: float | None = None

    @property
    def floor(self) -> float:
        """The tension floor of the run: ``tension_floor``, else :data:`TENSION_FLOOR`."""
        return TENSION_FLOOR if self.tension_floor is None else self.tension_floor


@dataclass(frozen=True)
class LPVParameters:
    """``[lpv]``: the LPV design of 8.3 and the deployment of 8.4 (eqs. 5.95-5.100).

    theta_grid_deg, psi_grid_deg : tuple of float or None
        The design grid of the scheduling parameters rho = (theta, psi) of eq. 5.97 (the
        scheduled stage's bar attitude) [deg], strictly increasing; None: not declared
        (``tmfem control lpv`` refuses the file).
    rate_bound_deg : float
        |d rho_k / dt| <= rate_bound_deg for both parameters [deg/s] (8.3: 10).
    theta0_deg, theta_e_deg, psi0_deg : float or None
        The scheduling values of eq. 5.100: theta from theta_0 (packaged) to theta_e
        (deployed) at psi_0 [deg]; None: not declared (the deployment refuses the file).
    omega_r : float
        Reference of eq. 5.100 [rad/s].
    membrane_modes : int or None
        K of the COM; None: ``[models.com]``.
    points : tuple of (x_f, y_f) or None
        Monitored membrane points of eq. 5.101 [m]; None: as ``[control]``.
    path : str or None
        The stage bases over the grid (:data:`LPV_PATHS`): "table-7-7-bases", the rule of
        :func:`tmfem.reference.tables.deployment_bases` for any two-stage system (sigma_2
        fixed, z_2 = 0.7 l cos(theta), r_2 from eq. 3.22 for Delta = 1 mm); "auto", the
        automatic deployment path of :mod:`tmfem.equilibrium.deployment_path` from the
        file's ``[packaged]`` to its deployed configuration, any symmetric M >= 2 system
        (:class:`tmfem.equilibrium.deployment_path.PathBases`: the path's bases at the
        progress whose theta is the grid's). None: "table-7-7-bases" for M = 2, "auto" for
        M >= 3 (:func:`lpv_path`).
    """

    omega_r: float = 0.3
    membrane_modes: int | None = None
    points: tuple | None = None
    path: str | None = None
    theta_grid_deg: tuple | None = None
    psi_grid_deg: tuple | None = None
    rate_bound_deg: float = 10.0
    theta0_deg: float | None = None
    theta_e_deg: float | None = None
    psi0_deg: float | None = None

    def check_schedule(self, where: str) -> None:
        """The scheduling values of eq. 5.100 on the design grid (a deployment: the reference
        would leave the grid, found otherwise only after the synthesis)."""
        for key, axis in (("theta0_deg", self.theta_grid_deg), ("theta_e_deg", self.theta_grid_deg),
                          ("psi0_deg", self.psi_grid_deg)):
            v = getattr(self, key)
            if v is not None and axis is not None and not axis[0] <= v <= axis[-1]:
                raise InputError(f"{where} [lpv]: expected '{key}' inside its grid [{axis[0]:g}, "
                                 f"{axis[-1]:g}] deg (eq. 5.100 on the design grid), found {v:g}")


@dataclass(frozen=True)
class ReportSettings:
    """``[report]``: what ``tmfem report`` adds for this system.

    perturbation : {coordinate rate: value}, the free-vibration start (default
        ``theta_11_dot = 0.01`` rad/s).
    implied_rest_lengths, implied_source : a second prestress case (rest lengths per group or
        tendon [m]) and where it comes from; none by default.
    notes_design, notes_models : notes printed beside the design and the model results.
    deployment : {system, uncertainty, t_end, controller}: a deployment the report runs (a
        preset name or a file path in ``system``); none by default (a deployable system with
        ``[packaged]`` runs its own).
    com_prestress : "designed" (default) or "printed-tendon-stress": the COM of ``tmfem
        compare`` at the designed prestress or scaled to the printed tendon stress.
    """

    perturbation: dict = field(default_factory=lambda: {"theta_11_dot": 0.01})
    implied_rest_lengths: dict | None = None
    implied_source: str = ""
    notes_design: tuple = ()
    notes_models: tuple = ()
    deployment: dict | None = None
    com_prestress: str = "designed"


@dataclass(frozen=True)
class DesignTable:
    """``[design]``: the optimisation of :func:`tmfem.design.optimize`.

    variables : {name: (lower, upper)} (names of :mod:`tmfem.design.variables`; checked
        against the system when the optimisation starts).
    objective : str or None (``"max:freq"``); constraints : tuple of str
        (``"tendon_stress<=6.32e7"``); aperture : the wrinkling aperture or None.
    """

    variables: dict
    objective: str | None = None
    constraints: tuple = ()
    aperture: float | None = None


@dataclass(frozen=True)
class Problem:
    """The tables of a system file beyond the structure (module docstring); ``raw`` keeps them
    as read, for writing the file back."""

    control: HinfWeights = field(default_factory=HinfWeights)
    deployment: DeploymentParameters | None = None
    lpv: LPVParameters | None = None
    report: ReportSettings = field(default_factory=ReportSettings)
    packaged: object = None
    raw: dict = field(default_factory=dict)
    design: DesignTable | None = None


def _control(t: dict, where: str) -> HinfWeights:
    w = f"{where} [control]"
    _keys(t, "control", where)
    d = HinfWeights()
    return HinfWeights(alpha=_positive(t, "alpha", w), u_m=_positive(t, "u_m", w),
                       W_e=_positive(t, "W_e", w, d.W_e), W_d=_positive(t, "W_d", w, d.W_d),
                       points=_points(t, "points", w),
                       coordinate_points=_points(t, "coordinate_points", w),
                       uncontrollable=_choice(t, "uncontrollable", w, UNCONTROLLABLE, d.uncontrollable))


def _gains(v, where: str) -> tuple:
    if isinstance(v, dict):
        missing = set(GAIN_KEYS) - set(v)
        extra = set(v) - set(GAIN_KEYS)
        if missing or extra:
            raise InputError(f"{where}: expected 'gains' with keys {list(GAIN_KEYS)} (Table 7.1), "
                             f"found {sorted(v)}")
        v = [v[k] for k in GAIN_KEYS]
    if not (isinstance(v, list) and len(v) == 4):
        raise InputError(f"{where}: expected 'gains' as {{omega_0, omega_e, tau, d_c}} "
                         f"(Table 7.1), found {v!r}")
    g = tuple(_positive({k: x}, k, where, zero=k == "omega_e") for k, x in zip(GAIN_KEYS, v))
    return g


def _deployment(t: dict, where: str) -> DeploymentParameters:
    w = f"{where} [deployment]"
    _keys(t, "deployment", where)
    d = DeploymentParameters()
    xi = _positive(t, "xi_r", w, d.xi_r)
    if xi != 1.0:
        raise InputError(f"{w}: expected xi_r = 1 (eq. 5.68 critically damped, the reference "
                         f"implemented), found {xi}")
    n = t.get("rbf_centres", d.rbf_centres)
    if not (isinstance(n, int) and not isinstance(n, bool) and 2 <= n <= UPPER["rbf_centres"]):
        raise InputError(f"{w}: expected 'rbf_centres' to be an integer in 2..{UPPER['rbf_centres']}, "
                         f"found {n!r}")
    return DeploymentParameters(
        omega_r=_positive(t, "omega_r", w, d.omega_r), xi_r=xi,
        gains=_gains(t["gains"], w) if "gains" in t else d.gains,
        uncertainty=_choice(t, "uncertainty", w, UNCERTAINTIES, d.uncertainty),
        path=_choice(t, "path", w, PATHS), rbf_centres=n, w_bar=_positive(t, "w_bar", w, d.w_bar),
        gamma=_positive(t, "gamma", w, d.gamma), r_min=_positive(t, "r_min", w, d.r_min),
        tension_floor=_fraction(t, "tension_floor", w))


def _fraction(t: dict, key: str, where: str):
    """A number in [0, 1) or None when absent."""
    if key not in t:
        return None
    v = t[key]
    if not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0.0 <= v < 1.0):
        raise InputError(f"{where}: expected '{key}' to be a number in [0, 1), found {v!r}")
    return float(v)


def _angle(t: dict, key: str, where: str):
    if key not in t:
        return None
    v = t[key]
    if not (isinstance(v, (int, float)) and not isinstance(v, bool) and -180.0 <= v <= 180.0):
        raise InputError(f"{where}: expected '{key}' to be an angle in degrees in [-180, 180], found {v!r}")
    return float(v)


def _axis(t: dict, key: str, where: str):
    if key not in t:
        return None
    v = t[key]
    ok = isinstance(v, list) and v and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and -180.0 <= x <= 180.0 for x in v)
    if not ok or any(b <= a for a, b in zip(v, v[1:])):
        raise InputError(f"{where}: expected '{key}' as a strictly increasing list of angles in "
                         f"degrees, found {shorten(v) if isinstance(v, list) else repr(v)}")
    if len(v) > MAX_GRID_AXIS:
        raise InputError(f"{where}: expected '{key}' with at most {MAX_GRID_AXIS} angles (every "
                         f"grid point is one linearisation of the model), found {len(v)}")
    return tuple(float(x) for x in v)


def _lpv(t: dict, where: str) -> LPVParameters:
    w = f"{where} [lpv]"
    _keys(t, "lpv", where)
    K = t.get("membrane_modes")
    if K is not None and not (isinstance(K, int) and not isinstance(K, bool) and K >= 1):
        raise InputError(f"{w}: expected 'membrane_modes' to be an integer >= 1, found {K!r}")
    if K is not None:
        check_membrane_modes(K, given=f"{w} membrane_modes")
    d = LPVParameters()
    return LPVParameters(omega_r=_positive(t, "omega_r", w, d.omega_r),
                         membrane_modes=K, points=_points(t, "points", w),
                         path=_choice(t, "path", w, LPV_PATHS),
                         theta_grid_deg=_axis(t, "theta_grid_deg", w), psi_grid_deg=_axis(t, "psi_grid_deg", w),
                         rate_bound_deg=_positive(t, "rate_bound_deg", w, d.rate_bound_deg, zero=True),
                         theta0_deg=_angle(t, "theta0_deg", w), theta_e_deg=_angle(t, "theta_e_deg", w),
                         psi0_deg=_angle(t, "psi0_deg", w))


def _report(t: dict, where: str) -> ReportSettings:
    w = f"{where} [report]"
    _keys(t, "report", where)
    pert = t.get("perturbation", {"theta_11_dot": 0.01})
    if not (isinstance(pert, dict) and pert and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            for v in pert.values())):
        raise InputError(f"{w}: expected 'perturbation' as a table coordinate = number, found {pert!r}")
    implied = t.get("implied_rest_lengths")
    if implied is not None and not (isinstance(implied, dict) and implied and all(
            _positive({k: v}, k, w) for k, v in implied.items())):
        raise InputError(f"{w}: expected 'implied_rest_lengths' as a table of rest lengths, "
                             f"found {implied!r}")
    dep = t.get("deployment")
    if dep is not None:
        _keys(dep, "report.deployment", w)
        if not isinstance(dep.get("system"), str):
            raise InputError(f"{w} deployment: expected 'system' (a preset name or a system "
                             f"file), found {dep.get('system')!r}")
        dep = {"uncertainty": "exact", "t_end": 16.0, "controller": "adaptive-hinf", **dep}
        _choice(dep, "uncertainty", f"{w} deployment", UNCERTAINTIES)
        _positive(dep, "t_end", f"{w} deployment")
    src = t.get("implied_source", "")
    if not isinstance(src, str):
        raise InputError(f"{w}: expected 'implied_source' to be a string, found {src!r}")
    return ReportSettings(perturbation={k: float(v) for k, v in pert.items()},
                          implied_rest_lengths=dict(implied) if implied else None,
                          implied_source=src, notes_design=_strings(t, "notes_design", w),
                          notes_models=_strings(t, "notes_models", w), deployment=dep,
                          com_prestress=_choice(t, "com_prestress", w, COM_PRESTRESS, "designed"))


def _design(t: dict, where: str) -> DesignTable:
    w = f"{where} [design]"
    _keys(t, "design", where)
    v = t.get("variables")
    ok = isinstance(v, dict) and v and all(
        isinstance(b, list) and len(b) == 2 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                    and math.isfinite(x) for x in b) and b[0] < b[1]
        for b in v.values())
    if not ok:
        raise InputError(f"{w}: expected 'variables' as a table name = [lower, upper] with lower < "
                         f"upper, found {v!r}")
    obj = t.get("objective")
    if obj is not None and not isinstance(obj, str):
        raise InputError(f"{w}: expected 'objective' as 'min:RESPONSE' or 'max:RESPONSE', found {obj!r}")
    return DesignTable(variables={k: (float(a), float(b)) for k, (a, b) in v.items()}, objective=obj,
                       constraints=_strings(t, "constraints", w), aperture=_positive(t, "aperture", w))


#: top-level tables read here
TABLES = ("control", "deployment", "lpv", "report", "packaged", "design")


def deep_merge(base: dict, override: dict) -> dict:
    """Return ``base`` with ``override`` merged in, tables recursively."""
    out = copy.deepcopy(base)
    for k, v in override.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def problem_from_dict(d: dict, where: str, build) -> Problem:
    """The :class:`Problem` of the parsed file ``d``; ``build(dict, where)`` builds the
    packaged System from the file with ``[packaged]`` merged in."""
    raw = {k: d[k] for k in TABLES if k in d}
    packaged = None
    if "packaged" in d:
        p = d["packaged"]
        if not isinstance(p, dict):
            raise InputError(f"{where}: expected [packaged] to be a table of overrides, found {p!r}")
        nested = sorted(set(p) & set(TABLES))
        if nested:
            raise InputError(f"{where} [packaged]: expected overrides of the structure's tables, "
                             f"found the problem table(s) {nested} (they belong to the file itself)")
        rest = {k: v for k, v in d.items() if k not in TABLES}
        merged = deep_merge(rest, p)
        if "rest_lengths" in p:                       # rest lengths are replaced, not merged
            merged["rest_lengths"] = p["rest_lengths"]
        elif "rest_lengths" in rest:
            merged.pop("rest_lengths")                 # the deployed ones do not hold there
        merged["name"] = f"{d.get('name', where)}-packaged"
        packaged = build(merged, f"{where} [packaged]")
    return Problem(control=_control(d["control"], where) if "control" in d else HinfWeights(),
                   deployment=_deployment(d["deployment"], where) if "deployment" in d else None,
                   lpv=_lpv(d["lpv"], where) if "lpv" in d else None,
                   report=_report(d["report"], where) if "report" in d else ReportSettings(),
                   packaged=packaged, raw=raw,
                   design=_design(d["design"], where) if "design" in d else None)


def lpv_path(system) -> str:
    """The stage-base rule of ``system``'s LPV grid: its ``[lpv] path``, else
    "table-7-7-bases" for a two-stage system and "auto" for M >= 3 stages (where the Table 7.7
    rule, a stage-2 rule, does not apply)."""
    p = system.problem.lpv.path if system.problem.lpv is not None else None
    if p is not None:
        return p
    return "table-7-7-bases" if system.M == 2 else "auto"


def default_u_m(system) -> float:
    """u_m of W_u = I / u_m when the file gives none: 0.5 % of the mean bar length [m] (7.4's
    0.01 m for l = 2.2 m and 1.8 m, 0.02 m for 3 m are 0.46-0.67 % of l)."""
    return float(0.005 * np.mean(system.l))

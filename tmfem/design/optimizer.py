"""Optimal design of a tensegrity-membrane system on the MTC (or SBC) model with exact gradients.

Problem: minimise or maximise one response f(p) of :data:`tmfem.design.sensitivities.RESPONSES`
over the design variables p (:mod:`tmfem.design.variables`) within their bounds, subject to
constraints ``response <= bound``, ``>= bound`` or ``== bound`` (a bound ``start``: the start
design's value). Every evaluation solves the static equilibrium (warm-started from the last
one) and :func:`design_sensitivities`; the optimiser is scipy's SLSQP on the variables scaled
to [0, 1] by their bounds, the objective by its start value and each constraint by its bound.

A constraint on a vector response (``freq``, ``omega2``, ``tendon_stress``, ``bar_buckling``,
...) is one constraint per entry, so that a bound on the lowest m eigenvalues stays smooth when
modes cross (the *bound formulation*); an objective on a vector response (``max freq``) is the
bound formulation of its extreme: maximise beta subject to f_i >= beta for every entry (``min``:
minimise beta subject to f_i <= beta), beta an extra variable.

At the optimum the Lagrange multipliers of the active constraints and bounds are the
non-negative least-squares solution of the stationarity condition
grad f + sum_i mu_i grad g_i = 0 (in the scaled variables, g_i <= 0 the active constraints
and bounds), and the KKT residual is its norm relative to |grad f|.
"""
from __future__ import annotations

import csv
import dataclasses
import logging
import math
import os
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize, nnls

from tmfem.design.configuration import redesign_of, warm_start
from tmfem.design.sensitivities import RESPONSES, design_sensitivities
from tmfem.design.variables import apply_design, parse_variables, variable_values
from tmfem.errors import ConvergenceError, InputError
from tmfem.io.run import partial_name

log = logging.getLogger(__name__)

SENSES = ("<=", ">=", "==")
#: a constraint is active when its scaled value is within this of its bound
ACTIVE_TOL = 1e-4
#: a constraint is violated at a design when its scaled value exceeds its bound by more than this
VIOLATION_TOL = 1e-6


@dataclass(frozen=True)
class Constraint:
    """``response sense bound`` (bound None: the start design's value)."""

    response: str
    sense: str
    bound: float | None

    def label(self) -> str:
        return f"{self.response}{self.sense}{'start' if self.bound is None else f'{self.bound:g}'}"


#: why a no-wrinkling constraint over a whole membrane held at its corners by points fails
WRINKLING_HINT = ("the membrane is held at its corners by points, so it is in compression near its corners and "
                  "free edges whatever the prestress and membrane_min_principal >= 0 over the whole membrane "
                  "is infeasible: restrict it to the usable surface with an aperture (--aperture A, "
                  "[design] aperture or aperture=A: a fraction of the inradius, e.g. 0.8; "
                  "docs/guides/design.md, Aperture)")


def parse_objective(text: str) -> tuple:
    """``"max:freq"`` / ``"min:mass"`` (also ``"max freq"``) -> (sense, response)."""
    parts = str(text).replace(":", " ").split()
    if len(parts) != 2 or parts[0] not in ("min", "max"):
        raise InputError(f"objective: expected 'min:RESPONSE' or 'max:RESPONSE', found {text!r}")
    _check_response(parts[1], "objective")
    return parts[0], parts[1]


def parse_constraint(text: str) -> Constraint:
    """``"tendon_stress<=6.32e7"``, ``"freq>=0.2"``, ``"mass==start"`` -> :class:`Constraint`."""
    for sense in SENSES:
        if sense in str(text):
            name, _, value = str(text).partition(sense)
            name, value = name.strip(), value.strip()
            _check_response(name, "constraint")
            if value == "start":
                return Constraint(name, sense, None)
            try:
                bound = float(value)
            except ValueError:
                bound = math.nan
            if not math.isfinite(bound):
                raise InputError(f"constraint {text!r}: expected a finite bound or 'start', found {value!r}")
            return Constraint(name, sense, bound)
    raise InputError(f"constraint: expected 'RESPONSE<=BOUND', '>=' or '==', found {text!r}")


def _check_response(name: str, what: str) -> None:
    base, _, idx = name.rpartition("_")
    if name not in RESPONSES and not (base in RESPONSES and idx.isdigit()):
        raise InputError(f"{what}: unknown response {name!r}; expected one of {sorted(RESPONSES)} "
                         f"(vectors also as name_i)")


@dataclass
class OptimizationResult:
    """Outcome of :func:`optimize`.

    names, lower, upper : the variables and their bounds; start, optimum : their values;
    start_responses, optimum_responses : objective and constraint responses at both designs;
    active : the active constraints and bounds with their multipliers; kkt_residual : the
    stationarity residual relative to |grad f|; history : rows (iteration, objective,
    max_violation, step); system : the optimal System (rest lengths included); state : the
    MTC positions (3, n_nodes) at the optimum (a warm start for further solves);
    success, message, evaluations, time_s; violated : the constraints the returned design
    violates by more than :data:`VIOLATION_TOL` (scaled by their bound), with the violation
    (and, for a no-wrinkling constraint without an aperture, :data:`WRINKLING_HINT` as ``hint``).
    """

    names: list
    lower: np.ndarray
    upper: np.ndarray
    start: np.ndarray
    optimum: np.ndarray
    start_responses: dict
    optimum_responses: dict
    active: list
    kkt_residual: float
    history: list
    system: object
    success: bool
    message: str
    evaluations: int
    time_s: float
    objective: str = ""
    constraints: list = field(default_factory=list)
    state: np.ndarray | None = None
    violated: list = field(default_factory=list)


class _Evaluator:
    """Equilibrium and sensitivities at a design p, cached for the last p; each equilibrium
    starts from the last one (from the undeformed membrane when that fails)."""

    def __init__(self, system, names, model, mesh_n, k, aperture, model_options):
        from tmfem.models.mtc.model import MTCModel
        from tmfem.models.sbc.model import SBCModel
        if model not in ("mtc", "sbc"):
            raise InputError(f"optimize: expected model 'mtc' or 'sbc', found {model!r}")
        self.Model = MTCModel if model == "mtc" else SBCModel
        self.start = "x0" if model == "mtc" else "start"
        self.system, self.mesh_n, self.k, self.aperture = system, mesh_n, k, aperture
        self.model_options = model_options
        m = self.Model(system, mesh_n=mesh_n, **model_options)
        self.r0 = m.rest_lengths.copy()
        self.vars = parse_variables(system, names)
        self.redesign = redesign_of(m) if any(v.kind == "angle" for v in self.vars) else None
        self.p0 = variable_values(system, self.r0, self.vars)
        self.x = None
        self.last = None
        self.count = 0

    def __call__(self, p):
        p = np.asarray(p, dtype=float)
        if self.last is not None and np.array_equal(self.last[0], p):
            return self.last[1]
        sysp, r = apply_design(self.system, self.r0, self.vars, p, redesign=self.redesign)
        m = self.Model(sysp, mesh_n=self.mesh_n, rest_lengths=r, **self.model_options)
        try:
            if self.x is None:
                eq = m.equilibrium()
            else:
                eq = m.equilibrium(**({self.start: self.x} if self.redesign is None else warm_start(m, self.x)))
        except ConvergenceError:
            if self.x is None:
                raise
            log.info("optimize: no equilibrium from the last design's state; from the undeformed membrane")
            eq = m.equilibrium()
        self.x = eq.state
        s = design_sensitivities(m, equilibrium=eq, variables=[v.name for v in self.vars], k=self.k,
                                 aperture=self.aperture)
        self.count += 1
        self.last = (p.copy(), (s, sysp))
        return s, sysp


def _entries(s, name: str):
    """Values (n,) and gradients (n, n_var) of a response (a scalar is one entry)."""
    v, g = s.value(name), s.gradient(name)
    return np.atleast_1d(v).astype(float), np.reshape(g, (-1, len(s.names)))


def optimize(system, *, objective: str, constraints=(), variables=None, model: str = "mtc",
             mesh_n: int = 10, k: int = 4,
             aperture: float | None = None, max_iter: int = 60, tol: float = 1e-6, history=None,
             model_options=None) -> OptimizationResult:
    """Optimal design of ``system`` (module docstring).

    Parameters
    ----------
    system : System
    objective : str
        ``"min:RESPONSE"`` or ``"max:RESPONSE"`` (:data:`RESPONSES`; ``freq_1`` an entry).
    constraints : sequence of str or Constraint
        ``"tendon_stress<=6.32e7"``, ``"freq>=0.1"``, ``"mass<=start"``.
    variables : dict {name: (lower, upper)}, optional
        Design variables and bounds; default the system file's ``[design] variables``.
    model : {"mtc", "sbc"}
        The finite-element model.
    mesh_n : int
        Membrane elements per side of the MTC model.
    k : int
        Number of lowest eigenvalues (the bound formulation's m).
    aperture : float, optional
        The wrinkling indicator's aperture (:func:`design_sensitivities`).
    max_iter : int
        SLSQP's iteration limit.
    tol : float
        SLSQP's tolerance on the scaled objective.
    history : path, optional
        CSV of the iterations (iteration, objective, max_violation, step), written as
        ``NAME.csv.partial`` while the run goes and renamed when it ends.
    model_options : dict, optional
        Further options of the model (``tendon_elements``, ``attachment``, ...).
    """
    t0 = time.perf_counter()
    sense, obj = parse_objective(objective)
    cons = [c if isinstance(c, Constraint) else parse_constraint(c) for c in constraints]
    if variables is None:
        design = getattr(system.problem, "design", None)
        if design is None:
            raise InputError("optimize: expected design variables (a [design] table in the system "
                             "file or variables={name: (lower, upper)}), found none")
        variables = design.variables
    if not isinstance(variables, dict) or not variables:
        raise InputError(f"optimize: expected variables as {{name: (lower, upper)}}, found {variables!r}")
    names = list(variables)
    lo = np.array([float(variables[n][0]) for n in names])
    hi = np.array([float(variables[n][1]) for n in names])
    if not np.all(np.isfinite(lo) & np.isfinite(hi) & (hi > lo)):
        raise InputError(f"optimize: expected finite bounds lower < upper, found {dict(zip(names, zip(lo, hi)))}")
    ev = _Evaluator(system, names, model, mesh_n, k, aperture, dict(model_options or {}))
    p0 = ev.p0
    if np.any(p0 < lo - 1e-12) or np.any(p0 > hi + 1e-12):
        bad = [n for n, a, b, v in zip(names, lo, hi, p0) if not a - 1e-12 <= v <= b + 1e-12]
        raise InputError(f"optimize: the start design lies outside the bounds of {bad}: "
                         f"{dict(zip(names, p0.tolist()))}")
    s0, _ = ev(p0)
    span = hi - lo
    n = len(names)
    f_vals0, _ = _entries(s0, obj)
    vector_obj = f_vals0.size > 1
    f_scale = max(float(np.abs(f_vals0).max()), 1e-30)
    sign = -1.0 if sense == "max" else 1.0
    bounds_of = {c: (c.bound if c.bound is not None else
                     (float(np.max(_entries(s0, c.response)[0])) if c.sense == "<="
                      else float(np.min(_entries(s0, c.response)[0])))) for c in cons}
    for c in cons:
        if c.sense == "==" and _entries(s0, c.response)[0].size > 1:
            raise InputError(f"constraint {c.label()}: expected a scalar response for '==', found a vector")
    c_scale = {c: max(abs(b), float(np.abs(_entries(s0, c.response)[0]).max()) if b == 0 else abs(b), 1e-30)
               for c, b in bounds_of.items()}

    def p_of(z):
        return lo + span * np.clip(z[:n], 0.0, 1.0)

    def objective_fn(z):
        if vector_obj:                                # bound formulation: beta = z[n]
            g = np.zeros(z.size)
            g[n] = sign
            return sign * z[n], g
        s, _ = ev(p_of(z))
        v, gr = _entries(s, obj)
        g = np.zeros(z.size)
        g[:n] = sign * gr[0] * span / f_scale
        return sign * v[0] / f_scale, g

    def constraint_rows(z):
        """Scaled g(z) <= 0 rows and their Jacobian, equality rows flagged; rows identical at
        the start (members equal by symmetry) are one row, the largest of them."""
        g, J, eqf = all_rows(z)
        pick = np.array([grp[int(np.argmax(g[grp]))] for grp in groups], dtype=int)
        return g[pick], J[pick], eqf[pick]

    def all_rows(z):
        s, _ = ev(p_of(z))
        rows, jac, eq = [], [], []
        if vector_obj:
            v, gr = _entries(s, obj)
            for vi, gi in zip(v, gr):
                row = np.zeros(z.size)
                row[:n] = sign * gi * span / f_scale         # max: beta - f_i <= 0
                row[n] = -sign
                rows.append(-sign * (z[n] - vi / f_scale))
                jac.append(row)
                eq.append(False)
        for c in cons:
            v, gr = _entries(s, c.response)
            b, sc = bounds_of[c], c_scale[c]
            sgn = -1.0 if c.sense == ">=" else 1.0
            for vi, gi in zip(v, gr):
                row = np.zeros(z.size)
                row[:n] = sgn * gi * span / sc
                rows.append(sgn * (vi - b) / sc)
                jac.append(row)
                eq.append(c.sense == "==")
        return np.array(rows), np.array(jac).reshape(len(rows), z.size), np.array(eq, dtype=bool)

    z0 = (p0 - lo) / span
    if vector_obj:
        z0 = np.append(z0, f_vals0.min() / f_scale if sense == "max" else f_vals0.max() / f_scale)
    groups = _identical_rows(*all_rows(z0))
    bounds = [(0.0, 1.0)] * n + ([(None, None)] if vector_obj else [])
    scipy_cons = []
    _, _, eq0 = constraint_rows(z0)
    for kind, want in (("ineq", False), ("eq", True)):
        idx = np.flatnonzero(eq0 == want)
        if idx.size:
            scipy_cons.append({"type": kind, "fun": lambda z, i=idx: -constraint_rows(z)[0][i],
                               "jac": lambda z, i=idx: -constraint_rows(z)[1][i]})
    hist, writer = [], _HistoryWriter(history)
    state = {"z": z0.copy(), "it": 0}

    def record(z):
        g, _, eqf = constraint_rows(z)
        viol = float(np.max(np.where(eqf, np.abs(g), np.maximum(g, 0.0)), initial=0.0))
        f = _objective_value(ev, p_of(z), obj, sense, vector_obj)
        step = float(np.linalg.norm((z[:n] - state["z"][:n]) * span))
        row = (state["it"], f, viol, step)
        hist.append(row)
        writer.write(row)
        state["z"], state["it"] = z.copy(), state["it"] + 1
        log.info("optimize it %d: %s = %.6g, max violation %.3g, step %.3g", *row[:1], obj, *row[1:])

    try:
        record(z0)
        res = minimize(objective_fn, z0, jac=True, method="SLSQP", bounds=bounds, constraints=scipy_cons,
                       callback=record, options={"maxiter": max_iter, "ftol": tol})
    except BaseException:
        writer.close(complete=False)                  # the history keeps its .partial name
        raise
    writer.close(complete=True)
    z = res.x
    p = p_of(z)
    s, sysp = ev(p)
    # multipliers: NNLS on the stationarity of the active constraints and bounds (scaled)
    _, gobj = objective_fn(z)
    g, J, eqf = constraint_rows(z)
    act = np.flatnonzero(eqf | (g > -ACTIVE_TOL))
    every = _row_labels(cons, s, obj, vector_obj)
    labels = [every[grp[0]] + (f" (with {len(grp) - 1} equal)" if len(grp) > 1 else "") for grp in groups]
    A = [J[i] for i in act]
    act_labels = [labels[i] for i in act]
    for j in range(n):
        for side, at in (("lower", z[j] <= ACTIVE_TOL), ("upper", z[j] >= 1 - ACTIVE_TOL)):
            if at:
                row = np.zeros(z.size)
                row[j] = -1.0 if side == "lower" else 1.0
                A.append(row)
                act_labels.append(f"{names[j]} {side} bound")
    if A:
        Am = np.array(A).T
        free_sign = np.array([eqf[i] for i in act] + [False] * (len(A) - act.size))
        # equality multipliers have any sign: split them into two non-negative columns
        Aext = np.hstack([Am, -Am[:, free_sign]])
        mu_ext, _ = nnls(Aext, -gobj)
        mu = mu_ext[:len(A)].copy()
        mu[free_sign] -= mu_ext[len(A):]
        resid = gobj + Am @ mu
    else:
        mu, resid = np.zeros(0), gobj
    kkt = float(np.linalg.norm(resid) / max(np.linalg.norm(gobj), 1e-30))
    active = [{"constraint": lab, "multiplier": float(m)} for lab, m in zip(act_labels, mu)]
    over = np.where(eqf, np.abs(g), g)
    n_obj = _entries(s, obj)[0].size if vector_obj else 0        # the bound formulation's rows: not the user's
    violated = [{"constraint": labels[i], "violation": float(over[i]), **_hint(labels[i], aperture)}
                for i in np.flatnonzero(over > VIOLATION_TOL) if groups[i][0] >= n_obj]
    wanted = [obj] + [c.response for c in cons]
    return OptimizationResult(
        names=names, lower=lo, upper=hi, start=p0, optimum=p,
        start_responses=_responses(s0, wanted), optimum_responses=_responses(s, wanted),
        active=active, kkt_residual=kkt, history=hist, system=sysp, success=bool(res.success),
        message=str(res.message), evaluations=ev.count, time_s=time.perf_counter() - t0,
        objective=f"{sense}:{obj}", constraints=[c.label() for c in cons], state=ev.x, violated=violated)


def _hint(label: str, aperture) -> dict:
    """``{"hint": WRINKLING_HINT}`` for a violated no-wrinkling constraint without an aperture."""
    return {"hint": WRINKLING_HINT} if aperture is None and label.startswith("membrane_min_principal>") else {}


def _identical_rows(g, J, eqf) -> list:
    """Index groups of constraint rows equal in value and gradient (to 1e-9 of their size):
    SLSQP's subproblem is degenerate with repeated rows."""
    key = np.column_stack([g, J, eqf])
    tol = 1e-9 * max(float(np.abs(key).max(initial=0.0)), 1e-30)
    groups, used = [], np.zeros(len(g), dtype=bool)
    for i in range(len(g)):
        if not used[i]:
            same = np.flatnonzero(~used & np.all(np.abs(key - key[i]) <= tol, axis=1))
            used[same] = True
            groups.append(same)
    return groups


def _objective_value(ev, p, obj, sense, vector_obj) -> float:
    s, _ = ev(p)
    v, _ = _entries(s, obj)
    return float(v.min() if sense == "max" else v.max()) if vector_obj else float(v[0])


def _row_labels(cons, s, obj, vector_obj) -> list:
    labels = []
    if vector_obj:
        labels += [f"{obj}_{i + 1} >= bound" for i in range(_entries(s, obj)[0].size)]
    for c in cons:
        m = _entries(s, c.response)[0].size
        labels += [c.label()] if m == 1 else [f"{c.response}_{i + 1}{c.sense}{c.label().split(c.sense)[1]}"
                                              for i in range(m)]
    return labels


def _responses(s, names) -> dict:
    out = {}
    for nm in dict.fromkeys(names):
        v = s.value(nm)
        out[nm] = np.asarray(v).tolist() if np.ndim(v) else float(v)
    return out


class _HistoryWriter:
    """CSV rows written as they come to ``NAME.csv.partial``, renamed to ``NAME.csv`` at the end."""

    def __init__(self, path):
        self.path = path
        self.fh = None
        if path is not None:
            self.fh = open(partial_name(path), "w", newline="")
            self.w = csv.writer(self.fh)
            self.w.writerow(["iteration", "objective", "max_violation", "step"])
            self.fh.flush()

    def write(self, row) -> None:
        if self.fh is not None:
            self.w.writerow([row[0]] + [f"{v:.10g}" for v in row[1:]])
            self.fh.flush()

    def close(self, *, complete: bool) -> None:
        if self.fh is not None:
            self.fh.close()
            if complete:
                os.replace(partial_name(self.path), self.path)
            self.fh = None


def result_dict(result: OptimizationResult) -> dict:
    """The JSON-able fields of a result (without the System)."""
    d = {f.name: getattr(result, f.name) for f in dataclasses.fields(result) if f.name not in ("system", "state")}
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in d.items()}

"""The model interface every model of a tensegrity-membrane system implements, and the registry.

A model is built from one :class:`~tmfem.system.System` and a backend, and offers

* named signals: ``input_names`` (tendon rest lengths ``r_<tendon>``, the control inputs u of
  eq. 5.19), ``output_names`` (bar coordinates q of eqs. 3.1-3.2 and membrane deflections
  ``w_k`` at the monitored points, eqs. 5.36-5.38), and the nominal input ``u0``;
* ``equilibrium(u=None)``: the static equilibrium for rest lengths u (default ``u0``), in the
  model's own configuration type (positions for the FE models, coordinates z for the COM);
* ``modes(k=..., ...)``: natural modes about the prestressed equilibrium (eq. 5.32);
* ``plant(...)``: the equation of motion as a :class:`Plant` that the simulation driver and
  Park's method (eqs. 5.34-5.35) integrate, with the inputs u(t) entering the residual -- so
  a controller can drive any model, the FE models included.

A :class:`Plant` is the second-order residual form of a model about a start state,

``residual(x, v, a, t, u) -> r``              eq. 5.27 (COM) or M a + C v + f_int(x; u) (FE);
``newton_matrix(x, v, a, t, cv, ca, u)``      K + cv C + ca M (the Newton matrix of eq. 5.34);
``outputs(x, v, u) -> y``                     the measured signals, ordered as ``output_names``;
``x0, v0``                                    the start state; ``u0`` the nominal input;

plus ``input_names``/``output_names``. Models register a :class:`ModelSpec` in
:data:`MODELS`: the CLI reads its ``--model`` choices and each model's own options from
there, and refuses an option that the chosen model does not take.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.tension_field import MEMBRANE_LAWS


class Plant(Protocol):
    """The equation of motion of a model with its inputs (module docstring)."""

    input_names: list
    output_names: list
    u0: np.ndarray
    x0: np.ndarray
    v0: np.ndarray

    def residual(self, x, v, a, t, u) -> np.ndarray: ...

    def newton_matrix(self, x, v, a, t, cv, ca, u): ...

    def outputs(self, x, v, u) -> np.ndarray: ...


class Model(Protocol):
    """What every model of a system provides (module docstring)."""

    system: object
    input_names: list
    output_names: list
    u0: np.ndarray

    def equilibrium(self, u=None): ...

    def modes(self, *, k: int): ...

    def plant(self, **options) -> Plant: ...


@dataclass(frozen=True)
class Option:
    """A model option as the CLI offers it: ``--flag``, its default, the commands it applies
    to (None: every command of the model) and argparse keyword arguments (type, help, ...)."""

    flag: str
    default: object = None
    commands: tuple | None = None
    kwargs: dict = field(default_factory=dict)

    @property
    def dest(self) -> str:
        return self.flag.lstrip("-").replace("-", "_")


@dataclass(frozen=True)
class ModelSpec:
    """A registered model: its name, a one-line description, the commands that serve it, its
    options (shared ones by name, see :data:`SHARED_OPTIONS`) and ``build(system, options,
    backend) -> model`` with ``options`` the dict of its option values by dest;
    ``uses_backend`` False for a model whose solves are small and dense (``--backend`` is then
    refused)."""

    name: str
    help: str
    commands: tuple
    build: object
    shared: tuple = ()
    own: tuple = ()
    uses_backend: bool = True


#: options that more than one model takes
SHARED_OPTIONS = {
    "mesh": Option("--mesh", 10, None, dict(type=int, metavar="N", help=(
        "membrane elements per side of each of the N quadrilateral patches (the dissertation's "
        "4 x 10 x 10: 10)"))),
    "tendon_elements": Option("--tendon-elements", 3, None, dict(
        type=int, help="truss elements per tendon (6.2: 3)")),
    "attachment": Option("--attachment", "point", None, dict(
        choices=("point", "distributed"), help=(
            "membrane corners pinned to the bar tops (point) or spread over a small corner patch "
            "(distributed)"))),
    "patch": Option("--patch", None, None, dict(type=float, metavar="R", help=(
        "patch radius [m] of --attachment distributed (default 10%% of r_mb)"))),
    "membrane_law": Option("--membrane-law", "svk", None, dict(choices=MEMBRANE_LAWS, help=(
        "membrane law (of the shell's lamina in the SBC model): St.Venant-Kirchhoff (svk, "
        "eq. 4.9) or tension-field (wrinkling, docs/guides/wrinkling.md)"))),
    "rayleigh": Option("--rayleigh", None, ("vibrate",), dict(
        type=float, nargs=2, metavar=("ALPHA", "BETA"),
        help="Rayleigh damping C = ALPHA M + BETA K_0 (default none)")),
}

MODELS: dict[str, ModelSpec] = {}


def register(spec: ModelSpec) -> ModelSpec:
    """Add ``spec`` to :data:`MODELS` (one entry per name)."""
    if spec.name in MODELS and MODELS[spec.name] is not spec:
        raise InputError(f"model registry: {spec.name!r} is registered already")
    for s in spec.shared:
        if s not in SHARED_OPTIONS:
            raise InputError(f"model registry: {spec.name}: unknown shared option {s!r}")
    MODELS[spec.name] = spec
    return spec


def _load_builtin() -> None:
    # the built-in models register themselves when their spec modules are imported
    import tmfem.models.com.spec  # noqa: F401
    import tmfem.models.mtc.spec  # noqa: F401
    import tmfem.models.sbc.spec  # noqa: F401


def all_models() -> dict[str, ModelSpec]:
    """Every registered model, by name."""
    _load_builtin()
    return dict(sorted(MODELS.items()))


def get_spec(name: str) -> ModelSpec:
    """The registered model ``name``."""
    models = all_models()
    if name not in models:
        raise InputError(f"model: expected one of {sorted(models)}, found {name!r}")
    return models[name]


def models_for(command: str) -> dict[str, ModelSpec]:
    """The models that command ``command`` serves."""
    return {n: s for n, s in all_models().items() if command in s.commands}


def model_options(name: str, command: str) -> list[Option]:
    """The options model ``name`` takes in command ``command`` (shared ones first)."""
    spec = get_spec(name)
    opts = [SHARED_OPTIONS[s] for s in spec.shared] + list(spec.own)
    return [o for o in opts if o.commands is None or command in o.commands]


def resolve_options(name: str, command: str, given: dict) -> dict:
    """The option values of model ``name`` in ``command``: ``given`` maps option dest -> value
    for every model option the command offers (None where not given). An option given for a
    model that does not take it is refused, naming the models it belongs to."""
    mine = {o.dest: o for o in model_options(name, command)}
    wrong = [d for d, v in given.items() if v is not None and d not in mine]
    if wrong:
        def flag(d):
            return "--" + d.replace("_", "-")
        owners = {m: [o.dest for o in model_options(m, command) if o.dest not in mine]
                  for m in models_for(command) if m != name}
        parts = []
        for d in wrong:
            ms = [m for m, theirs in owners.items() if d in theirs]
            part = f"{flag(d)} belongs to --model {', '.join(ms) or '(none)'}"
            for m in ms:
                names = [flag(o) for o in sorted(owners[m])]
                if len(names) > 1:
                    part += f" ({', '.join(names[:-1])} and {names[-1]} belong to --model {m})"
            parts.append(part)
        raise InputError(f"{command} --model {name}: option does not apply: " + "; ".join(parts))
    return {d: (given.get(d) if given.get(d) is not None else o.default) for d, o in mine.items()}


def split_perturbation(perturb: dict | None, names) -> tuple[np.ndarray, np.ndarray]:
    """Initial offsets and rates of the coordinates ``names`` from a perturbation by name.

    Parameters
    ----------
    perturb : dict or None
        ``{"theta_11_dot": 0.01, "theta_12": 0.001}``: a coordinate name adds to its value,
        ``<name>_dot`` to its rate (6.5.1-6.5.2).
    names : list of str
        The coordinates (``system.q_names`` for the FE models, ``model.z_names`` for the COM).

    Returns
    -------
    d, d_dot : ndarray (len(names),)
    """
    names = list(names)
    accepted = names + [n + "_dot" for n in names]
    d = np.zeros(len(names))
    d_dot = np.zeros(len(names))
    for k, val in (perturb or {}).items():
        if k not in accepted:
            raise InputError(f"perturbation: unknown state {k!r}; expected one of {accepted}")
        if not np.isfinite(val):
            raise InputError(f"perturbation {k}: expected a finite number, found {val!r}")
        i = accepted.index(k)
        if i < len(names):
            d[i] += val
        else:
            d_dot[i - len(names)] += val
    return d, d_dot


class LinearPlant:
    """The linear second-order plant M a + C v + K (x - x_e) + B (u - u_e) = 0 with outputs
    y = y_e + C_y [x - x_e; v] (a linearisation, eq. 5.33), as a :class:`Plant`.

    Parameters
    ----------
    M, C, K, B : ndarray
    x_e, u_e, y_e : ndarray
        Operating point.
    Cy : ndarray (ny, 2 n)
    x0, v0 : ndarray, optional
        Start (default the operating point at rest).
    """

    def __init__(self, *, M, C, K, B, Cy, x_e, u_e, y_e, input_names, output_names,
                 x0=None, v0=None):
        self.M, self.C, self.K, self.B, self.Cy = (np.asarray(a, dtype=float) for a in (M, C, K, B, Cy))
        self.x_e, self.u0, self.y_e = (np.asarray(a, dtype=float) for a in (x_e, u_e, y_e))
        self.input_names, self.output_names = list(input_names), list(output_names)
        self.x0 = self.x_e.copy() if x0 is None else np.asarray(x0, dtype=float)
        self.v0 = np.zeros_like(self.x_e) if v0 is None else np.asarray(v0, dtype=float)

    def residual(self, x, v, a, t, u):
        """M a + C v + K (x - x_e) + B (u - u_e)."""
        return self.M @ a + self.C @ v + self.K @ (x - self.x_e) + self.B @ (u - self.u0)

    def jacobians(self, x, v, a, t, u):
        """(K, C, M)."""
        return self.K, self.C, self.M

    def outputs(self, x, v, u):
        """y_e + C_y [x - x_e; v]."""
        return self.y_e + self.Cy @ np.concatenate([x - self.x_e, v])

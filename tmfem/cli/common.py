"""Options shared by subcommands (which system to use) and the checks every command runs on
its options before any expensive step (docs/guides/cli.md)."""
from __future__ import annotations

import argparse
import logging
import math
import os
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from tmfem.errors import InputError, ResourceLimit, shorten
from tmfem.resources import (MEMORY_FRACTION, check_membrane_modes, check_mesh_budget,
                             check_system_budget, fe_bytes, machine_memory, require_memory)
from tmfem.system import System, load_preset, load_system

log = logging.getLogger(__name__)


def add_system_args(parser: argparse.ArgumentParser) -> None:
    """Add ``[spec] --preset NAME --as-printed`` to a subcommand."""
    parser.add_argument("spec", nargs="?", help="system file (TOML); or use --preset")
    parser.add_argument("--preset", help="built-in system (see `tmfem presets`)")
    parser.add_argument("--as-printed", action="store_true",
                        help="use the dissertation's printed values instead of the consistent ones")


def system_from_args(args: argparse.Namespace) -> System:
    """The system named by ``spec`` or ``--preset`` (exactly one)."""
    if (args.spec is None) == (args.preset is None):
        out = getattr(args, "out", None)
        if args.spec is None and isinstance(out, str) and out.lower().endswith(".toml"):
            # `export FILE.toml` alone: argparse gives the one positional to the output file
            raise InputError(f"expected a system file and an output file, found only {out!r}: "
                             f"the output file comes after the system file")
        raise InputError("expected exactly one of a system file or --preset NAME")
    if args.preset is not None:
        return load_preset(args.preset, as_printed=args.as_printed)
    if args.as_printed:
        raise InputError("--as-printed applies to presets only")
    system = load_system(args.spec)
    check_system_budget(system, source=str(args.spec))
    return system


def add_model_args(parser, command: str, *, default: str, capability: str | None = None,
                   stages=()) -> None:
    """``--model`` (the registered models with ``capability``), ``--backend`` and the options
    of every such model for a run of ``stages`` (:func:`tmfem.models.registry.model_options`),
    each as an argument made from the option's data and saying which models take it; read them
    with :func:`model_from_args`, which refuses an option the chosen model does not take."""
    from tmfem.models.registry import model_options, models_with
    from tmfem.solvers.backends import AUTO_CROSSOVER_DOFS, backend_names
    specs = models_with(capability)
    parser.add_argument("--model", choices=sorted(specs), default=default,
                        help="; ".join(f"{n}: {s.help}" for n, s in specs.items())
                        + f" (default {default})")
    parser.add_argument("--backend", choices=backend_names(), default=None,
                        help="linear-algebra backend of the finite-element models (default auto: "
                             f"petsc from {AUTO_CROSSOVER_DOFS} free dofs when installed, else scipy; "
                             "docs/guides/backends.md)")
    options, owners = {}, {}
    for name in specs:
        for o in model_options(name, stages):
            options.setdefault(o.name, o)
            owners.setdefault(o.name, []).append(name)
    group = parser.add_argument_group("model options (refused for a model that does not take them)")
    for name, o in options.items():
        default_text = "" if o.default is None else f"; default {o.default}"
        kwargs = {"default": None, "help": f"{o.doc.replace('%', '%%')} [--model "
                                           f"{', '.join(owners[name])}{default_text}]"}
        if o.choices is not None:
            kwargs["choices"] = o.choices
        elif o.type is not str:
            kwargs["type"] = o.type
        if o.nargs is not None:
            kwargs["nargs"] = o.nargs
        if o.metavar is not None:
            kwargs["metavar"] = o.metavar
        group.add_argument(o.flag, **kwargs)
    parser.set_defaults(_model_options=tuple(options), _model_stages=tuple(stages),
                        _model_capability=capability)


def model_options_from_args(args, command: str):
    """(system, options, spec): the system, the chosen model's option values
    (:func:`tmfem.models.registry.resolve_options`: an option the model does not take is
    refused) and its registry entry; the resource checks run here, before any model is built."""
    from tmfem.models.registry import get_spec, models_with, resolve_options
    spec = get_spec(args.model)
    given = {d: getattr(args, d) for d in args._model_options}
    options = resolve_options(args.model, given, stages=args._model_stages, command=command,
                              among=models_with(args._model_capability))
    if args.backend is not None and not spec.uses_backend:
        raise InputError(f"{command} --model {args.model}: option does not apply: --backend "
                         f"(the {args.model} model solves small dense systems; --backend is for "
                         "the finite-element models)")
    system = system_from_args(args)
    if isinstance(options.get("mesh"), int):
        backend = backend_from_args(args) if spec.uses_backend else "scipy"
        dofs = check_model_budget(system, mesh=options["mesh"],
                                  tendon_elements=options.get("tendon_elements") or 1,
                                  bar_elements=options.get("bar_elements"),
                                  dofs_per_node=spec.dofs_per_node, backend=backend)
        if isinstance(getattr(args, "modes", None), int):     # modal: the exact DOFs later
            check_modes_budget(dofs, modes=args.modes, given=f"--mesh {options['mesh']}",
                               backend=backend, dofs_per_node=spec.dofs_per_node)
    if "attachment" in options:
        check_attachment_options(system, attachment=options["attachment"], patch=options["patch"])
    if options.get("membrane_modes") is not None:
        check_membrane_modes(options["membrane_modes"])
    check_outputs(args, command)
    return system, options, spec


def default_monitor(system) -> list[str]:
    """Monitored nodes of Figures 6.1 (B_14 of 1-4) and 6.5-6.7 (B_11, A_21, B_21 of 2-3)."""
    if system.M == 1:
        return [f"B_1{system.N}"] if system.N < 10 else [f"B_1,{system.N}"]
    return ["B_11", "A_21", "B_21"]


def requested_files(args, command: str, accepted, names) -> dict:
    """The file options of ``names`` given in ``args`` (by dest), refused (before any work)
    where they are not among those the chosen model's report writes (``accepted``)."""
    given = {k: getattr(args, k) for k in names if getattr(args, k, None)}
    wrong = [k for k in given if k not in accepted]
    if wrong:
        flags = "/".join("--" + k.replace("_", "-") for k in wrong)
        raise InputError(f"{command} --model {args.model}: option does not apply: {flags} (the "
                         f"{args.model} model writes "
                         + (", ".join("--" + k.replace("_", "-") for k in accepted) or "no files")
                         + ")")
    return given


#: output options of the finite-element commands (static, modal, vibrate, converge) and their
#: suffixes; ``vibrate --vtk`` names a directory
OUTPUT_SUFFIXES = {"vtk": (".vtu", ".vtk", ".xdmf"), "png": (".png",), "stress_plot": (".png",),
                   "wrinkle_plot": (".png",), "csv": (".csv",), "plot": (".png",)}


def check_outputs(args, command: str) -> None:
    """Check the output options of ``args`` (:data:`OUTPUT_SUFFIXES`) before any work."""
    for dest, suffixes in OUTPUT_SUFFIXES.items():
        path = getattr(args, dest, None)
        if path is None:
            continue
        if command == "vibrate" and dest == "vtk":
            output_dir(path, option="--vtk")
        else:
            output_file(path, option="--" + dest.replace("_", "-"), suffixes=suffixes)


def backend_from_args(args) -> str:
    """The backend name of ``--backend`` (default ``auto``: the model chooses by its free dofs,
    :func:`tmfem.solvers.backends.choose_backend`)."""
    return args.backend or "auto"


def with_backend(out: dict, model) -> dict:
    """``out`` with the key ``backend``: the backend the model solved with."""
    return {**out, "backend": model.backend.name}


def model_from_args(args, command: str):
    """(model, options, spec): the model chosen by ``--model``, built from the system and its
    options (:func:`model_options_from_args`), and its registry entry."""
    system, options, spec = model_options_from_args(args, command)
    model = spec.build(system, options, backend_from_args(args))
    if spec.uses_backend:
        say(command, f"backend {model.backend.name} ({model.ndof} free dofs)")
    rest = model.u0
    if np.ndim(rest) == 1 and len(rest) == len(system.tendons):
        warn_long_rest_lengths(system, rest)     # all slack: an error before the solve
    return model, options, spec


def add_attachment_args(parser) -> None:
    """``--attachment`` / ``--patch``: membrane corner attachment of the plane-stress FE
    (``equilibrium``, ``study``) and of the MTC model (``converge``)."""
    parser.add_argument("--attachment", choices=("point", "distributed"), default="point",
                        help="membrane corner attachment: 'point' (default, the dissertation's "
                             "model; singular, F_Delta and the rest lengths drift like 1/log(n) "
                             "with the mesh) or 'distributed' (corner spread over a patch by an "
                             "RBE3-type affine coupling; converges under mesh refinement)")
    parser.add_argument("--patch", type=float, default=None, metavar="R",
                        help="patch radius [m] of --attachment distributed (default 10%% of "
                             "r_mb). It must reach beyond the corner's two edge neighbours: "
                             "with fewer than 3 nodes it is an error, with only those it "
                             "reduces to the point attachment (1-4 at the default patch: "
                             "--mesh 5 fails, --mesh 10 equals point; use --mesh >= 20)")


def add_membrane_law_arg(parser) -> None:
    """``--membrane-law``: membrane law of the plane-stress FE (``equilibrium``, ``study``) and
    of the MTC model (``converge``; the registry's option for ``static``/``modal``/``vibrate``)."""
    from tmfem.fem.tension_field import MEMBRANE_LAWS
    parser.add_argument("--membrane-law", choices=MEMBRANE_LAWS, default="svk",
                        help="membrane law: St.Venant-Kirchhoff (svk, default, eq. 4.9/5.8) or "
                             "tension-field (wrinkling; docs/guides/wrinkling.md)")


def parse_perturbation(items, names) -> dict:
    """``["theta_11_dot=0.01", ...]`` -> {name: value}; names must be states of the model,
    each at most once, values finite."""
    out, seen = {}, set()
    for it in items or []:
        if "=" not in it:
            raise InputError(f"perturbation: expected NAME=VALUE, found {it!r}")
        k, v = it.split("=", 1)
        k = k.strip()
        if k not in names:
            raise InputError(f"perturbation: unknown state {k!r}; expected one of {names}")
        try:
            out[k] = float(v)
        except ValueError:
            raise InputError(f"perturbation {k}: expected a number, found {v!r}") from None
        if not math.isfinite(out[k]):
            raise InputError(f"perturbation {k}: expected a finite number, found {v!r}")
        if k in seen:
            raise InputError(f"--perturb: each state at most once, found {k} twice")
        seen.add(k)
    return out


#: ``--quiet`` of the running command (set by :func:`tmfem.cli.main`)
QUIET = {"on": False}


def say(command: str, text: str) -> None:
    """A command's progress line ``tmfem <command>: <text>`` on stderr, the CLI's message
    channel; silent with ``--quiet`` (errors, warnings and failed checks still print)."""
    if not QUIET["on"]:
        print(f"tmfem {command}: {text}", file=sys.stderr, flush=True)


def warn(command: str, text: str) -> None:
    """A command's warning through the CLI's message channel: ``tmfem: WARNING: <text>`` on
    stderr (the ``tmfem`` logger), each text once per run, also with ``--quiet``."""
    logging.getLogger(f"tmfem.cli.{command}").warning(text)


def progress_options() -> dict:
    """tqdm options of the CLI's bars: drawn on stderr only when it is a terminal, never
    with ``--quiet`` or ``TQDM_DISABLE`` set (not empty, 0 or false); plain ASCII with
    ``NO_COLOR`` set (docs/guides/cli.md, "Progress and messages")."""
    off = (QUIET["on"] or not sys.stderr.isatty()
           or os.environ.get("TQDM_DISABLE", "").strip().lower() not in ("", "0", "false"))
    return {"file": sys.stderr, "disable": off, "ascii": bool(os.environ.get("NO_COLOR"))}


@contextmanager
def progress_bar(t_end: float, dt: float, label: str):
    """A tqdm progress bar over the steps of a time run, as a ``progress(step, n_steps)``
    callback (:func:`progress_options`; closed on exit, also on an error)."""
    from tqdm import tqdm
    bar = tqdm(total=int(round(t_end / dt)), desc=label, unit="step", leave=False,
               mininterval=0.5, **progress_options())

    def update(k, n):
        bar.update(k - bar.n)
    try:
        yield update
    finally:
        bar.close()
# ---------------------------------------------------------------------------- validation
# Checked before any expensive step, so that a bad option costs nothing (docs/guides/cli.md).

def finite_float(text: str) -> float:
    """argparse ``type``: a finite float (``inf``, ``nan`` and ``1e999`` are refused)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, found {text!r}") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, found {text!r}")
    return v


def positive_float(text: str) -> float:
    """argparse ``type``: a finite float > 0."""
    v = finite_float(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, found {text!r}")
    return v


def positive_int(text: str) -> int:
    """argparse ``type``: an integer >= 1."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, found {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, found {text!r}")
    return v


def output_file(path, *, option: str, suffixes) -> Path:
    """An output file checked before the work starts: known suffix, parent directory
    creatable and writable, not a directory (:func:`tmfem.io.paths.check_path`)."""
    from tmfem.io.paths import check_path

    if path is None:
        return None
    try:
        return check_path(path, suffixes=tuple(suffixes))
    except InputError as exc:
        raise InputError(f"{option}: {exc}") from None


def output_dir(path, *, option: str) -> Path:
    """An output directory, created now and checked writable, before the work starts."""
    from tmfem.io.paths import check_dir

    if path is None:
        return None
    try:
        return check_dir(path)
    except InputError as exc:
        raise InputError(f"{option}: {exc}") from None


# the estimates live in the library (tmfem.resources); the CLI checks them before any work


MAX_STEPS = 200_000


def check_time_steps(*, t_end: float, dt: float, states: int | None = None,
                     given: str = "--t-end") -> int:
    """Number of time steps of a run of ``t_end`` s in steps of ``dt`` s, refused when it
    is zero (dt > t_end), over ``MAX_STEPS`` or when the histories (``states`` values per
    step, 8 bytes each, position and velocity) would not fit in memory; ``given`` names where
    ``t_end`` comes from (the option, or a file's field)."""
    from tmfem.simulation.driver import check_time_grid

    steps = check_time_grid(t_end, dt)
    if steps > MAX_STEPS:
        raise ResourceLimit(f"{given} {t_end:g} s / --dt {dt:g} s = {steps:,} steps; the limit "
                            f"is {MAX_STEPS:,} (raise --dt or lower {given})")
    if states is not None:
        need = 2 * 8.0 * states * steps
        limit = MEMORY_FRACTION * machine_memory()
        if need > limit:
            raise ResourceLimit(f"{steps:,} steps x {states:,} states need {need / 2**30:.1f} "
                                f"GiB of history; the limit is {limit / 2**30:.1f} GiB")
    return steps


#: Most ParaView frames of one series (a frame is a .vtu of the whole configuration: 1-4's
#: COM frames take ~50 kB, so 10 000 frames ~0.5 GB of disk)
MAX_FRAMES = 10_000


def check_frames(*, steps: int, every: int, option: str | None = "--vtk-every") -> int:
    """ParaView frames of a time run of ``steps`` steps, one every ``every`` (set by
    ``option``, or fixed when it is None: ``deploy --vtk``): at most :data:`MAX_FRAMES`.
    Returns the number of frames."""
    frames = steps // every + 1
    if frames > MAX_FRAMES:
        given, fix = ((f"{option} {every}", f"raise {option} or lower --t-end") if option else
                      (f"--vtk (a frame every {every} steps)", "raise --dt or lower --t-end"))
        raise ResourceLimit(f"{given}: {steps:,} steps give {frames:,} ParaView frames; "
                            f"the limit is {MAX_FRAMES:,} ({fix})")
    return frames


def backend_plan(name: str | None):
    """``plan(dofs) -> (backend, ranks, ranks on this machine)``: what ``--backend name``
    (None or ``auto``: :func:`tmfem.solvers.backends.choose_backend`) will solve a model of
    about ``dofs`` DOFs with, under the launcher's ranks: the memory estimate's input
    (:func:`tmfem.resources.fe_bytes`)."""
    from tmfem.solvers.backends import choose_backend
    from tmfem.solvers.petsc_loader import launched_local_ranks, launched_ranks

    def plan(dofs: int):
        chosen = choose_backend(n_dofs=dofs) if name in (None, "auto") else name
        return chosen, launched_ranks(), launched_local_ranks()
    return plan


def check_model_budget(system: System, *, mesh: int, tendon_elements: int = 1,
                       bar_elements: int | None = None, modes: int | None = None,
                       dofs_per_node: int = 3, backend: str | None = None) -> int:
    """Refuse a finite-element model of ``system`` that would not fit this machine, before
    it is built: the membrane mesh (:func:`check_mesh_budget`, ``dofs_per_node`` 3 for the
    membrane elements, 6 for shells) plus 3 (k - 1) DOFs per tendon of k truss elements and,
    with ``bar_elements`` b (beam bars, 6 DOFs per node), 6 (3 b - 1) per bar; ``modes`` must
    stay below the DOF estimate, and the eigen solver's basis (2 ``modes`` vectors of the
    DOFs, 8 bytes an entry) must fit beside the model. ``backend``: the ``--backend`` given
    (None: auto), whose memory per DOF the estimate takes (:func:`backend_plan`). Returns
    the DOF estimate."""
    extra = 3 * len(system.tendons) * (tendon_elements - 1)
    what = [f"{len(system.tendons)} tendons x {tendon_elements} elements"]
    if bar_elements is not None:
        extra += 6 * system.M * system.N * (3 * bar_elements - 1)
        what.append(f"{system.M * system.N} bars x {bar_elements} beam elements")
    given = f"--mesh {mesh} --tendon-elements {tendon_elements}" + (
        f" --bar-elements {bar_elements}" if bar_elements is not None else "")
    dofs = check_mesh_budget(N=system.N, n=mesh, option=given, dofs_per_node=dofs_per_node,
                             extra_dofs=extra, extra_text=", ".join(what),
                             plan=backend_plan(backend))
    if modes is not None and modes >= dofs:
        raise InputError(f"--modes {modes}: expected fewer modes than the model's about {dofs:,} "
                         "DOFs")
    if modes is not None:
        check_modes_budget(dofs, modes=modes, given=given, backend=backend,
                           dofs_per_node=dofs_per_node)
    return dofs


def check_modes_budget(dofs: int, *, modes: int, given: str = "", backend: str | None = None,
                       dofs_per_node: int = 3) -> None:
    """Refuse ``--modes`` whose eigen-solver basis (2 ``modes`` vectors of ``dofs`` entries,
    8 bytes each, on every rank) does not fit beside the model
    (:func:`tmfem.resources.fe_bytes` of the backend, :func:`backend_plan`)."""
    name, ranks, here = backend_plan(backend)(dofs)
    require_memory(fe_bytes(dofs, backend=name, ranks=ranks, ranks_here=here,
                            dofs_per_node=dofs_per_node) + here * 16.0 * dofs * modes,
                   given=f"--modes {modes} {given}".strip(),
                   what=f"the model's about {dofs:,} DOFs with a basis of 2 x {modes} vectors")


def check_com_modes(system: System, *, modes: int, membrane_modes=None) -> int:
    """``--modes`` of the control-oriented model: at most its n_q + K coordinates. Returns K
    (``membrane_modes`` or the system's default)."""
    from tmfem.models.com.model import default_membrane_modes
    K = default_membrane_modes(system) if membrane_modes is None else membrane_modes
    states = len(system.q_names) + K
    if modes > states:
        raise InputError(f"--modes {modes}: the control-oriented model of {system.name} has "
                         f"{states} coordinates (n_q + K = {len(system.q_names)} + {K}); expected "
                         f"--modes <= {states}")
    return K


def check_attachment_options(system: System, *, attachment: str, patch) -> None:
    """``--patch`` applies to ``--attachment distributed`` only and must fit the membrane
    (:func:`check_patch`)."""
    if patch is not None and attachment != "distributed":
        raise InputError(f"--patch: option does not apply with --attachment {attachment} "
                         f"(expected --attachment distributed), found --patch {patch}")
    check_patch(system, patch)


def check_patch(system: System, patch) -> None:
    """``--patch R``: 0 < R < half the shortest membrane edge (the patches of neighbouring
    corners would overlap)."""
    if patch is None:
        return

    c = system.membrane_corners
    edge = float(np.min(np.linalg.norm(np.roll(c, -1, axis=1) - c, axis=0)))
    if not (math.isfinite(patch) and 0 < patch < edge / 2):
        raise InputError(f"--patch: expected 0 < R < {edge / 2:.4g} m (half the shortest "
                         f"membrane edge of {system.name}), found {patch!r}")


def warn_long_rest_lengths(system: System, rest=None) -> list[str]:
    """Tendons whose rest length is at least their length in the design configuration
    (slack there: a tension-only member carries no force). Returns one message per tendon
    and logs each; all of them is an error (nothing prestresses the system)."""
    r = system.rest_lengths if rest is None else np.asarray(rest, dtype=float)
    if r is None:
        return []
    L = system.tendon_lengths()
    names = system.tendon_names()
    msgs = [f"tendon {names[k]}: rest length {r[k]:.5g} m >= its length {L[k]:.5g} m in the "
            "design configuration; it is slack there" for k in np.flatnonzero(r >= L)]
    if msgs and len(msgs) == len(names):
        raise InputError(f"every tendon is slack at the design configuration: rest lengths "
                         f"{shorten(np.round(r, 5).tolist())} m >= lengths "
                         f"{shorten(np.round(L, 5).tolist())} m; "
                         "nothing prestresses the system (expected rest lengths shorter than "
                         "the tendons)")
    for m in msgs:
        log.warning(m)
    return msgs


# ---------------------------------------------------------------------------- progress
class Progress:
    """The CLI's progress bar (tqdm on stderr, :func:`progress_options`).

    ``step(label)`` advances one stage of a multi-stage job and names the next one;
    ``callback(desc)`` returns a ``progress(done, total)`` function for library loops
    (e.g. :func:`tmfem.equilibrium.symmetric_map.equilibrium_map`) drawn as a nested bar.
    """

    def __init__(self, *, total: int, desc: str):
        from tqdm import tqdm

        self._tqdm = tqdm
        self.bar = tqdm(total=total, desc=desc, unit="step", leave=True, dynamic_ncols=True,
                        **progress_options())

    def step(self, label: str) -> None:
        self.bar.set_postfix_str(label, refresh=False)
        self.bar.update(1)

    def note(self, label: str) -> None:
        """Show what runs now without advancing."""
        self.bar.set_postfix_str(label)

    def callback(self, desc: str):
        inner = {}

        def progress(done: int, total: int) -> None:
            if "bar" not in inner:
                inner["bar"] = self._tqdm(total=total, desc=desc, leave=False, position=1,
                                          dynamic_ncols=True, **progress_options())
            inner["bar"].n = done
            inner["bar"].refresh()
            if done >= total:
                inner["bar"].close()
        return progress

    def close(self) -> None:
        self.bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

"""Options shared by subcommands: which system to use."""
from __future__ import annotations

import argparse
from contextlib import contextmanager

from tmfem.errors import InputError
from tmfem.system import System, load_preset, load_system


def add_system_args(parser: argparse.ArgumentParser) -> None:
    """Add ``[spec] --preset NAME --as-printed`` to a subcommand."""
    parser.add_argument("spec", nargs="?", help="system file (TOML); or use --preset")
    parser.add_argument("--preset", help="built-in system (see `tmfem presets`)")
    parser.add_argument("--as-printed", action="store_true",
                        help="use the dissertation's printed values instead of the consistent ones")


def system_from_args(args: argparse.Namespace) -> System:
    """The system named by ``spec`` or ``--preset`` (exactly one)."""
    if (args.spec is None) == (args.preset is None):
        raise InputError("expected exactly one of a system file or --preset NAME")
    if args.preset is not None:
        return load_preset(args.preset, as_printed=args.as_printed)
    if args.as_printed:
        raise InputError("--as-printed applies to presets only")
    return load_system(args.spec)


def add_model_args(parser, command: str, *, default: str) -> None:
    """``--model`` (the registry's models that serve ``command``), ``--backend`` and every
    model option of ``command``, each saying which models take it; read them with
    :func:`model_from_args`, which refuses an option the chosen model does not take."""
    from tmfem.models.base import model_options, models_for
    from tmfem.solvers.backends import backend_names
    specs = models_for(command)
    parser.add_argument("--model", choices=sorted(specs), default=default,
                        help="; ".join(f"{n}: {s.help}" for n, s in specs.items())
                        + f" (default {default})")
    parser.add_argument("--backend", choices=backend_names(), default=None,
                        help="linear-algebra backend of the finite-element models (default scipy; "
                             "petsc: docs/backends.md)")
    options, owners = {}, {}
    for name in specs:
        for o in model_options(name, command):
            options.setdefault(o.dest, o)
            owners.setdefault(o.dest, []).append(name)
    group = parser.add_argument_group("model options (refused for a model that does not take them)")
    for dest, o in options.items():
        default_text = "" if o.default is None else f"; default {o.default}"
        group.add_argument(o.flag, **{**o.kwargs, "default": None,
                                      "help": f"{o.kwargs.get('help', '')} [--model "
                                              f"{', '.join(owners[dest])}{default_text}]"})
    parser.set_defaults(_model_option_dests=tuple(options))


def model_options_from_args(args, command: str):
    """(system, options): the system and the chosen model's option values
    (:func:`tmfem.models.base.resolve_options`: an option the model does not take is refused)."""
    from tmfem.models.base import get_spec, resolve_options
    spec = get_spec(args.model)
    given = {d: getattr(args, d) for d in args._model_option_dests}
    options = resolve_options(args.model, command, given)
    if args.backend is not None and not spec.uses_backend:
        raise InputError(f"{command} --model {args.model}: option does not apply: --backend "
                         f"(the {args.model} model solves small dense systems; --backend is for "
                         "the finite-element models)")
    return system_from_args(args), options


def model_from_args(args, command: str):
    """(model, options): the model chosen by ``--model``, built from the system and its
    options (:func:`model_options_from_args`)."""
    from tmfem.models.base import get_spec
    system, options = model_options_from_args(args, command)
    return get_spec(args.model).build(system, options, args.backend or "scipy"), options


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
                             "tension-field (wrinkling; docs/wrinkling.md)")


def parse_perturbation(items, names) -> dict:
    """``["theta_11_dot=0.01", ...]`` -> {name: value}; names must be states of the model."""
    out = {}
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
    return out


@contextmanager
def progress_bar(t_end: float, dt: float, label: str):
    """A tqdm progress bar over the steps of a time run, as a ``progress(step, n_steps)``
    callback (on stderr; closed on exit, also on an error)."""
    from tqdm import tqdm
    bar = tqdm(total=int(round(t_end / dt)), desc=label, unit="step", leave=False,
               mininterval=0.5)

    def update(k, n):
        bar.update(k - bar.n)
    try:
        yield update
    finally:
        bar.close()

"""The registry of models and the options each model declares (as data, for any front end).

A model registers a :class:`ModelSpec`: its name, a one-line description, ``build(system,
options, backend) -> model``, its options as :class:`Option` records (name, type, default,
doc, choices) and its capabilities. The command-line interface turns the options into
arguments (:func:`tmfem.cli.common.add_model_args`) and refuses an option that the chosen
model does not take (:func:`resolve_options`).

An option belongs to the *stages* of a run it changes (``"equilibrium"``: the static solve,
``"dynamics"``: the equation of motion; None: the model itself), and a command asks for the
options of the stages it runs. A capability says what a model offers beyond the interface of
:mod:`tmfem.models.base` (``"finite-element"``: a membrane mesh with node positions, stress
fields and mesh convergence).
"""
from __future__ import annotations


from tmfem.errors import InputError
from tmfem.models.com.spec import SPEC as COM
from tmfem.models.mtc.spec import SPEC as MTC
from tmfem.models.sbc.spec import SPEC as SBC
from tmfem.models.spec import ModelSpec, Option

__all__ = ["ModelSpec", "Option", "MODELS", "register", "all_models", "get_spec",
           "models_with", "model_options", "resolve_options"]

MODELS: dict[str, ModelSpec] = {}


def register(spec: ModelSpec) -> ModelSpec:
    """Add ``spec`` to :data:`MODELS` (one entry per name)."""
    if spec.name in MODELS and MODELS[spec.name] is not spec:
        raise InputError(f"model registry: {spec.name!r} is registered already")
    MODELS[spec.name] = spec
    return spec


for _spec in (COM, MTC, SBC):
    register(_spec)


def all_models() -> dict[str, ModelSpec]:
    """Every registered model, by name."""
    return dict(sorted(MODELS.items()))


def get_spec(name: str) -> ModelSpec:
    """The registered model ``name``."""
    if name not in MODELS:
        raise InputError(f"model: expected one of {sorted(MODELS)}, found {name!r}")
    return MODELS[name]


def models_with(capability: str | None = None) -> dict[str, ModelSpec]:
    """The models that have ``capability`` (None: every model)."""
    return {n: s for n, s in all_models().items()
            if capability is None or capability in s.capabilities}


def model_options(name: str, stages=()) -> list[Option]:
    """The options of model ``name`` that a run of ``stages`` takes: the model's own (no
    stage) and those of the given stages."""
    return [o for o in get_spec(name).options if o.stage is None or o.stage in stages]


def resolve_options(name: str, given: dict, *, stages=(), command: str = "",
                    among=None) -> dict:
    """The option values of model ``name`` in a run of ``stages``: ``given`` maps option name
    -> value for every model option offered (None where not given). An option given for a
    model that does not take it is refused, naming the models (of ``among``, default all) it
    belongs to; ``command`` prefixes the message."""
    mine = {o.name: o for o in model_options(name, stages)}
    wrong = [d for d, v in given.items() if v is not None and d not in mine]
    if wrong:
        owners = {m: [o.name for o in model_options(m, stages) if o.name not in mine]
                  for m in (among or all_models()) if m != name}
        parts = []
        for d in wrong:
            ms = [m for m, theirs in owners.items() if d in theirs]
            part = f"{Option.flag_of(d)} belongs to --model {', '.join(ms) or '(none)'}"
            for m in ms:
                names = [Option.flag_of(o) for o in sorted(owners[m])]
                if len(names) > 1:
                    part += f" ({', '.join(names[:-1])} and {names[-1]} belong to --model {m})"
            parts.append(part)
        raise InputError(f"{command} --model {name}: option does not apply: " + "; ".join(parts))
    return {d: (given.get(d) if given.get(d) is not None else o.default) for d, o in mine.items()}

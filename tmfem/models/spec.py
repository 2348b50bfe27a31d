"""How a model describes itself to the registry (:mod:`tmfem.models.registry`): its options as
data and its build function."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Option:
    """A model option as data: ``name`` (a Python identifier; the command line spells it
    ``--name-with-dashes``), its ``type`` (int, float, str), ``default`` (None: decided by
    the model), a one-paragraph ``doc``, the allowed ``choices``, ``nargs`` values (None: one)
    with their ``metavar``, and the ``stage`` of a run it changes (``"equilibrium"``,
    ``"dynamics"``; None: the model itself)."""

    name: str
    type: type = str
    default: object = None
    doc: str = ""
    choices: tuple | None = None
    nargs: int | None = None
    metavar: object = None
    stage: str | None = None

    @property
    def flag(self) -> str:
        """The command-line spelling ``--name-with-dashes``."""
        return self.flag_of(self.name)

    @staticmethod
    def flag_of(name: str) -> str:
        return "--" + name.replace("_", "-")


@dataclass(frozen=True)
class ModelSpec:
    """A registered model: its ``name``, a one-line ``help``, ``build(system, options,
    backend) -> model`` with ``options`` the dict of its option values by name, its
    ``options`` (:class:`Option`), ``uses_backend`` (False for a model whose solves are small
    and dense: a backend is then refused), its ``capabilities`` (:mod:`tmfem.models.registry`),
    the unknowns per membrane node ``dofs_per_node`` (for the memory estimate of a mesh) and
    ``post``, the module with its reports (``static_summary``, ``modal_summary``,
    ``format_static``, ``format_modal``, ...), imported when a report is asked for;
    ``equilibrium_kwargs(options)`` and ``plant_kwargs(options)`` map the option values of the
    ``"equilibrium"`` and ``"dynamics"`` stages to keyword arguments of the model's
    ``equilibrium`` and ``plant`` (default: none)."""

    name: str
    help: str
    build: Callable
    options: tuple = ()
    uses_backend: bool = True
    capabilities: tuple = ()
    dofs_per_node: int = 3
    post: str | None = None
    equilibrium_kwargs: Callable = lambda options: {}
    plant_kwargs: Callable = lambda options: {}

    def report(self):
        """The module of the model's reports (``post``)."""
        import importlib
        return importlib.import_module(self.post)

"""The MTC model in the model registry: its command-line options and how they build it."""
from __future__ import annotations

from tmfem.errors import InputError
from tmfem.models.base import ModelSpec, Option, register
from tmfem.models.mtc.design import design_mesh_of
from tmfem.models.mtc.model import MTCModel

STATIC = ("static", "modal", "vibrate")


def apply_rest_lengths(system, text):
    """The system and the ``rest_lengths`` argument of :class:`MTCModel` for a
    ``--rest-lengths`` text: ``system``/``design``/``design@n``/``mtc`` or ``GROUP=VALUE[,...]``."""
    if text is None or text in ("system", "design", "mtc") or design_mesh_of(text) is not None:
        return system, text
    values = {}
    for item in text.split(","):
        key, sep, val = item.partition("=")
        try:
            values[key.strip()] = float(val)
        except ValueError:
            sep = ""
        if not sep:
            raise InputError(f"--rest-lengths: expected system, design, design@n, mtc or "
                             f"GROUP=VALUE[,...] "
                             f"(e.g. S1=1.5025), found {text!r}")
    return system.with_rest_lengths(values), "system"


def sequence_of(mesh: int, sequence):
    """Coarsest mesh of the static mesh sequencing chosen by ``--sequence`` (default 10 when
    the mesh is finer than 20, else none; 0 disables)."""
    if sequence is None:
        return 10 if mesh > 20 else None
    return sequence or None


def build(system, options: dict, backend) -> MTCModel:
    """The MTC model of ``system`` with the registry's option values."""
    system, rest = apply_rest_lengths(system, options["rest_lengths"])
    return MTCModel(system, mesh_n=options["mesh"], tendon_elements=options["tendon_elements"],
                    attachment=options["attachment"], patch=options["patch"], rest_lengths=rest,
                    backend=backend, membrane_law=options["membrane_law"])


SPEC = register(ModelSpec(
    name="mtc", help="membrane-truss-cable finite-element model (4.4): membrane elements, truss "
                     "bars, tension-only truss tendons",
    commands=("static", "modal", "vibrate"), build=build,
    shared=("mesh", "tendon_elements", "attachment", "patch", "membrane_law", "rayleigh"),
    own=(
        Option("--rest-lengths", None, None, dict(help=(
            "tendon rest lengths: 'system' (default when the system has them), 'design' (default "
            "otherwise: the ch. 3 design, eq. 3.8, on this model's mesh and attachment, so it "
            "changes with --mesh), 'design@n' (the ch. 3 design on the n x n mesh with point "
            "corners, e.g. design@10 as in 6.2: the same rest lengths on every mesh; the default "
            "of `tmfem converge`), 'mtc' (those that make the design an exact equilibrium of this "
            "model) or values per group/tendon, e.g. 'S1=1.5025'"))),
        Option("--start", "undeformed", ("static", "modal"), dict(
            choices=("undeformed", "design"),
            help="start of the static iteration (the undeformed membrane, as in 6.2)")),
        Option("--sequence", None, STATIC, dict(type=int, help=(
            "mesh sequencing of the static solve from this coarse n, halving (default: 10 when "
            "--mesh > 20, else none; 0 disables)"))),
    )))

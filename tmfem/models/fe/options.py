"""Options that both finite-element models take (and ``mesh``, which the control-oriented model
takes for its membrane basis), as data for the registry (:mod:`tmfem.models.registry`)."""
from __future__ import annotations

from tmfem.fem.tension_field import MEMBRANE_LAWS
from tmfem.models.spec import Option

MESH = Option("mesh", int, 10, metavar="N", doc=(
    "membrane elements per side of each of the N quadrilateral patches (the dissertation's "
    "4 x 10 x 10: 10)"))
TENDON_ELEMENTS = Option("tendon_elements", int, 3, "truss elements per tendon (6.2: 3)")
ATTACHMENT = Option("attachment", str, "point", choices=("point", "distributed"), doc=(
    "membrane corners pinned to the bar tops (point) or spread over a small corner patch "
    "(distributed)"))
PATCH = Option("patch", float, None, metavar="R", doc=(
    "patch radius [m] of --attachment distributed (default 10% of r_mb)"))
MEMBRANE_LAW = Option("membrane_law", str, "svk", choices=MEMBRANE_LAWS, doc=(
    "membrane law (of the shell's lamina in the SBC model): St.Venant-Kirchhoff (svk, eq. 4.9) "
    "or tension-field (wrinkling, docs/guides/wrinkling.md)"))
RAYLEIGH = Option("rayleigh", float, (0.0, 0.0), nargs=2, metavar=("ALPHA", "BETA"), stage="dynamics",
                  doc="Rayleigh damping C = ALPHA M + BETA K_0 (0 0: undamped)")
SEQUENCE = Option("sequence", int, None, stage="equilibrium", doc=(
    "mesh sequencing of the static solve from this coarse n, halving (default: 10 when --mesh "
    "> 20, else none; 0 disables)"))

#: the options of both finite-element models
FE_OPTIONS = (MESH, TENDON_ELEMENTS, ATTACHMENT, PATCH, MEMBRANE_LAW, RAYLEIGH)


def sequence_of(mesh: int, sequence):
    """Coarsest mesh of the static mesh sequencing chosen by ``sequence`` (default 10 when
    the mesh is finer than 20, else none; 0 disables)."""
    if sequence is None:
        return 10 if mesh > 20 else None
    return sequence or None


def rayleigh_kwargs(options: dict) -> dict:
    """Keyword arguments ``alpha``, ``beta`` of an FE model's ``plant`` from ``rayleigh``."""
    alpha, beta = options["rayleigh"]
    return {"alpha": alpha, "beta": beta}

"""The membrane as data for the output files: a mesh placed in space with its fields."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tmfem.errors import InputError
from tmfem.mesh.polygon import MembraneMesh


#: The one name of the membrane displacement field in every output (design, MTC statics,
#: COM series, report): displacement [m] from the flat reference membrane, 3 components in
#: the floating frame O_f of the current corners (eq. 3.4). (The element benchmarks'
#: ``Structure.to_meshio`` writes ``displacement``: a generic shell in the inertial frame.)
DISPLACEMENT_FIELD = "displacement_Of"


@dataclass(frozen=True)
class MembraneField:
    """A membrane mesh placed in space, with data for the output files.

    Attributes
    ----------
    mesh : MembraneMesh
        The flat reference mesh (2, nn) / (4, ne) in the floating frame O_f.
    x : ndarray (3, nn)
        Current node positions in the inertial frame.
    point_data : dict
        Arrays of shape (nn,) or (c, nn) (e.g. displacement (3, nn)).
    cell_data : dict
        Arrays of shape (ne,) or (c, ne) (e.g. ``von_mises``, ``sigma_p1``).
    """

    mesh: MembraneMesh
    x: np.ndarray
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)

    def __post_init__(self):
        nn = self.mesh.p.shape[1]
        ne = self.mesh.t.shape[1]
        x = np.asarray(self.x, dtype=float)
        if x.shape != (3, nn):
            raise InputError(f"membrane field: expected positions x of shape (3, {nn}), "
                             f"found {x.shape}")
        if not np.all(np.isfinite(x)):
            raise InputError("membrane field: positions x have non-finite entries")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "point_data",
                           {k: check_data(f"membrane point data {k!r}", v, nn)
                            for k, v in self.point_data.items()})
        object.__setattr__(self, "cell_data",
                           {k: check_data(f"membrane cell data {k!r}", v, ne)
                            for k, v in self.cell_data.items()})


def check_data(what: str, value, n: int) -> np.ndarray:
    """Data of shape (n,) or (c, n) -> (n,) or (n, c) (meshio's row-major layout)."""
    a = np.asarray(value)
    if a.ndim == 1 and a.shape[0] == n:
        return a
    if a.ndim == 2 and a.shape[1] == n:
        return np.ascontiguousarray(a.T)
    raise InputError(f"{what}: expected shape ({n},) or (c, {n}), found {a.shape}")

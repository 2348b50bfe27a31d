"""A generalised LPV plant known at any parameter value, from what a user brings.

:func:`plant_function` turns the plant argument of :func:`tmfem.control.lpv.gridded_synthesis.lpvsyn`
into one callable rho -> (A, B, C, D) with the partition of python-control's ``hinfsyn``
(inputs [w, u], outputs [p, y]; the last ``ncon`` inputs and the last ``nmeas`` outputs):

* a callable ``P(rho)`` returning a ``StateSpace`` or a tuple (A, B, C, D): evaluated exactly
  everywhere (design grid and verification grid);
* a ``StateSpace`` (an LTI plant, the same at every rho);
* a tuple (A, B, C, D) of arrays of shape ``grid_shape + (rows, cols)``, a
  :class:`~tmfem.control.lpv.plant.GriddedLPV` or a
  :class:`~tmfem.control.lpv.generalized_plant.GeneralizedLPV` (state feedback): known at the grid
  points and interpolated between them (:meth:`GriddedLPV.interpolate`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.control.lpv.plant import GriddedLPV, grid_point_text
from tmfem.control.lpv.generalized_plant import GeneralizedLPV
from tmfem.errors import InputError


@dataclass
class PlantFunction:
    """rho -> (A, B, C, D) with sizes; ``axes`` the plant's own grid (None for a function);
    ``parameter_names`` the gridded plant's (None: rho0, rho1, ...)."""

    evaluate: object
    n: int
    m: int
    p: int
    axes: list | None
    interpolated: bool
    rate_bounds: np.ndarray | None = None
    parameter_names: list | None = None

    def point_text(self, rho, *, rates: bool = False) -> str:
        """A parameter point (or with ``rates`` a rate vertex) as text with units
        (:func:`~tmfem.control.lpv.plant.grid_point_text`)."""
        names = self.parameter_names or [f"rho{k}" for k in range(np.size(rho))]
        return grid_point_text(names, rho, rates=rates)

    def at(self, rho) -> tuple:
        A, B, C, D = _matrices(self.evaluate(np.asarray(rho, dtype=float)), rho)
        if (A.shape, B.shape, C.shape, D.shape) != ((self.n, self.n), (self.n, self.m), (self.p, self.n),
                                                      (self.p, self.m)):
            raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected A {self.n}x{self.n}, "
                             f"B {self.n}x{self.m}, C {self.p}x{self.n}, D {self.p}x{self.m} as at the first "
                             f"point, found {A.shape}, {B.shape}, {C.shape}, {D.shape}")
        return A, B, C, D


def _matrices(value, rho) -> tuple:
    """(A, B, C, D) as finite real arrays from a StateSpace or a 4-tuple."""
    if hasattr(value, "A") and hasattr(value, "dt"):
        if value.dt not in (0, None):
            raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected a continuous-time "
                             f"system, found sample time {value.dt} (discrete-time LPV synthesis is not "
                             "implemented)")
        value = (value.A, value.B, value.C, value.D)
    if not (isinstance(value, (tuple, list)) and len(value) == 4):
        raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected a StateSpace or a tuple "
                         f"(A, B, C, D), found {type(value).__name__}")
    out = []
    for nm, M in zip("ABCD", value):
        M = np.atleast_2d(np.asarray(M))
        if np.iscomplexobj(M):
            raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected real {nm}, found "
                             "complex entries")
        M = M.astype(float)
        if not np.all(np.isfinite(M)):
            raise InputError(f"LPV plant at rho = {np.asarray(rho).tolist()}: expected finite {nm}, found "
                             "NaN or inf")
        out.append(M)
    return tuple(out)


def grid_axes(grid) -> list:
    """The axes of ``grid`` (a sequence of 1-D arrays, one 1-D array for one parameter, or a
    dict name -> values), validated: non-empty, finite, strictly increasing."""
    if isinstance(grid, dict):
        grid = list(grid.values())
    if grid is None:
        raise InputError("LPV synthesis: expected a grid (one array of parameter values per parameter), "
                         "found none")
    one = isinstance(grid, np.ndarray) and grid.ndim == 1 or \
        isinstance(grid, (list, tuple)) and len(grid) > 0 and all(np.isscalar(v) for v in grid)
    axes = []
    for k, a in enumerate([grid] if one else list(grid)):
        a = np.atleast_1d(np.asarray(a, dtype=float))
        if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
            raise InputError(f"LPV grid: expected axis {k} as a non-empty, finite, strictly increasing "
                             f"sequence, found {np.asarray(a).tolist()}")
        axes.append(a)
    if not axes:
        raise InputError("LPV grid: expected at least one parameter axis, found none")
    return axes


def plant_function(P, *, axes, interpolation: str = "multilinear") -> PlantFunction:
    """:class:`PlantFunction` of a plant argument (module docstring), checked against the
    design grid ``axes``: a gridded plant must have every design point among its own grid
    points (the design uses the data, not an interpolation)."""
    if isinstance(P, GeneralizedLPV):
        P = GriddedLPV(axes=P.axes, parameter_names=P.parameter_names, rate_bounds=P.rate_bounds,
                       A=P.A, B=np.concatenate([P.B1, P.B2], -1), C=P.C1,
                       D=np.concatenate([P.D11, P.D12], -1),
                       state_names=[f"x{i}" for i in range(P.A.shape[-1])],
                       input_names=[f"in{i}" for i in range(P.B1.shape[-1] + P.B2.shape[-1])],
                       output_names=[f"p{i}" for i in range(P.C1.shape[-2])], interpolation=interpolation)
    elif isinstance(P, (tuple, list)) and len(P) == 4 and all(np.ndim(M) >= 2 for M in P):
        A, B, C, D = (np.asarray(M) for M in P)
        shp = tuple(a.size for a in axes)
        for nm, M in zip("ABCD", (A, B, C, D)):
            if np.iscomplexobj(M):
                raise InputError(f"LPV plant: expected real {nm}, found complex entries")
            if M.shape[:-2] != shp:
                raise InputError(f"LPV plant: expected {nm} of shape grid {shp} + (rows, cols) for the grid "
                                 f"given, found {M.shape}")
        P = GriddedLPV(axes=axes, parameter_names=[f"rho{k}" for k in range(len(axes))],
                       rate_bounds=np.zeros((len(axes), 2)), A=A, B=B, C=C, D=D,
                       state_names=[f"x{i}" for i in range(A.shape[-1])],
                       input_names=[f"in{i}" for i in range(B.shape[-1])],
                       output_names=[f"out{i}" for i in range(C.shape[-2])], interpolation=interpolation)
    if isinstance(P, GriddedLPV):
        if len(P.axes) != len(axes):
            raise InputError(f"LPV grid: expected {len(P.axes)} axes as the plant's grid, found {len(axes)}")
        for k, (pa, a) in enumerate(zip(P.axes, axes)):
            off = [float(v) for v in a if np.min(np.abs(pa - v)) > 1e-12 * max(1.0, np.max(np.abs(pa)))]
            if off:
                raise InputError(f"LPV grid: expected design points among the plant's grid points, found "
                                 f"{P.parameter_names[k]} = {off} not in {pa.tolist()}")
        gp = P
        return PlantFunction(evaluate=gp.at, n=gp.nx, m=gp.nu, p=gp.ny, axes=gp.axes, interpolated=True,
                             rate_bounds=gp.rate_bounds, parameter_names=list(gp.parameter_names))
    if interpolation != "multilinear":
        raise InputError(f"LPV plant: interpolation applies to a plant given on a grid, found "
                         f"interpolation={interpolation!r} with a {type(P).__name__}")
    if hasattr(P, "A") and hasattr(P, "dt"):
        A, B, C, D = _matrices(P, [])
        return PlantFunction(evaluate=lambda rho: (A, B, C, D), n=A.shape[0], m=B.shape[1], p=C.shape[0],
                             axes=None, interpolated=False)
    if callable(P):
        rho0 = np.array([a[0] for a in axes])
        A, B, C, D = _matrices(P(rho0), rho0)
        return PlantFunction(evaluate=P, n=A.shape[0], m=B.shape[1], p=C.shape[0], axes=None,
                             interpolated=False)
    raise InputError(f"LPV plant: expected a callable rho -> StateSpace or (A, B, C, D), a StateSpace, "
                     f"gridded arrays (A, B, C, D), a GriddedLPV or a GeneralizedLPV, found "
                     f"{type(P).__name__}")

"""Gridded linear-parameter-varying plants (eq. 5.90) and their build from the COM.

An LPV plant x' = A(rho) x + B(rho) u, y = C(rho) x + D(rho) u (eq. 5.90) is known here on a
rectangular grid of parameter values (any number of parameters), the gridding approach of
8.3: state-space matrices at every grid point, named states/inputs/outputs shared by all
points, interpolation between grid points (multilinear, or tensor-product splines) and bounds
on the parameter rates.

:func:`com_lpv_plant` builds it for a symmetric tensegrity-membrane system from
linearisations of the control-oriented model (eq. 5.33) at the symmetric equilibria of
eq. 5.97 on a (theta, psi) grid, rho = [theta_1N, psi_1N] (theta_13, psi_13 of 8.3), with the
membrane point deflections of eq. 5.17 as coordinates.
"""
from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import RegularGridInterpolator, make_interp_spline

from tmfem.equilibrium.deployment_path import lpv_grid_point
from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
from tmfem.errors import InfeasibleDesign, InputError
from tmfem.models.com.linearize import linearize
from tmfem.models.com.mode_count import MembraneModeChoice
from tmfem.models.com.model import ControlOrientedModel, membrane_modes_of
from tmfem.system.geometry import membrane_corners_regular
from tmfem.system.topology import label

log = logging.getLogger(__name__)

#: how a gridded plant is evaluated between its grid points (:meth:`GriddedLPV.interpolate`)
INTERPOLATIONS = ("multilinear", "spline")
#: Kinds of scheduling parameter that are angles [rad] (the bar angles theta_1N, psi_1N of
#: :func:`scheduling_parameters`): shown in degrees in messages and logs.
ANGLE_KINDS = ("theta_", "psi_")


def scheduling_parameters(N: int) -> list:
    """The scheduling parameters rho = [theta_1N, psi_1N] of an N-bar symmetric system: the
    angles of the stage-1 bar whose azimuth is the configuration's psi (eq. 3.20:
    psi_1j = psi_1 + 2 pi j / N, so j = N), which 8.3 writes theta_13, psi_13 for N = 3. The
    other bars of stage 1 have the same theta and their psi a whole 2 pi j / N away."""
    return [label("theta", 1, N), label("psi", 1, N)]


def grid_point_text(names, rho, *, rates: bool = False) -> str:
    """A grid point ``rho`` of the parameters ``names`` as text with units: the angles of
    :data:`ANGLE_KINDS` in degrees ("theta_13 = 64 deg, psi_13 = 25 deg"; with ``rates``
    their rates in deg/s, "theta_13' = 10 deg/s"), other parameters as given; "none" when
    ``rho`` is None."""
    if rho is None:
        return "none"
    tick, unit = ("'", " deg/s") if rates else ("", " deg")
    return ", ".join(f"{nm}{tick} = {np.degrees(v):.4g}{unit}" if nm.startswith(ANGLE_KINDS)
                     else f"{nm}{tick} = {v:.4g}" for nm, v in zip(names, np.atleast_1d(np.asarray(rho, dtype=float))))


@dataclass
class GriddedLPV:
    """State-space models on a rectangular parameter grid (eq. 5.90, gridding of 8.3).

    Attributes
    ----------
    axes : list of (n_k,) arrays
        Grid values of each parameter (strictly increasing; radians for angles).
    parameter_names : list of str
    A, B, C, D : arrays of shape ``grid_shape + (rows, cols)``
    rate_bounds : (n_p, 2) array
        Lower and upper bound of each parameter rate d rho_k / dt (per second).
    state_names, input_names, output_names : list of str
    x_e, u_e, y_e : arrays of shape ``grid_shape + (n,)``, optional
        Equilibrium state, input and output at each grid point (the linearisations are
        about them); zeros when not given.
    membrane_points : list of (component, x_f, y_f), optional
        The membrane point coordinates of eq. 5.17 among the states (:func:`com_lpv_plant`).
    interpolation : {"multilinear", "spline"}
        Between grid points (:meth:`interpolate`): multilinear (default), or the tensor product
        of interpolating splines of degree min(3, n_k - 1) along each axis (not-a-knot cubic
        along an axis of 4 or more points, the parabola through 3 points): the same values at
        the grid points, an error O(h^4) instead of O(h^2) between them for smooth matrices.
    """

    axes: list
    parameter_names: list
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    rate_bounds: np.ndarray
    state_names: list
    input_names: list
    output_names: list
    x_e: np.ndarray | None = None
    u_e: np.ndarray | None = None
    y_e: np.ndarray | None = None
    membrane_points: list | None = None
    interpolation: str = "multilinear"
    _interp: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        self.axes = [np.atleast_1d(np.asarray(a, dtype=float)) for a in self.axes]
        shape = tuple(a.size for a in self.axes)
        if self.interpolation not in INTERPOLATIONS:
            raise InputError(f"LPV plant: interpolation expected one of {list(INTERPOLATIONS)}, found "
                             f"{self.interpolation!r}")
        if len(self.parameter_names) != len(self.axes):
            raise InputError(f"LPV plant: expected {len(self.axes)} parameter names, found "
                             f"{len(self.parameter_names)}")
        for k, a in enumerate(self.axes):
            if a.size > 1 and np.any(np.diff(a) <= 0):
                raise InputError(f"LPV plant: axis {self.parameter_names[k]!r} must be strictly "
                                 f"increasing, found {a.tolist()}")
        for nm in ("A", "B", "C", "D"):
            M = np.asarray(getattr(self, nm), dtype=float)
            if M.shape[:-2] != shape or not np.all(np.isfinite(M)):
                raise InputError(f"LPV plant: {nm} must have shape {shape} + (rows, cols) with "
                                 f"finite entries, found shape {M.shape}")
            setattr(self, nm, M)
        n, m, p = self.nx, self.nu, self.ny
        if self.A.shape[-2:] != (n, n) or self.B.shape[-2:] != (n, m) or \
                self.C.shape[-2:] != (p, n) or self.D.shape[-2:] != (p, m):
            raise InputError(f"LPV plant: inconsistent sizes A {self.A.shape[-2:]}, B "
                             f"{self.B.shape[-2:]}, C {self.C.shape[-2:]}, D {self.D.shape[-2:]}")
        if (len(self.state_names), len(self.input_names), len(self.output_names)) != (n, m, p):
            raise InputError(f"LPV plant: expected {n} state, {m} input and {p} output names, found "
                             f"{len(self.state_names)}, {len(self.input_names)}, {len(self.output_names)}")
        rb = np.asarray(self.rate_bounds, dtype=float).reshape(len(self.axes), 2)
        if np.any(rb[:, 0] > rb[:, 1]) or not np.all(np.isfinite(rb)):
            raise InputError(f"LPV plant: rate bounds must be finite [lower, upper] with lower <= "
                             f"upper, found {rb.tolist()}")
        self.rate_bounds = rb
        for nm, k in (("x_e", n), ("u_e", m), ("y_e", p)):
            v = getattr(self, nm)
            v = np.zeros(shape + (k,)) if v is None else np.asarray(v, dtype=float)
            if v.shape != shape + (k,):
                raise InputError(f"LPV plant: {nm} must have shape {shape + (k,)}, found {v.shape}")
            setattr(self, nm, v)

    # ------------------------------------------------------------------ sizes and points
    @property
    def grid_shape(self) -> tuple:
        return tuple(a.size for a in self.axes)

    @property
    def nx(self) -> int:
        return self.A.shape[-1]

    @property
    def nu(self) -> int:
        return self.B.shape[-1]

    @property
    def ny(self) -> int:
        return self.C.shape[-2]

    def points(self):
        """Iterate over ``(index, rho)`` of all grid points (C order)."""
        for idx in itertools.product(*(range(s) for s in self.grid_shape)):
            yield idx, np.array([a[i] for a, i in zip(self.axes, idx)])

    def rate_vertices(self) -> np.ndarray:
        """Vertices of the rate box (eq. 5.94: dP/dt is affine in the rates), one row each;
        a parameter with equal lower and upper bound contributes one value."""
        cols = [np.unique(rb) for rb in self.rate_bounds]
        return np.array(list(itertools.product(*cols)), dtype=float).reshape(-1, len(cols))

    def _check_inside(self, rho):
        rho = np.asarray(rho, dtype=float).reshape(-1)
        if rho.size != len(self.axes):
            raise InputError(f"LPV plant: expected {len(self.axes)} parameter values, found {rho.size}")
        for k, (a, r) in enumerate(zip(self.axes, rho)):
            tol = 1e-12 * max(1.0, abs(a[-1]))
            if r < a[0] - tol or r > a[-1] + tol:
                raise InputError(f"LPV plant: {self.parameter_names[k]} = {r:.6g} outside the grid "
                                 f"[{a[0]:.6g}, {a[-1]:.6g}]")
        return np.clip(rho, [a[0] for a in self.axes], [a[-1] for a in self.axes])

    def on_turn(self, rho, angles: dict) -> "GriddedLPV":
        """This plant with the angles among x_e and y_e (the entries named in ``angles``, e.g.
        the bar angles theta_ij, psi_ij; not their rates) counted continuously over the grid,
        each on the turn of ``angles`` ({name: value [rad]}) at ``rho``.

        The grid points' equilibria give every azimuth on (-pi, pi]: an azimuth that passes
        +-pi between two grid points (psi_32 of the three-stage tower from 3.118 rad at
        theta_13 = 60 deg to -3.094 at 57.5 deg) would be interpolated across the wrap, through
        0. Each such entry is unwrapped along every axis (``numpy.unwrap``: whole turns added
        where consecutive points differ by more than pi; untouched otherwise), then moved by
        whole turns to the value nearest ``angles[name]`` at ``rho`` (a reference that
        starts there). A plant whose angles neither wrap nor differ by a turn from ``angles``
        is returned unchanged."""
        X = {"x_e": self.x_e.copy(), "y_e": self.y_e.copy()}
        names = {"x_e": self.state_names, "y_e": self.output_names}
        idx = {k: [i for i, n in enumerate(names[k]) if n in angles] for k in X}
        for k, ii in idx.items():
            for ax in range(len(self.axes)):
                X[k][..., ii] = np.unwrap(X[k][..., ii], axis=ax)
        unwrapped = replace(self, x_e=X["x_e"], y_e=X["y_e"], _interp={})
        for k, ii in idx.items():
            at = unwrapped.interpolate(k, rho)
            for i in ii:
                X[k][..., i] += 2 * np.pi * np.round((angles[names[k][i]] - at[i]) / (2 * np.pi))
        if all(np.array_equal(X[k], getattr(self, k)) for k in X):
            return self
        return replace(self, x_e=X["x_e"], y_e=X["y_e"], _interp={})

    def interpolate(self, name, rho):
        """``A``, ``B``, ``C``, ``D``, ``x_e``, ``u_e`` or ``y_e`` at ``rho`` (inside the grid;
        axes with one point are constant), by the plant's ``interpolation``: multilinear, or
        splines along one axis after the other (the first axis' spline is built once).

        ``name`` may be a tuple of these names: a tuple of their values is returned, which the
        multilinear interpolation evaluates at once (one interpolant of the stacked values, built
        once per tuple: the same numbers as one name at a time, for one evaluation's cost).
        """
        names = (name,) if isinstance(name, str) else tuple(name)
        rho = self._check_inside(rho)
        keep = [k for k, a in enumerate(self.axes) if a.size > 1]
        if not keep:
            out = tuple(getattr(self, nm)[(0,) * len(self.axes)].copy() for nm in names)
        elif self.interpolation == "multilinear":
            out = self._multilinear(names, keep, rho)
        else:
            out = tuple(self._splines(nm, keep, rho) for nm in names)
        return out[0] if isinstance(name, str) else out

    def _multilinear(self, names: tuple, keep: list, rho) -> tuple:
        """The values of ``names`` at ``rho`` by one RegularGridInterpolator of their values
        stacked along a last axis (built once per ``names``)."""
        if names not in self._interp:
            fixed = tuple(slice(None) if k in keep else 0 for k in range(len(self.axes)))
            parts = [getattr(self, nm)[fixed] for nm in names]
            grid = parts[0].shape[:len(keep)]
            stacked = np.concatenate([p.reshape(grid + (-1,)) for p in parts], axis=-1)
            shapes = [p.shape[len(keep):] for p in parts]
            self._interp[names] = (RegularGridInterpolator([self.axes[k] for k in keep], stacked),
                                   shapes, np.cumsum([int(np.prod(sh)) for sh in shapes])[:-1])
        f, shapes, cuts = self._interp[names]
        return tuple(v.reshape(sh) for v, sh in zip(np.split(f(rho[keep])[0], cuts), shapes))

    def _splines(self, name: str, keep: list, rho) -> np.ndarray:
        """The value of ``name`` at ``rho`` by splines along one kept axis after the other."""
        if name not in self._interp:
            Mk = getattr(self, name)[tuple(slice(None) if k in keep else 0 for k in range(len(self.axes)))]
            self._interp[name] = make_interp_spline(self.axes[keep[0]], Mk, k=min(3, self.axes[keep[0]].size - 1),
                                                    axis=0)
        out = self._interp[name](rho[keep[0]])
        for k in keep[1:]:
            out = make_interp_spline(self.axes[k], out, k=min(3, self.axes[k].size - 1), axis=0)(rho[k])
        return np.asarray(out)

    def at(self, rho):
        """(A, B, C, D) at ``rho`` (:meth:`interpolate`)."""
        return self.interpolate(("A", "B", "C", "D"), rho)

    def refined(self, factor: int) -> list:
        """Axes of a grid ``factor`` times finer in each parameter (the design points kept)."""
        if int(factor) != factor or factor < 1:
            raise InputError(f"refinement factor: expected an integer >= 1, found {factor!r}")
        return [a if a.size == 1 else np.concatenate(
            [np.linspace(a[i], a[i + 1], int(factor) + 1)[:-1] for i in range(a.size - 1)] + [a[-1:]])
            for a in self.axes]

    def resampled(self, axes) -> "GriddedLPV":
        """The plant interpolated onto other grid axes (inside this grid)."""
        shape = tuple(np.size(a) for a in axes)
        out = {nm: np.zeros(shape + getattr(self, nm).shape[len(self.axes):])
               for nm in ("A", "B", "C", "D", "x_e", "u_e", "y_e")}
        for idx in itertools.product(*(range(s) for s in shape)):
            rho = [np.atleast_1d(a)[i] for a, i in zip(axes, idx)]
            for nm in out:
                out[nm][idx] = self.interpolate(nm, rho)
        return GriddedLPV(axes=list(axes), parameter_names=list(self.parameter_names),
                          rate_bounds=self.rate_bounds.copy(), state_names=self.state_names,
                          input_names=self.input_names, output_names=self.output_names, **out)

    def measurement(self, names):
        """C_m and y_e of the measured signals ``names``: plant outputs (their rows of C, which
        must not depend on u) or states (rows of the identity, y_e = x_e), on the grid
        (shapes ``grid_shape + (len(names), nx)`` and ``grid_shape + (len(names),)``)."""
        shp = self.grid_shape
        C = np.zeros(shp + (len(names), self.nx))
        y_e = np.zeros(shp + (len(names),))
        for k, nm in enumerate(names):
            if nm in self.output_names:
                i = self.output_names.index(nm)
                if np.any(self.D[..., i, :] != 0):
                    raise InputError(f"output feedback: measured output {nm!r} must not depend on u directly "
                                     "(its row of D is nonzero)")
                C[..., k, :], y_e[..., k] = self.C[..., i, :], self.y_e[..., i]
            else:
                i = self.state_names.index(nm)
                C[..., k, i], y_e[..., k] = 1.0, self.x_e[..., i]
        return C, y_e

    def to_ss(self, index):
        """python-control ``StateSpace`` with named signals at grid point ``index``."""
        import control
        idx = tuple(index)
        return control.ss(self.A[idx], self.B[idx], self.C[idx], self.D[idx], states=self.state_names,
                          inputs=self.input_names, outputs=self.output_names)


def choose_membrane_points(model, *, rings=(0.2, 0.4, 0.6), per_ring: int = 12) -> list:
    """K point coordinates (eq. 5.17) for ``model`` chosen greedily among (u, v, w) at points
    on rings about the membrane centre (radii as fractions of r_mb): each step adds the
    candidate that maximises the smallest singular value of the rows of T_v_eta picked so
    far. Ch. 8 does not print its points (docs/validation/errata.md); this rule keeps T_v_eta well
    conditioned."""
    system = model.system
    c = membrane_corners_regular(system.N, system.r_mb).mean(axis=1)      # centre in O_f
    nd = model.layout.n_delta
    cands, rows = [], []
    for fr in rings:
        for t in np.radians(7.5) + 2 * np.pi * np.arange(per_ring) / per_ring:
            xy = c + fr * system.r_mb * np.array([np.cos(t), np.sin(t)])
            for comp, k in (("w", 2), ("u", 0), ("v", 1)):
                try:
                    r = model.membrane.point_matrix(xy[:, None], k)[0, 1 + nd:]
                except InputError:
                    continue
                cands.append((comp, float(xy[0]), float(xy[1])))
                rows.append(r)
    R = np.array(rows)
    R = R / np.linalg.norm(R, axis=1, keepdims=True).max()
    picked = []
    for _ in range(model.K):
        best = max((i for i in range(len(cands)) if i not in picked),
                   key=lambda i: np.linalg.svd(R[picked + [i]], compute_uv=False).min())
        picked.append(best)
    return [cands[i] for i in picked]


def lpv_membrane_mode_choice(system) -> MembraneModeChoice:
    """K of the LPV plant of ``system`` and where it comes from: its ``[lpv] membrane_modes``,
    else that of the control-oriented model (:func:`tmfem.models.com.model.membrane_modes_of`:
    the file's ``[models.com]``, else the automatic choice)."""
    lpv = system.problem.lpv
    if lpv is not None and lpv.membrane_modes is not None:
        return MembraneModeChoice(K=int(lpv.membrane_modes), source="file")
    return membrane_modes_of(system)


def lpv_membrane_modes(system) -> int:
    """K of :func:`lpv_membrane_mode_choice`."""
    return lpv_membrane_mode_choice(system).K


def com_lpv_plant(system, *, theta, psi, bases=None, membrane_modes: int | None = None,
                  membrane_points=None, mesh_n: int = 10, damping: float = 0.0,
                  rate_bounds=None, progress=None) -> GriddedLPV:
    """Gridded LPV plant of a symmetric system from COM linearisations (8.3, eqs. 5.33, 5.97).

    At each (theta, psi) of the grid the symmetric configuration of eq. 5.97 (stage bases
    from ``bases(theta, psi)``, e.g. :func:`tmfem.reference.deployments.lpv_bases`) is
    built, the control-oriented model designs its rest lengths there (the equilibrium u_e,
    eq. 3.16) and is linearised (eq. 5.33) with the membrane point coordinates of eq. 5.17
    (``membrane_points``; default :func:`choose_membrane_points` at the first grid point).
    rho = [theta_1N, psi_1N] = [theta, psi] (:func:`scheduling_parameters`; theta_13, psi_13 of
    8.3 for N = 3).

    Parameters
    ----------
    theta, psi : arrays [rad]
        Grid axes.
    membrane_modes : int, optional
        K of the COM at every grid point; default :func:`lpv_membrane_modes`.
    rate_bounds : (2, 2) array, optional
        [[min, max] of d theta/dt, [min, max] of d psi/dt] [rad/s]; default +-10 deg/s (8.3).
    progress : callable, optional
        Called with (done, total) after each grid point.
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    psi = np.atleast_1d(np.asarray(psi, dtype=float))
    if rate_bounds is None:
        rb = np.radians(10.0)
        rate_bounds = [[-rb, rb], [-rb, rb]]
    pts = membrane_points
    if membrane_modes is None:
        membrane_modes = lpv_membrane_modes(system)
    shape = (theta.size, psi.size)
    mats, names = {}, None
    total = theta.size * psi.size
    for a, th in enumerate(theta):
        for b, ps in enumerate(psi):
            rule = bases(th, ps) if bases else {}
            try:
                s = with_configuration(system, configuration_5_97(system, th, ps, **rule))
                if pts is None:                      # chosen once, at the first grid point
                    pts = choose_membrane_points(ControlOrientedModel(s, membrane_modes=membrane_modes,
                                                                      mesh_n=mesh_n))
                m = ControlOrientedModel(s, membrane_modes=membrane_modes, mesh_n=mesh_n, damping=damping,
                                         membrane_points=pts)
                L = linearize(m)
            except InfeasibleDesign as exc:
                raise type(exc)(f"{lpv_grid_point(th, ps)} is not a feasible equilibrium of the grid's "
                                f"stage-base rule: {exc}; expected a grid inside the region of feasible "
                                "equilibria (narrow the [lpv] theta_grid_deg / psi_grid_deg)") from None
            got = (L.state_names, L.input_names, L.output_names)
            if names is None:
                names = got
                for nm, v in (("A", L.A), ("B", L.B), ("C", L.Cy), ("D", L.D),
                              ("x_e", np.concatenate([L.z_e, np.zeros_like(L.z_e)])),
                              ("u_e", L.u_e), ("y_e", L.y_e)):
                    mats[nm] = np.zeros(shape + v.shape)
            for nm, v in (("A", L.A), ("B", L.B), ("C", L.Cy), ("D", L.D),
                          ("x_e", np.concatenate([L.z_e, np.zeros_like(L.z_e)])),
                          ("u_e", L.u_e), ("y_e", L.y_e)):
                mats[nm][a, b] = v
            log.info("LPV plant: point theta = %.2f deg, psi = %.2f deg linearised",
                     np.degrees(th), np.degrees(ps))
            if progress is not None:
                progress(a * psi.size + b + 1, total)
    return GriddedLPV(axes=[theta, psi], parameter_names=scheduling_parameters(system.N),
                      rate_bounds=np.asarray(rate_bounds, dtype=float), state_names=names[0],
                      input_names=names[1], output_names=names[2], membrane_points=list(pts), **mats)

"""The :class:`System`: one description of a tensegrity-membrane system for every model.

A system is its topology (M stages of N bars, tendon families of 2.2, or the SL/SU
tendons of a 1-N(D) system), the fixed base A_1j, the bar lengths, the undeformed
membrane polygon, the materials, and a design configuration q (eqs. 3.1-3.2). Rest
lengths are optional: an equilibrium design (``tmfem.equilibrium``) computes them.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from tmfem.errors import InputError
from tmfem.system.coordinates import q_index, q_size, split_q
from tmfem.system.geometry import (SymmetricConfig, bar_direction, base_centre, beta,
                                   floating_frame, membrane_corners_regular, wrap_angle)
from tmfem.system.materials import BarSection, MembraneMaterial, TendonSection
from tmfem.system.problem import Problem
from tmfem.system.topology import Tendon, label, node_labels, tendon_topology


def rest_length_array(values, n_tendons: int) -> np.ndarray:
    """Rest lengths r (eqs. 3.8-3.9) as a float array, checked: ``n_tendons`` finite
    positive values within the plausibility bounds of a system file
    (:data:`tmfem.system.validate.BOUNDS`), else InputError."""
    from tmfem.system.validate import BOUNDS
    r = np.asarray(values, dtype=float)
    if r.shape != (n_tendons,) or np.any(~np.isfinite(r)) or np.any(r <= 0):
        raise InputError(f"expected {n_tendons} positive rest lengths, found {r}")
    lo, hi, unit, _ = BOUNDS[("rest_lengths", "*")]
    if np.any((r < lo) | (r > hi)):
        k = int(np.flatnonzero((r < lo) | (r > hi))[0])
        raise InputError(f"expected rest lengths within {lo:g}..{hi:g} {unit} (docs/guides/equilibrium.md, "
                         f"limits), found {r[k]:.4g} {unit} (tendon {k + 1} of {n_tendons})")
    return r


@lru_cache(maxsize=None)
def _q_names(M: int, N: int) -> tuple[str, ...]:
    """Names of the generalised coordinates of an M-N system (:attr:`System.q_names`)."""
    xyz, th, ps = q_index(M, N)
    names = [""] * q_size(M, N)
    for (i, j), k in np.ndenumerate(th):
        names[k], names[ps[i, j]] = label("theta", i + 1, j + 1), label("psi", i + 1, j + 1)
        for c, comp in enumerate("xyz"):
            if xyz[c, i, j] >= 0:
                names[xyz[c, i, j]] = label(comp, i + 1, j + 1)
    return tuple(names)


@lru_cache(maxsize=None)
def _node_label_set(M: int, N: int, deployable: bool) -> frozenset:
    """The node labels of an M-N (or 1-N(D)) system as a set, made once per topology."""
    return frozenset(node_labels(M, N, deployable))


@lru_cache(maxsize=256)
def _tendon_connectivity(M: int, N: int, deployable: bool, tendons: tuple) -> np.ndarray:
    """End-node indices (2, n_tendons) of ``tendons`` in the node order of
    :func:`tmfem.system.topology.node_labels`, made once per topology (read-only); InputError
    for a tendon end that is no node of the system."""
    idx = {n: k for k, n in enumerate(node_labels(M, N, deployable))}
    for t in tendons:
        for e in t.ends:
            if e not in idx:
                raise InputError(f"tendon {t.name}: expected end nodes among the "
                                 f"{len(idx)} nodes of a {M}-{N} system, found {e!r}")
    c = np.array([[idx[t.ends[0]] for t in tendons], [idx[t.ends[1]] for t in tendons]],
                 dtype=int).reshape(2, len(tendons))
    c.flags.writeable = False
    return c


@lru_cache(maxsize=256)
def _section_representatives(tendons: tuple) -> tuple:
    """The first tendon of each (group, family) of ``tendons``, in their order: the tendons
    whose cross sections (:meth:`System.tendon_section`) stand for all of them."""
    first = {}
    for t in tendons:
        first.setdefault((t.group, t.family), t)
    return tuple(first.values())


@dataclass(frozen=True)
class System:
    """A tensegrity-membrane system and its design configuration.

    Parameters
    ----------
    name : str
        Short name, e.g. ``"1-4"``.
    M, N : int
        Number of stages and of bars per stage.
    deployable : bool
        True for a 1-N(D) system (tendons SL, SU through the points H_1j).
    base : ndarray (3, N)
        Fixed lower ends A_1j of the first-stage bars, inertial frame.
    l : ndarray (M, N)
        Bar lengths l_ij.
    q : ndarray
        Design configuration, generalised coordinates of eqs. 3.1-3.2.
    membrane, membrane_corners :
        Membrane material and its undeformed corners (2, N) in the floating frame O_f.
    bar : BarSection
    tendon_sections : dict
        Cross sections keyed by group (``"S1"``, ``"V2"``, ``"SL"``), by family (``"S"``)
        or ``"*"``; the most specific key wins.
    k_H : float, optional
        Position of H_1j along the bars of a 1-N(D) system, 0 < k_H < 1.
    tendons : tuple of Tendon, optional
        Connectivity; defaults to the families of 2.2.
    rest_lengths : ndarray, optional
        Rest length of each tendon, aligned with ``tendons``.
    symmetric : SymmetricConfig, optional
        The symmetric parametrisation of ``q`` when the system is symmetric.
    r_mb : float, optional
        Circumradius of a regular membrane.
    monitor_nodes : tuple of str
        Node labels whose motion studies record by default (the dissertation's Figs.
        6.21-6.27 for its presets; file table ``[monitor] nodes``).
    monitor_points : ndarray (2, n_points)
        Membrane points (x_f, y_f) [m] whose transverse deflections w_k are outputs by
        default (eqs. 5.36, 5.38 for the presets; file table ``[monitor] points``).
    model_defaults : dict
        Default options of the models for this system, ``{model: {option: value}}`` (file
        table ``[models.<name>]``; the presets carry the dissertation's membrane modes K of
        the control-oriented model).
    problem : Problem
        What the file declares beyond the structure: the packaged configuration, the control,
        deployment, LPV and report tables (:mod:`tmfem.system.problem`).
    """

    name: str
    M: int
    N: int
    deployable: bool
    base: np.ndarray
    l: np.ndarray
    q: np.ndarray
    membrane: MembraneMaterial
    membrane_corners: np.ndarray
    bar: BarSection
    tendon_sections: dict
    k_H: float | None = None
    tendons: tuple = ()
    rest_lengths: np.ndarray | None = None
    symmetric: SymmetricConfig | None = None
    r_mb: float | None = None
    description: str = ""
    notes: tuple = ()
    printed: dict = field(default_factory=dict)
    monitor_nodes: tuple = ()
    monitor_points: np.ndarray = field(default_factory=lambda: np.zeros((2, 0)))
    model_defaults: dict = field(default_factory=dict)
    problem: Problem = field(default_factory=Problem)

    def __post_init__(self):
        M, N = self.M, self.N
        if not (isinstance(M, int) and M >= 1):
            raise InputError(f"expected M >= 1 stages, found M={M!r}")
        if not (isinstance(N, int) and N >= 3):
            raise InputError(f"expected N >= 3 bars per stage, found N={N!r}")
        if self.deployable and M != 1:
            raise InputError(f"a 1-N(D) system has one stage, found M={M}")
        if self.deployable and not (isinstance(self.k_H, (int, float)) and 0 < self.k_H < 1):
            raise InputError(f"a 1-N(D) system needs 0 < k_H < 1, found k_H={self.k_H!r}")
        base = np.asarray(self.base, dtype=float)
        l = np.broadcast_to(np.asarray(self.l, dtype=float), (M, N)).copy()
        q = np.asarray(self.q, dtype=float)
        corners = np.asarray(self.membrane_corners, dtype=float)
        if base.shape != (3, N):
            raise InputError(f"expected base A_1j of shape (3, {N}), found {base.shape}")
        if not (np.isfinite(l).all() and (l > 0).all()):
            raise InputError(f"expected bar lengths l > 0, found {l.ravel()}")
        nq = q_size(M, N)
        if q.shape != (nq,) or not np.isfinite(q).all():
            raise InputError(f"expected q of length {nq} (eqs. 3.1-3.2) with finite entries, "
                             f"found shape {q.shape}")
        if corners.shape != (2, N):
            raise InputError(f"expected membrane corners of shape (2, {N}), found {corners.shape}")
        tendons = tuple(self.tendons) or tuple(tendon_topology(M, N, self.deployable))
        _tendon_connectivity(M, N, self.deployable, tendons)
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "l", l)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "membrane_corners", corners)
        object.__setattr__(self, "tendons", tendons)
        pts = np.asarray(self.monitor_points, dtype=float).reshape(2, -1) \
            if np.size(self.monitor_points) else np.zeros((2, 0))
        if not np.isfinite(pts).all():
            raise InputError(f"expected finite monitored membrane points, found {pts.T.tolist()}")
        object.__setattr__(self, "monitor_points", pts)
        labels = _node_label_set(M, N, self.deployable)
        for n in self.monitor_nodes:
            if n not in labels:
                raise InputError(f"monitored node: expected one of the nodes of a {M}-{N} system, "
                                 f"found {n!r}")
        object.__setattr__(self, "monitor_nodes", tuple(self.monitor_nodes))
        for t in _section_representatives(tendons):
            self.tendon_section(t)
        if self.rest_lengths is not None:
            object.__setattr__(self, "rest_lengths", rest_length_array(self.rest_lengths,
                                                                       len(tendons)))

    def __repr__(self) -> str:
        """One line (the arrays are attributes; ``tmfem.system.system_to_dict`` shows all)."""
        kind = f"{self.M}-{self.N}" + ("(D)" if self.deployable else "")
        rest = "" if self.rest_lengths is None else ", rest lengths given"
        return (f"System({self.name!r}, {kind}, {len(self.node_labels)} nodes, "
                f"{self.M * self.N} bars, {len(self.tendons)} tendons"
                + ("" if self.symmetric is None else ", symmetric") + rest + ")")

    # ------------------------------------------------------------------ construction
    @classmethod
    def symmetric_system(cls, *, name: str, N: int, config: SymmetricConfig, r_mb: float,
                         membrane: MembraneMaterial, bar: BarSection, tendon_sections: dict,
                         deployable: bool = False, k_H: float | None = None,
                         rest_lengths: dict | None = None, description: str = "",
                         notes=(), printed: dict | None = None, monitor_nodes=(),
                         monitor_points=None, model_defaults: dict | None = None,
                         problem: Problem | None = None) -> "System":
        """Build a symmetric system (3.3.1) from its parametrisation.

        ``rest_lengths`` may be given per group (``{"S1": 1.5}``) or per tendon name.
        """
        if not (r_mb > 0):
            raise InputError(f"expected membrane radius r_mb > 0, found {r_mb!r}")
        sys = cls(name=name, M=config.M, N=N, deployable=deployable, **config.system_arrays(N),
                  membrane=membrane, membrane_corners=membrane_corners_regular(N, r_mb), bar=bar,
                  tendon_sections=dict(tendon_sections), k_H=k_H, symmetric=config, r_mb=r_mb,
                  description=description, notes=tuple(notes), printed=dict(printed or {}),
                  monitor_nodes=tuple(monitor_nodes), model_defaults=dict(model_defaults or {}),
                  monitor_points=np.zeros((2, 0)) if monitor_points is None else monitor_points,
                  problem=problem or Problem())
        if rest_lengths:
            sys = sys.with_rest_lengths(rest_lengths)
        return sys

    def replace(self, **changes) -> "System":
        """A copy with fields changed (``dataclasses.replace``)."""
        return dataclasses.replace(self, **changes)

    def with_rest_lengths(self, rest: dict | np.ndarray) -> "System":
        """A copy with rest lengths given per tendon (array or name map) or per group."""
        if isinstance(rest, dict):
            values = []
            for t in self.tendons:
                v = rest.get(t.name, rest.get(t.group))
                if v is None:
                    raise InputError(f"no rest length for tendon {t.name} (group {t.group}); "
                                     f"given keys: {sorted(rest)}")
                if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                    raise InputError(f"rest length of tendon {t.name}: expected a number in m, "
                                     f"found {v!r}")
                values.append(float(v))
            rest = np.array(values)
        return self.replace(rest_lengths=np.asarray(rest, dtype=float))

    # ------------------------------------------------------------------ coordinates
    @property
    def q_names(self) -> list[str]:
        """Names of the generalised coordinates, e.g. ``theta_11``, ``psi_11``, ``x_21`` (a new
        list of the names made once per (M, N))."""
        return list(_q_names(int(self.M), int(self.N)))

    def split_q(self, q=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Lower ends A (3, M, N), declinations theta (M, N) and azimuths psi (M, N) from q."""
        return split_q(self.q if q is None else q, self.base)

    def bar_ends(self, q=None) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bar ends A_ij, B_ij, each (3, M, N)."""
        A, theta, psi = self.split_q(q)
        return A, A + self.l[None] * bar_direction(theta, psi)

    @property
    def node_labels(self) -> list[str]:
        """Node labels in global order: A_ij by stage, B_ij by stage, then H_1j (2.2)."""
        return node_labels(self.M, self.N, self.deployable)

    def node_index(self, name: str) -> int:
        """Index of node ``name`` in :attr:`node_labels`; InputError naming the nodes if unknown."""
        try:
            return self.node_labels.index(name)
        except ValueError:
            raise InputError(f"unknown node {name!r}; nodes are {self.node_labels}") from None

    def nodes(self, q=None) -> np.ndarray:
        """Coordinates (3, n_nodes) of all labelled nodes, in :attr:`node_labels` order."""
        A, B = self.bar_ends(q)
        parts = [A.reshape(3, -1), B.reshape(3, -1)]
        if self.deployable:
            parts.append(A[:, 0, :] + self.k_H * (B[:, 0, :] - A[:, 0, :]))
        return np.concatenate(parts, axis=1)

    @property
    def tendon_connectivity(self) -> np.ndarray:
        """Tendon end-node indices, shape (2, n_tendons) (a new array)."""
        return _tendon_connectivity(self.M, self.N, self.deployable, self.tendons).copy()

    @property
    def bar_connectivity(self) -> np.ndarray:
        """Bar end-node indices (A_ij, B_ij), shape (2, M N)."""
        n = self.M * self.N
        return np.array([np.arange(n), n + np.arange(n)])

    def tendon_vectors(self, q=None) -> np.ndarray:
        """Vectors from the first to the second end of each tendon, (3, n_tendons)."""
        X = self.nodes(q)
        c = self.tendon_connectivity
        return X[:, c[1]] - X[:, c[0]]

    def tendon_lengths(self, q=None) -> np.ndarray:
        """Current tendon lengths |d_k| (n_tendons,) at configuration q (eq. 3.8)."""
        return np.linalg.norm(self.tendon_vectors(q), axis=0)

    def tendon_section(self, tendon: Tendon) -> TendonSection:
        """Cross section of ``tendon``: the most specific of its group, family or ``"*"``."""
        for key in (tendon.group, tendon.family, "*"):
            if key in self.tendon_sections:
                return self.tendon_sections[key]
        raise InputError(f"no cross section for tendon {tendon.name}: expected a key "
                         f"{tendon.group!r}, {tendon.family!r} or '*' in tendon_sections, "
                         f"found {sorted(self.tendon_sections)}")

    @property
    def tendon_EA(self) -> np.ndarray:
        """Axial stiffness EA of every tendon (n_tendons,), as in eqs. 3.8-3.9."""
        return np.array([self.tendon_section(t).EA for t in self.tendons])

    def tendon_names(self) -> list[str]:
        """Tendon names in :attr:`tendons` order."""
        return [t.name for t in self.tendons]

    def membrane_corners_inertial(self, q=None) -> np.ndarray:
        """Positions (3, N) of the membrane corners B_Mj for configuration q."""
        return self.bar_ends(q)[1][:, -1, :]

    def corner_displacements(self, q=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Corner displacements in the floating frame (eq. 3.4), with the frame.

        Returns
        -------
        delta : ndarray (3, N)
            R^fe (B_Mj - B_MN) - P_j: position of corner B_Mj in O_f minus the undeformed
            corner P_j (``membrane_corners``, w = 0).
        origin : ndarray (3,)
            O_f = B_MN.
        R : ndarray (3, 3)
            R^ef (eq. 3.3), the axes of O_f of :func:`tmfem.system.geometry.floating_frame`.
        """
        corners = self.membrane_corners_inertial(q)
        o, R = floating_frame(corners)
        local = R.T @ (corners - o[:, None])
        local[:2] -= self.membrane_corners
        return local, o, R

    # ------------------------------------------------------------------ symmetry
    def symmetric_from_q(self, q=None, tol: float = 1e-9) -> SymmetricConfig:
        """Recover the symmetric parametrisation (3.19-3.20) from q, or raise InputError."""
        A, theta, psi = self.split_q(q)
        N = self.N
        r1 = np.linalg.norm(self.base[:, 0] - self.base[:, -1]) / (2 * np.sin(np.pi / N))
        c = base_centre(N, r1)
        th, ps, sg, zz, rr = [], [], [], [], []
        j = np.arange(1, N + 1)
        for i in range(self.M):
            rel = A[:, i, :] - c[:, None]
            rad = np.hypot(rel[0], rel[1])
            ang = np.arctan2(rel[1], rel[0])
            sig = wrap_angle(ang - beta(N))
            psi0 = wrap_angle(psi[i] - 2 * np.pi * j / N)
            checks = {"theta": np.ptp(theta[i]), "base radius": np.ptp(rad),
                      "base height": np.ptp(rel[2]), "base rotation": np.ptp(np.unwrap(sig)),
                      "azimuth": np.ptp(np.unwrap(psi0)), "bar length": np.ptp(self.l[i])}
            limit = tol * max(1.0, rad.max())
            bad = {k: v for k, v in checks.items() if v > limit}
            if bad:
                raise InputError(f"stage {i + 1} is not symmetric (eqs. 3.19-3.20): expected a "
                                 f"spread <= {limit:.3g} over the bars, found "
                                 + ", ".join(f"{k} {v:.3g}" for k, v in bad.items()))
            th.append(theta[i, 0])
            ps.append(psi0[-1])
            sg.append(0.0 if i == 0 else sig[-1])
            zz.append(0.0 if i == 0 else rel[2, 0])
            rr.append(rad[0])
        return SymmetricConfig(theta=th, psi=ps, sigma=sg, z=zz, r=rr, l=self.l[:, 0])

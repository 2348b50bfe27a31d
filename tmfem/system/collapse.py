"""A static equilibrium that is no tensegrity any more: bars that collapsed flat or through
their lower ends, non-finite results. Checked on every static solve before anything is
written (docs/guides/cli.md, "Collapse"), so that a converged iteration never passes for a design.
"""
from __future__ import annotations

import math

import numpy as np

from tmfem.errors import CollapsedStructure, shorten
from tmfem.system.topology import label

#: A bar has collapsed when the rise of its upper end above its lower end is at most this
#: fraction of its length (theta >= 88.9 deg) -- or a tenth of its design rise, for designs
#: that stand steeper than that (1-4(D) stowed, theta = 87.6 deg).
FLAT_RISE = 0.02


def flat_bars(system, X) -> list[int]:
    """Stage-major indices (i - 1) N + j - 1 of the bars whose rise in the node positions X
    (3, n_nodes of ``system.node_labels``) fell to the collapse limit (:data:`FLAT_RISE`);
    only bars that rise in the design configuration can collapse."""
    n = system.M * system.N
    X = np.asarray(X, dtype=float)
    Xd = system.nodes()
    rise = X[2, n:2 * n] - X[2, :n]
    rise_d = Xd[2, n:2 * n] - Xd[2, :n]
    lengths = np.asarray(system.l, dtype=float).ravel()
    limit = np.minimum(FLAT_RISE * lengths, 0.1 * rise_d)
    return np.flatnonzero((rise_d > 0) & ~(rise > limit)).tolist()


def nonfinite_keys(values: dict) -> list[str]:
    """Keys of ``values`` (nested dicts and lists of numbers) holding NaN or infinity."""
    bad = []

    def walk(key, v):
        if isinstance(v, dict):
            for k, w in v.items():
                walk(f"{key}.{k}" if key else str(k), w)
        elif isinstance(v, (list, tuple, np.ndarray)):
            if any(not math.isfinite(float(w)) for w in np.ravel(np.asarray(v, dtype=object))
                   if isinstance(w, (int, float, np.number)) and not isinstance(w, bool)):
                bad.append(key)
            else:
                for w in v:
                    if isinstance(w, (dict, list, tuple)):
                        walk(key, w)
        elif isinstance(v, (float, np.floating)) and not math.isfinite(v):
            bad.append(key)
    walk("", values)
    return list(dict.fromkeys(bad))


def check_standing(system, X, *, what: str, values: dict | None = None,
                   rest_lengths=None) -> None:
    """Refuse a static equilibrium that collapsed or has non-finite results.

    Parameters
    ----------
    system : System
    X : ndarray (3, n_nodes)
        Positions of the labelled nodes at the equilibrium found.
    what : str
        The solve, for the message (``static equilibrium of 1-4 (MTC)``).
    values : dict, optional
        Results to scan for NaN and infinity (the summary of the solve).
    rest_lengths : array, optional
        The tendons' rest lengths: the message names the most stretched tendons (chord
        length over rest length; what pulled the structure down).

    Raises
    ------
    CollapsedStructure
        naming the bars (with their rise and the design's), the tendons, and the check.
    """
    flat = flat_bars(system, X)
    bad = nonfinite_keys(values or {})
    if not flat and not bad and np.all(np.isfinite(X)):
        return
    parts = []
    if flat:
        n = system.M * system.N
        Xd = system.nodes()
        names = [label("b", k // system.N + 1, k % system.N + 1) for k in flat]
        k0 = flat[0]
        rise = float(X[2, n + k0] - X[2, k0])
        rise_d = float(Xd[2, n + k0] - Xd[2, k0])
        parts.append(f"bars {shorten(names)} lie flat (check: the rise of a bar's upper end "
                     f"above its lower end > {FLAT_RISE:.0%} of its length; {names[0]}: "
                     f"{rise:.4g} m, design {rise_d:.4g} m)")
    if rest_lengths is not None:
        c = system.tendon_connectivity
        chord = np.linalg.norm(X[:, c[1]] - X[:, c[0]], axis=0)
        stretch = chord / np.asarray(rest_lengths, dtype=float)
        order = np.argsort(-stretch)
        top = [f"{system.tendons[k].name} at {stretch[k]:.3g} x its rest length"
               for k in order if stretch[k] > 1.5]
        if top:
            parts.append(f"tendons stretched {shorten(top, 3)}")
    if bad or not np.all(np.isfinite(X)):
        parts.append(f"non-finite results ({shorten(bad or ['node positions'])}; e.g. a "
                     "membrane strained beyond the range of its law)")
    kind = "collapsed" if flat else "has no valid state"
    raise CollapsedStructure(f"{what} {kind}: " + "; ".join(parts) + " (expected a standing "
                             "tensegrity; check the rest lengths and the prestress)")


def check_equilibrium(model, equilibrium, *, values: dict | None = None) -> None:
    """:func:`check_standing` on the equilibrium of any model (:mod:`tmfem.models.base`): the
    labelled nodes placed from its bar coordinates q (``equilibrium.outputs``, eqs. 3.1-3.2).

    Parameters
    ----------
    model : a model of :mod:`tmfem.models` (``system``, ``name`` and ``u0``, the rest lengths)
    equilibrium : Equilibrium
    values : dict, optional
        The summary of the solve, scanned for NaN and infinity.
    """
    system = model.system
    q = np.array([equilibrium.outputs[n] for n in system.q_names], dtype=float)
    X = system.nodes(q) if np.all(np.isfinite(q)) else np.full((3, len(system.node_labels)), np.nan)
    check_standing(system, X, values=values, rest_lengths=model.u0,
                   what=f"static equilibrium of {system.name} ({model.name.upper()})")


def check_stable(model, modes) -> None:
    """Refuse an equilibrium that lost its stability: a mode of negative stiffness (omega^2
    < 0 in K_T phi = omega^2 M phi, eq. 5.32, beyond 1e-6 of the largest |omega^2|).

    Raises
    ------
    CollapsedStructure
        naming the first unstable mode and its omega^2.
    """
    w2 = np.asarray(modes.omega2, dtype=float)
    neg = np.flatnonzero(~(w2 >= -1e-6 * np.max(np.abs(w2), initial=0.0)))
    if neg.size:
        raise CollapsedStructure(
            f"static equilibrium of {model.system.name} ({model.name.upper()}) is unstable: "
            f"{neg.size} of {w2.size} modes have negative stiffness (mode {neg[0] + 1}: omega^2 = "
            f"{w2[neg[0]]:.4g} 1/s^2; check: the tangent stiffness K_T positive definite, "
            "eq. 5.32); expected a stable tensegrity, check the rest lengths and the prestress")

"""The round-off floor of a static solve: the residual below which no Newton step can go.

Both nonlinear solvers (:mod:`tmfem.solvers.trust_region`, :mod:`tmfem.solvers.petsc_snes`)
accept a state as converged on the floor when energy changes are round-off, |r| no longer
halves and |r| <= :data:`FLOOR_FACTOR` tol x force scale. A model whose floor lies above that
(stiff beams and shells: 1e-9 of the member forces) fails with the tol asked for; the message
says so.
"""
from __future__ import annotations

import numpy as np

#: how far above tol x force scale a residual may end on the round-off floor
FLOOR_FACTOR = 1e3


def floor_hint(rn: float, fs: float, tol: float) -> str:
    """The cause of a failure that ends with |r| = rn at most 1e-6 of the force scale fs (no
    step improved it, or no tenfold progress in 40 iterations): the model's round-off floor
    lies above the :data:`FLOOR_FACTOR` tol fs that the iteration accepts as one, and a tol ten
    times above rn / (FLOOR_FACTOR fs) ends on it; else empty."""
    rel = rn / fs if fs > 0 else np.inf
    if not rel <= 1e-6:
        return ""
    return (f"; the residual stalled at {rel:.2g} of the force scale: the model's round-off floor "
            f"lies above the {FLOOR_FACTOR:g} x tol = {FLOOR_FACTOR * tol:g} taken as one, use "
            f"tol >= {10 * rel / FLOOR_FACTOR:.0e}")

"""The round-off floor of a static solve: the residual below which no Newton step can go.

Both nonlinear solvers (:mod:`tmfem.solvers.trust_region`, :mod:`tmfem.solvers.petsc_snes`)
accept a state as converged on the floor when energy changes are round-off, |r| no longer
halves and |r| <= 1e3 tol x force scale. A model whose floor lies above that (stiff beams
and shells: 1e-9 of the member forces) fails with the tol asked for; the message says so.
"""
from __future__ import annotations

import numpy as np


def floor_hint(rn: float, fs: float, tol: float) -> str:
    """The cause of a failure that ends with |r| = rn at most 1e-6 of the force scale fs (no
    step improved it, or no tenfold progress in 40 iterations): the model's round-off floor
    lies above the 1e3 tol fs that the iteration accepts as one, and a tol ten times above
    rn / (1e3 fs) ends on it; else empty."""
    rel = rn / fs if fs > 0 else np.inf
    if not rel <= 1e-6:
        return ""
    return (f"; the residual stalled at {rel:.2g} of the force scale: the model's round-off floor "
            f"lies above the 1e3 x tol = {1e3 * tol:g} taken as one, use tol >= {10 * rel / 1e3:.0e}")

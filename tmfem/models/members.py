"""Per-member physics of a configuration: lengths, forces, force densities, stresses, slack
(eqs. 3.8-3.9), for output files and pictures."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.system.topology import FAMILIES_D, FAMILIES_MN

#: Codes of the tendon families (cell data ``family`` of the VTK files): index in this tuple.
FAMILY_CODES = FAMILIES_MN + FAMILIES_D


def member_data(system, *, q=None, tendon_forces=None, rest_lengths=None,
                bar_forces=None) -> dict:
    """Per-member data of bars then tendons, each array of length M N + n_tendons.

    Force density is force / current length (eq. 3.8 uses q = f / l); stress is force /
    cross-section area. A tendon is slack when its force is <= 0; without forces, when
    its current length is below its rest length. ``strain`` is (l - l0) / l0.
    """
    nb = system.M * system.N
    nt = len(system.tendons)
    A, B = system.bar_ends(q)
    bar_len = np.linalg.norm(B - A, axis=0).T.ravel()      # stage-major: (i-1) N + j-1
    ten_len = system.tendon_lengths(q)

    def vec(name, v, n):
        if v is None:
            return None
        v = np.asarray(v, dtype=float)
        if v.shape != (n,):
            raise InputError(f"{name}: expected shape ({n},), found {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError(f"{name}: non-finite entries {v}")
        return v

    tf = vec("tendon_forces", tendon_forces, nt)
    bf = vec("bar_forces", bar_forces, nb)
    r = rest_lengths if rest_lengths is not None else system.rest_lengths
    r = vec("rest_lengths", r, nt)
    if r is not None and np.any(r <= 0):
        raise InputError(f"rest_lengths: expected positive values, found {r}")
    nan_b, nan_t = np.full(nb, np.nan), np.full(nt, np.nan)

    force = np.concatenate([nan_b if bf is None else bf, nan_t if tf is None else tf])
    length = np.concatenate([bar_len, ten_len])
    area = np.concatenate([np.full(nb, system.bar.area),
                           [system.tendon_section(t).area for t in system.tendons]])
    if tf is not None:
        slack_t = (tf <= 0).astype(np.int64)
    elif r is not None:
        slack_t = (ten_len < r).astype(np.int64)
    else:
        slack_t = np.full(nt, -1, dtype=np.int64)
    rest = np.concatenate([nan_b, nan_t if r is None else r])
    stage_b = np.repeat(np.arange(1, system.M + 1), system.N)
    j_b = np.tile(np.arange(1, system.N + 1), system.M)
    return {
        "kind": np.concatenate([np.zeros(nb), np.ones(nt)]).astype(np.int64),
        "member_id": np.concatenate([np.arange(nb), np.arange(nt)]).astype(np.int64),
        "family": np.concatenate([np.full(nb, -1),
                                  [FAMILY_CODES.index(t.family) for t in system.tendons]]
                                 ).astype(np.int64),
        "stage": np.concatenate([stage_b, [t.stage for t in system.tendons]]).astype(np.int64),
        "j": np.concatenate([j_b, [t.j for t in system.tendons]]).astype(np.int64),
        "length": length,
        "axial_force": force,
        "force_density": force / length,
        "axial_stress": force / area,
        "slack": np.concatenate([np.full(nb, -1, dtype=np.int64), slack_t]),
        "rest_length": rest,
        "strain": (length - rest) / rest,
    }

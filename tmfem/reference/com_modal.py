"""Natural frequencies of the control-oriented model (6.4, eq. 5.33) and studies.

The COM is linearised about its equilibrium (eq. 5.33); the undamped natural frequencies
are sqrt(eig(M_hat^-1 K)) / 2 pi. The printed COM column and highest COM frequency of the
system's file (``[printed.frequencies_hz]``: Tables 6.6, 6.7 and 6.5 for the presets 1-4 and
2-3) are printed beside ours when the file carries them.
"""
from __future__ import annotations

import logging

import numpy as np

from tmfem.errors import InputError
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.post import com as post_com
from tmfem.reference.tables import printed_frequencies

log = logging.getLogger(__name__)


def dissertation_com_frequencies(system):
    """(source, COM column, highest COM frequency or None) printed for ``system`` (its file's
    ``[printed.frequencies_hz]``: Table 6.6 for the preset 1-4, 6.7 for 2-3), or None."""
    ref = printed_frequencies(system)
    if ref is None or "COM" not in ref:
        return None
    return ref.get("source", "printed"), list(ref["COM"]), ref.get("COM_highest")


def com_frequencies(system, *, membrane_modes: int, prestress_scale: float = 1.0,
                    mesh_n: int = 10, rest_lengths=None, membrane_law: str = "svk"):
    """(frequencies in Hz, model) of the COM linearised about its equilibrium (eq. 5.33)."""
    if rest_lengths is None:       # the system's own (e.g. printed) if it has them
        rest_lengths = "design" if system.rest_lengths is None else "system"
    m = ControlOrientedModel(system, membrane_modes=membrane_modes, mesh_n=mesh_n,
                             prestress_scale=prestress_scale, rest_lengths=rest_lengths,
                             membrane_law=membrane_law)
    lin = linearize(m)
    return lin.frequencies_hz(), m


def modal_summary(system, *, modes: int = 12, membrane_modes: int | None = None,
                  prestress_scale: float = 1.0, mesh_n: int = 10, membrane_law: str = "svk") -> dict:
    """Natural frequencies of the COM beside Tables 6.6/6.7 (JSON-able dict).

    Parameters
    ----------
    system : System
    modes : int
        Number of frequencies reported (at most the number of coordinates nq + K).
    membrane_modes : int, optional
        K; default the dissertation's (5 for 1-4, 4 for 2-3).
    prestress_scale : float
        Factor on the designed membrane prestress (1 = designed, see ControlOrientedModel).
    membrane_law : {"svk", "tension-field"}
        Membrane basis about the linear or the tension-field prestress (docs/guides/wrinkling.md).
    """
    K = default_membrane_modes(system) if membrane_modes is None else int(membrane_modes)
    if not (isinstance(modes, int) and modes >= 1):
        raise InputError(f"--modes: expected an integer >= 1, found {modes!r}")
    log.info("%s COM, K = %d membrane modes", system.name, K)
    rest_lengths = "design" if system.rest_lengths is None else "system"
    m = ControlOrientedModel(system, membrane_modes=K, mesh_n=mesh_n,
                             prestress_scale=prestress_scale, rest_lengths=rest_lengths,
                             membrane_law=membrane_law)
    res = m.equilibrium()
    return add_dissertation_com(post_com.modal_summary(m, res, m.modes(k=modes, at=res)),
                                system=system, modes=modes)


def add_dissertation_com(out: dict, *, system, modes: int) -> dict:
    """``out`` (:func:`tmfem.post.com.modal_summary`) with the printed COM column of
    ``system``'s file (Table 6.6/6.7 for the presets) and the relative differences, for the
    file's K."""
    ref = dissertation_com_frequencies(system)
    if ref is not None and out["membrane_modes"] == out["default_membrane_modes"]:
        src, com, highest = ref
        f = np.asarray(out["freq_hz"])
        k = min(len(f), len(com))
        out["dissertation"] = {"source": src, "COM": com[:k],
                               "highest_hz": highest}
        out["relative_difference"] = (f[:k] / np.array(com[:k]) - 1).tolist()
    return out


def frequency_study(system, *, K_values, prestress_scales=(1.0,), modes: int = 12,
                    mesh_n: int = 10) -> list[dict]:
    """Frequencies vs number of membrane modes K and prestress factor (rows of dicts)."""
    rows = []
    for s in prestress_scales:
        for K in K_values:
            log.info("frequency study %s: prestress x%g, K = %d", system.name, s, K)
            f, m = com_frequencies(system, membrane_modes=K, prestress_scale=s, mesh_n=mesh_n)
            rows.append({"prestress_scale": s, "K": K, "freq_hz": f[:modes].tolist(),
                         "highest_hz": float(f[-1])})
    return rows

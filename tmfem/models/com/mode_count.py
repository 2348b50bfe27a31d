"""How many membrane modes K the control-oriented model keeps (eq. 5.1) when the system file
does not say (``[models.com] membrane_modes``).

The COM's frequencies converge towards the finite-element models' as K grows, until what
remains is its own approximation (rigid bars, membrane modes about the designed prestress,
ch. 5). The default K is the smallest one whose frequencies in the *band of interest* -- the
:data:`BAND_MODES` lowest modes, those ``tmfem modal`` and ``tmfem report`` show by default --
agree with the finite-element model's within :data:`TOLERANCE`, among the K that keep every
repeated membrane frequency whole (:func:`splits_repeated`):

    max_i |f_i^COM(K) / f_i^FE - 1| <= TOLERANCE,   i = 1 .. BAND_MODES,

with the MTC model as reference, or the SBC model for a 1-N(D) system (the MTC has no H_1j
nodes). When no K up to :data:`K_SEARCH` agrees, K is the smallest whose band lies within
:data:`CONVERGED` of the K = :data:`K_SEARCH` model's (more modes would not change the band)
and a warning names the modes that still disagree.

Cost: one finite-element modal analysis (mesh 10, 3 elements per tendon) and one COM with
K = :data:`K_SEARCH`; the COM of K < K_SEARCH modes is the Galerkin truncation of that one
(the first K of the same fixed-corner modes, eq. 5.1), so its linearised mass and stiffness
(eq. 5.33) are the leading blocks of the K_SEARCH model's, exact about eta = 0. The choice is
kept per system content, in the process and on disk (:mod:`tmfem.cache`, namespace
``membrane-modes``, keyed by the system's content, this module's constants and tmfem's
version), so the commands and functions that build COMs of one system pay for it once, also
across runs.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from tmfem.cache import JsonCache, content_digest
from tmfem.errors import TmfemError

log = logging.getLogger(__name__)

#: the band of interest: the lowest modes compared (the default ``--modes`` of modal and report)
BAND_MODES = 12
#: largest relative difference to the finite-element frequencies accepted in the band
#: (6.4 finds < 3 % for 1-4 and < 1 % for 2-3 with the dissertation's K)
TOLERANCE = 0.05
#: relative change of the band below which more membrane modes no longer matter
CONVERGED = 0.01
#: smallest automatic K: the three measured membrane points of the deployed plants of 7.4
K_MIN = 3
#: the most membrane modes the automatic choice considers (one COM of this size is built)
K_SEARCH = 16
#: membrane elements per side of each patch of the finite-element model compared with (6.2: 10)
FE_MESH = 10
#: relative gap below which neighbouring membrane frequencies are one repeated frequency (the
#: pairs of a cyclically symmetric membrane): the automatic K never keeps part of one
REPEATED = 1e-6


@dataclass
class MembraneModeChoice:
    """The membrane modes K of a system's control-oriented model and where K comes from.

    Attributes
    ----------
    K : int
    source : {"file", "automatic", "given"}
        ``"file"``: the system file's ``[models.com] membrane_modes``; ``"automatic"``:
        :func:`choose_membrane_modes`; ``"given"``: an option (``--membrane-modes``) or argument.
    reference : str
        The model the band was compared with (``"MTC"``, ``"SBC"``; ``"COM K=16"`` when the
        finite-element model failed); "" for ``source="file"``.
    band_modes, tolerance : int, float
    reference_hz, com_hz : list of float
        The band's frequencies of the reference and of the COM with the chosen K (truncation).
    relative_difference : list of float
        com_hz / reference_hz - 1 per mode of the band.
    disagreeing_modes : list of int
        Modes (1-based) of the band still more than ``tolerance`` off.
    max_difference_by_K : dict
        K -> largest |relative difference| in the band (None: fewer than band_modes modes).
    cached : bool
        The automatic choice was read from the on-disk cache (:mod:`tmfem.cache`).
    """

    K: int
    source: str
    reference: str = ""
    band_modes: int = 0
    tolerance: float = TOLERANCE
    reference_hz: list = field(default_factory=list)
    com_hz: list = field(default_factory=list)
    relative_difference: list = field(default_factory=list)
    disagreeing_modes: list = field(default_factory=list)
    max_difference_by_K: dict = field(default_factory=dict)
    cached: bool = False

    @property
    def text(self) -> str:
        """One line for the commands' output."""
        if self.source == "file":
            return f"K = {self.K} membrane modes ([models.com] membrane_modes of the file)"
        if self.source == "given":
            return f"K = {self.K} membrane modes (given)"
        s = (f"K = {self.K} membrane modes (chosen: the COM's {self.band_modes} lowest frequencies "
             f"against the {self.reference} model's, tolerance {100 * self.tolerance:g} %")
        if self.disagreeing_modes:
            worst = max(abs(self.relative_difference[i - 1] if self.relative_difference[i - 1] is not None
                            else np.inf) for i in self.disagreeing_modes)
            s += (f"; modes {self.disagreeing_modes} still differ, by up to {100 * worst:.1f} %, "
                  "and more modes do not change them")
        return s + (", cached)" if self.cached else ")")

    def to_dict(self) -> dict:
        """JSON-able (a non-finite difference -- an unstable mode -- becomes None)."""
        def finite(v):
            return v if v is None or np.isfinite(v) else None
        return {"K": self.K, "source": self.source, "reference": self.reference,
                "band_modes": self.band_modes, "tolerance": self.tolerance,
                "reference_hz": self.reference_hz, "com_hz": self.com_hz,
                "relative_difference": [finite(v) for v in self.relative_difference],
                "disagreeing_modes": self.disagreeing_modes,
                "max_difference_by_K": {str(k): finite(v) for k, v in self.max_difference_by_K.items()},
                "cached": self.cached}

    @classmethod
    def from_dict(cls, d: dict) -> "MembraneModeChoice":
        """The inverse of :meth:`to_dict` (integer K keys again); raises TypeError or ValueError
        on a dict that is not one."""
        d = dict(d)
        d["max_difference_by_K"] = {int(k): v for k, v in d.get("max_difference_by_K", {}).items()}
        return cls(**d)


_CHOICES: dict[str, MembraneModeChoice] = {}
#: the automatic choices kept between runs
_STORE = JsonCache("membrane-modes")


def membrane_modes_of(system, K: int | None = None, *, model_class) -> MembraneModeChoice:
    """``K`` when given (``source="given"``), else :func:`membrane_mode_choice`.
    ``model_class``: the control-oriented model's class (passed in by
    :func:`tmfem.models.com.model.membrane_modes_of`, so that this module stays below it)."""
    if K is not None:
        return MembraneModeChoice(K=int(K), source="given")
    return membrane_mode_choice(system, model_class=model_class)


def declared_membrane_modes(system) -> int | None:
    """K of the system's ``[models.com] membrane_modes``, None when the file declares none."""
    K = system.model_defaults.get("com", {}).get("membrane_modes")
    return None if K is None else int(K)


def membrane_mode_choice(system, *, model_class) -> MembraneModeChoice:
    """K of the system's ``[models.com] membrane_modes`` (the presets carry the
    dissertation's: 5 for 1-4, 4 for 2-3, 3 for 1-4(D), 5 for 1-6D), else
    :func:`choose_membrane_modes` (computed once per system content)."""
    K = declared_membrane_modes(system)
    if K is not None:
        return MembraneModeChoice(K=int(K), source="file")
    key = _fingerprint(system)
    if key not in _CHOICES:
        _CHOICES[key] = _stored_choice(system, key, model_class=model_class)
    return _CHOICES[key]


def _cache_key(fingerprint: str) -> dict:
    """Everything the automatic choice depends on: the system's content and this module's
    constants (tmfem's version is added by the cache)."""
    return {"system": fingerprint, "BAND_MODES": BAND_MODES, "TOLERANCE": TOLERANCE, "CONVERGED": CONVERGED,
            "K_MIN": K_MIN, "K_SEARCH": K_SEARCH, "FE_MESH": FE_MESH, "REPEATED": REPEATED}


def _stored_choice(system, fingerprint: str, *, model_class) -> MembraneModeChoice:
    """:func:`choose_membrane_modes` through the on-disk cache: an entry of the same key is
    read (``cached=True``; its warning repeated), else the choice is computed and stored."""
    key = _cache_key(fingerprint)
    entry = _STORE.get(key)
    if entry is not None:
        try:
            choice = MembraneModeChoice.from_dict(entry)
            if choice.source != "automatic" or choice.K < 1:
                raise ValueError(f"source {choice.source!r}, K = {choice.K}")
        except (TypeError, ValueError) as e:
            log.info("%s: cached membrane-mode choice %s is not one (%s): recomputing",
                     system.name, _STORE.path(key), e)
        else:
            choice.cached = True
            log.debug("%s: %s", system.name, choice.text)
            _warn_disagreeing(system, choice)
            return choice
    choice = choose_membrane_modes(system, model_class=model_class)
    _STORE.put(key, {k: v for k, v in choice.to_dict().items() if k != "cached"})
    return choice


def choose_membrane_modes(system, *, model_class, band_modes: int = BAND_MODES,
                          tolerance: float = TOLERANCE, k_search: int = K_SEARCH) -> MembraneModeChoice:
    """The smallest K in K_MIN..k_search whose COM frequencies in the band (the ``band_modes``
    lowest) agree with the finite-element model's within ``tolerance`` (module docstring);
    else the smallest K whose band is within :data:`CONVERGED` of the k_search model's, with a
    warning naming the modes that disagree. ``model_class``: the control-oriented model's class
    (:class:`tmfem.models.com.model.ControlOrientedModel`)."""
    from tmfem.resources import check_membrane_modes, check_mesh_budget

    check_membrane_modes(k_search, given="the automatic membrane-mode search")
    check_mesh_budget(N=system.N, n=FE_MESH, option=f"the automatic membrane-mode search's FE mesh {FE_MESH}")
    rest = "design" if system.rest_lengths is None else "system"
    com = model_class(system, membrane_modes=k_search, rest_lengths=rest, output_points=[])
    lin = com.linearization()
    nq, k_hi = com.nq, com.K
    n = min(band_modes, nq + k_hi)
    fe_name, ref = _fe_band(system, n, rest)
    if ref is None:
        ref = _truncated_hz(lin, nq + k_hi, n)
        fe_name = f"COM K={k_hi}"
    ref = np.asarray(ref, dtype=float)
    n = min(n, len(ref))
    ref = ref[:n]
    hi = _truncated_hz(lin, nq + k_hi, n)
    worst, bands = {}, {}
    for K in range(min(K_MIN, k_hi), k_hi + 1):
        if nq + K < n or splits_repeated(com.membrane.omega, K):
            worst[K] = None
            continue
        f = _truncated_hz(lin, nq + K, n)
        bands[K] = f
        worst[K] = float(np.max(np.abs(_relative(f, ref))))
    agree = [K for K, w in worst.items() if w is not None and w <= tolerance]
    if agree:
        K = agree[0]
    else:
        K = min(K for K, f in bands.items() if np.all(np.abs(f - hi) <= CONVERGED * np.abs(hi)))
    rel = _relative(bands[K], ref)
    bad = [int(i) + 1 for i in np.flatnonzero(np.abs(rel) > tolerance)]
    choice = MembraneModeChoice(K=K, source="automatic", reference=fe_name, band_modes=n,
                                tolerance=tolerance, reference_hz=ref.tolist(),
                                com_hz=bands[K].tolist(), relative_difference=rel.tolist(),
                                disagreeing_modes=bad, max_difference_by_K=worst)
    log.info("%s: membrane modes by K (largest difference to %s in the %d lowest modes): %s",
             system.name, fe_name, n, ", ".join(f"{k}: {'-' if w is None else f'{100 * w:.1f} %'}"
                                                 for k, w in worst.items()))
    log.debug("%s: %s", system.name, choice.text)
    _warn_disagreeing(system, choice, k_search=k_hi)
    return choice


def _warn_disagreeing(system, choice: MembraneModeChoice, *, k_search: int = K_SEARCH) -> None:
    """The warning that names the band's modes no K brings within the tolerance."""
    if not choice.disagreeing_modes:
        return
    worst = max(np.inf if v is None else abs(v) for v in choice.relative_difference)
    log.warning("%s: COM frequencies of modes %s differ from the %s model's by more than %g %% with "
                "any K up to %d (largest %.1f %% at the chosen K = %d): the COM's own approximation "
                "(rigid bars, linear tendon springs of eqs. 3.8-3.9, membrane modes about the "
                "designed prestress, ch. 5; docs/guides/com.md)", system.name, choice.disagreeing_modes,
                choice.reference, 100 * choice.tolerance, k_search, 100 * worst, choice.K)


def _relative(f, ref) -> np.ndarray:
    """f / ref - 1, with inf where either is not a positive frequency (an unstable mode never
    agrees)."""
    f, ref = np.asarray(f, dtype=float), np.asarray(ref, dtype=float)
    ok = (f > 0) & (ref > 0)
    return np.where(ok, f / np.where(ok, ref, 1.0) - 1.0, np.inf)


def splits_repeated(omega, K: int) -> bool:
    """Whether the first K membrane modes of frequencies ``omega`` (ascending) keep part of a
    repeated frequency (omega_K and omega_K+1 within :data:`REPEATED` of each other): such a
    COM depends on which vectors of the frequency's eigenspace the eigensolver returned."""
    return 0 < K < len(omega) and abs(omega[K] - omega[K - 1]) <= REPEATED * abs(omega[K])


def _truncated_hz(lin, m: int, n: int) -> np.ndarray:
    """The ``n`` lowest frequencies [Hz] of the leading m x m blocks of the linearised mass and
    stiffness (eq. 5.33): the COM with the first m - n_q membrane modes."""
    import scipy.linalg as sla
    lam = np.sort(sla.eigvals(lin.K[:m, :m], lin.M[:m, :m]).real)[:n]
    return np.sign(lam) * np.sqrt(np.abs(lam)) / (2 * np.pi)


def _fe_band(system, n: int, rest: str):
    """("MTC" or "SBC", the n lowest frequencies [Hz]) of the finite-element model the COM is
    compared with (mesh 10, 3 elements per tendon), or (name, None) when it fails."""
    if system.deployable:
        from tmfem.models.sbc.model import SBCModel as FE
        name = "SBC"
    else:
        from tmfem.models.mtc.model import MTCModel as FE
        name = "MTC"
    try:
        model = FE(system, rest_lengths=rest, mesh_n=FE_MESH)
        return name, model.modes(k=n, at=model.equilibrium()).freq_hz
    except TmfemError as e:
        log.warning("%s: the %s model failed (%s); membrane modes chosen by the COM's own "
                    "convergence", system.name, name, e)
        return name, None


def _fingerprint(system) -> str:
    """A key of everything the choice depends on: geometry, materials, tendons, rest lengths
    (:func:`tmfem.cache.content_digest`)."""
    return content_digest(system.base, system.l, system.q, system.membrane_corners, system.rest_lengths,
                          system.M, system.N, system.deployable, system.k_H, system.membrane, system.bar,
                          system.tendon_sections, system.tendons)

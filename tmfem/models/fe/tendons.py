"""The tendons of a finite-element model: k tension-only truss elements each (eqs. 4.23-4.24),
their sections, and their rest lengths -- the rules of :mod:`tmfem.models.fe.rest_lengths` at
set-up and the inputs u of a plant in time (eq. 5.19)."""
from __future__ import annotations

import numpy as np

from tmfem.errors import InputError
from tmfem.fem.truss import TrussElement, TrussSet
from tmfem.models.fe.rest_lengths import design_mesh_of, design_rest_lengths_at

#: what a change of rest length does to a tendon (:class:`Tendons`)
TENDON_LAWS = ("cable", "fixed-rate")


class Tendons:
    """Mix-in of the finite-element models: tendon sections and rest lengths.

    The model provides ``system``, ``topology`` (tendon connectivity ``tendon_conn``,
    ``tendon_of_element``, ``tendon_elements``, ``attachment``), ``dofmap``, ``mesh_n``,
    ``patch``, ``backend`` and ``lumped_tendon_mass``, calls :meth:`_init_tendons` and
    implements :meth:`consistent_rest_lengths` (the rule ``"mtc"``).

    ``tendon_law``: what a change of rest length (:meth:`set_tendon_lengths`, a plant's
    input) does to a tendon. ``"cable"``: a cable reeled in or out, EA fixed, so its spring
    rate follows eq. 3.9, k = EA / r, at the current rest length. ``"fixed-rate"``: the rate
    stays k = EA / r_0 of the nominal rest lengths r_0 (EA scales with r / r_0), the
    control-affine tendon of eq. 5.19 (B(x) u) that the control-oriented model uses.
    """

    def _init_tendons(self, rest_lengths, tendon_law: str) -> None:
        if tendon_law not in TENDON_LAWS:
            raise InputError(f"tendon_law: expected 'cable' or 'fixed-rate', found {tendon_law!r}")
        self.tendon_law = tendon_law
        secs = [self.system.tendon_section(t) for t in self.system.tendons]
        self.tendon_EA = np.array([s.EA for s in secs])
        self.tendon_area = np.array([s.area for s in secs])
        self.tendon_rhoA = np.array([(s.rho or 0.0) * s.area for s in secs])
        self.tendon_yield = np.array([s.yield_stress if s.yield_stress else np.nan for s in secs])
        self.rest_lengths_source = None
        if rest_lengths is None:
            rest_lengths = "system" if self.system.rest_lengths is not None else "design"
        self.set_rest_lengths(rest_lengths)

    def set_rest_lengths(self, rest) -> None:
        """Set the tendon rest lengths: an array (one per tendon) or ``"system"``,
        ``"design"`` (the ch. 3 design on this model's mesh and attachment), ``"design@n"``
        or ``"mtc"`` (:mod:`tmfem.models.fe.rest_lengths`)."""
        n_t = len(self.system.tendons)
        if isinstance(rest, str):
            source = rest
            if rest == "system":
                if self.system.rest_lengths is None:
                    raise InputError(f"rest_lengths='system': expected rest lengths in system "
                                     f"{self.system.name!r}, found none (use 'design' or 'mtc')")
                r = self.system.rest_lengths
            elif rest == "design":
                r = self._design_rest_lengths()
            elif rest == "mtc":
                if self.system.deployable:
                    raise InputError("rest_lengths='mtc': does not apply to a 1-N(D) system (the "
                                     "consistent rest lengths balance truss bars without points "
                                     "H_1j); expected 'design' (eq. 3.8), 'system' or values")
                r = self.consistent_rest_lengths()["rest_lengths"]
            elif design_mesh_of(rest) is not None:
                r = design_rest_lengths_at(self.system, design_mesh_of(rest))
            else:
                raise InputError(f"rest_lengths: expected an array or one of 'system', 'design', "
                                 f"'design@n' (n >= 1), 'mtc', found {rest!r}")
        else:
            source = "given"
            r = np.asarray(rest, dtype=float)
        r = np.asarray(r, dtype=float)
        if r.shape != (n_t,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
            raise InputError(f"expected {n_t} positive tendon rest lengths, found {r}")
        self.rest_lengths = r
        self.nominal_rest_lengths = r.copy()
        self.rest_lengths_source = source
        self._set_tendons(r)

    def _design_rest_lengths(self) -> np.ndarray:
        """Rest lengths of the ch. 3 design (eqs. 3.8-3.9) on this model's membrane mesh and
        corner attachment, so that the design and the model see the same corner stiffness."""
        from tmfem.equilibrium.design import design_equilibrium
        d = design_equilibrium(self.system, mesh_n=self.mesh_n,
                               attachment=self.topology.attachment, patch=self.patch,
                               backend=self.backend)
        return np.asarray(d.rest_lengths, dtype=float)

    def _set_tendons(self, r) -> None:
        k = self.topology.tendon_elements
        e = self.topology.tendon_of_element
        self.tendons = TrussSet(conn=self.topology.tendon_conn, L=r[e] / k, EA=self.tendon_EA[e],
                                rhoA=self.tendon_rhoA[e], tension_only=np.ones(e.size, dtype=bool))
        self.tendon_element = TrussElement(self.tendons, self.dofmap,
                                           lumped_mass=self.lumped_tendon_mass)
        self._M = None
        self._dist = None

    def set_tendon_lengths(self, u) -> None:
        """Tendon rest lengths as time-varying inputs (a plant's u): the reference lengths of
        the tendon elements become u / k in place (no re-assembly of patterns)."""
        u = np.asarray(u, dtype=float)
        if u.shape != self.rest_lengths.shape or not np.all(u > 0):
            raise InputError(f"expected {self.rest_lengths.size} positive tendon rest lengths, "
                             f"found {u}")
        if np.array_equal(u, self.rest_lengths):
            return
        self.rest_lengths = u.copy()
        e = self.topology.tendon_of_element
        self.tendons.L = u[e] / self.topology.tendon_elements
        if self.tendon_law == "fixed-rate":
            self.tendons.EA = self.tendon_EA[e] * (u / self.nominal_rest_lengths)[e]

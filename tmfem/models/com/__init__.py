"""Control-oriented model (COM) of tensegrity-membrane systems (dissertation ch. 5).

Rigid bars, massless tendons and a linear membrane described by static corner shapes and
a few prestressed relative-deflection modes in the floating frame O_f; the corner
constraints Phi(q, zeta) = 0 (eq. 3.5) are eliminated by coordinate partitioning
(eqs. 5.20-5.28), giving the ODE  M_hat(z) z'' + F_hat(z, z') + B_hat(z) u = 0  whose input
u is the vector of tendon rest lengths. Entry point: :class:`ControlOrientedModel`; its
linearisation is :func:`tmfem.models.com.linearize.linearize` (also ``tmfem.linearize``).
See docs/guides/com.md.
"""
from tmfem._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "ControlOrientedModel": "tmfem.models.com.model",
    "Linearization": "tmfem.models.com.linearize"
})

"""The section of a homogeneous isotropic shell: its lamina law and its mass.

Used by the MITC4 shell (:mod:`tmfem.fem.mitc4`) and by the membrane laws of
:mod:`tmfem.fem.tension_field`, which take the law of a shell's lamina.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmfem.errors import InputError

#: transverse shear correction factor of the plane-stress lamina law
SHEAR_FACTOR = 5.0 / 6.0


@dataclass(frozen=True)
class ShellSection:
    """Homogeneous isotropic shell: modulus E [Pa], Poisson ratio nu, thickness [m],
    density rho [kg/m^3], transverse shear factor k (5/6)."""

    E: float
    nu: float
    thickness: float
    rho: float = 0.0
    shear_factor: float = SHEAR_FACTOR

    def __post_init__(self):
        for name in ("E", "thickness", "shear_factor"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"shell section: expected {name} > 0, found {v!r}")
        if not (np.isfinite(self.rho) and self.rho >= 0):
            raise InputError(f"shell section: expected rho >= 0, found {self.rho!r}")
        if not (-1.0 < self.nu < 0.5):
            raise InputError(f"shell section: expected -1 < nu < 0.5, found {self.nu!r}")

    def lamina_matrix(self) -> np.ndarray:
        """D (5, 5) of the local engineering strains [e11, e22, 2e12, 2e13, 2e23]:
        plane-stress St.Venant-Kirchhoff plus k G transverse shear (eq. 4.9)."""
        E, nu = self.E, self.nu
        c = E / (1.0 - nu**2)
        G = E / (2.0 * (1.0 + nu))
        D = np.zeros((5, 5))
        D[:2, :2] = c * np.array([[1.0, nu], [nu, 1.0]])
        D[2, 2] = G
        D[3, 3] = D[4, 4] = self.shear_factor * G
        return D

"""Materials and cross sections of membranes, bars and tendons (Tables 6.1, 7.2, 7.4, 7.6)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from tmfem.errors import InputError


# Largest magnitude accepted for a material constant or size: far beyond any material
# (diamond: E ~ 1.2e12 Pa) but small enough that products such as E A l^2 or E I stay
# finite in double precision (E = 1e300 overflowed in the stiffness and was reported as
# a geometric failure).
MAX_MAGNITUDE = 1e20


def _positive(owner: str, **values: float | None) -> None:
    for name, v in values.items():
        if v is None:
            continue
        if isinstance(v, bool) or not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise InputError(f"{owner}: expected {name} > 0, found {v!r}")
        if v > MAX_MAGNITUDE:
            raise InputError(f"{owner}: expected {name} <= {MAX_MAGNITUDE:g} (SI units), found "
                             f"{v!r}")


@dataclass(frozen=True)
class MembraneMaterial:
    """Isotropic linear-elastic membrane: modulus E [Pa], Poisson ratio nu, density rho
    [kg/m^3], thickness h [m], optional yield stress [Pa] for the checks of eqs. 5.29-5.30."""

    E: float
    nu: float
    rho: float
    h: float
    yield_stress: float | None = None

    def __post_init__(self):
        _positive("membrane", E=self.E, rho=self.rho, h=self.h, yield_stress=self.yield_stress)
        if not (0.0 <= self.nu < 0.5):
            raise InputError(f"membrane: expected 0 <= nu < 0.5, found nu={self.nu!r}")


@dataclass(frozen=True)
class BarSection:
    """Solid circular bar: modulus E [Pa], density rho [kg/m^3], diameter d [m]."""

    E: float
    rho: float
    d: float

    def __post_init__(self):
        _positive("bar", E=self.E, rho=self.rho, d=self.d)

    @property
    def area(self) -> float:
        """Cross-section area pi d^2 / 4."""
        return math.pi * self.d**2 / 4.0

    @property
    def inertia(self) -> float:
        """Area moment of inertia of the solid circle, pi d^4 / 64."""
        return math.pi * self.d**4 / 64.0

    def mass(self, length: float) -> float:
        """Mass rho A l of a bar of the given length."""
        return self.rho * self.area * length

    def euler_critical_load(self, length: float, K: float = 1.0) -> float:
        """Euler buckling load pi^2 E I / (K l^2) of a hinged column (eq. 5.31)."""
        return math.pi**2 * self.E * self.inertia / (K * length**2)


@dataclass(frozen=True)
class TendonSection:
    """Tendon: modulus E [Pa], diameter d [m], optional density rho and yield stress."""

    E: float
    d: float
    rho: float | None = None
    yield_stress: float | None = None

    def __post_init__(self):
        _positive("tendon", E=self.E, d=self.d, rho=self.rho, yield_stress=self.yield_stress)

    @property
    def area(self) -> float:
        """Cross-section area pi d^2 / 4."""
        return math.pi * self.d**2 / 4.0

    @property
    def EA(self) -> float:
        """Axial stiffness E A (eqs. 3.8-3.9)."""
        return self.E * self.area

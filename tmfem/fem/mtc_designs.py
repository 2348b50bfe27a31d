"""The 2-3 design behind Tables 6.5 and 6.7 (identified with the MTC model; docs/errata.md).

The 2-3 design printed in Table 6.4 is not an equilibrium (Delta < 0, slack tendons), and
its printed rest lengths fit no symmetric equilibrium of its dimensions. Tables 6.5 and 6.7
are reproduced instead by the *final (deployed) configuration of the 2-3 system of 7.4.3*
(Table 7.7: theta = 55 deg, psi_1 = 10 deg, psi_2 = -24.86 deg, l = 1.8 m, r_1 = 0.75 m,
r_mb = 1 m), built with the materials of Table 6.1 (steel bars of 30 mm, nylon tendons of
0.6 mm, Kapton membrane). Its stage-2 base is not printed; eq. 5.97 gives sigma_2 = psi_2 - psi
= -34.86 deg, and r_2, z_2 follow from the seven printed final rest lengths of Table 7.7 with
the tendon forces of the null vector of eq. 3.26 (:func:`fit_stage2_base`: residual below the
0.1 mm rounding of the table): r_2 = 0.52088 m, z_2 = 0.72269 m, Delta = 0.988 mm.
"""
from __future__ import annotations

import numpy as np

from tmfem.system import load_preset
from tmfem.system.geometry import SymmetricConfig
from tmfem.system.system import System

# Table 7.7, final configuration (tendon sections of Table 7.6: d = 0.254 mm, C and D 0.4 mm)
TABLE_7_7_FINAL_REST = {"S1": 1.0286, "V2": 0.7736, "D2": 0.7199, "C2": 1.1094, "R2": 1.4835,
                        "P2": 0.8459, "S2": 1.1831}
THETA_DEG, PSI1_DEG, PSI2_DEG = 55.0, 10.0, -24.86        # Table 7.7
L_BAR, R1, R_MB = 1.8, 0.75, 1.0                          # 7.4.3
R2_FIT, Z2_FIT = 0.52088, 0.72269                         # fit_stage2_base()


def _config(r2: float, z2: float, sigma2: float) -> SymmetricConfig:
    th = np.radians(THETA_DEG)
    return SymmetricConfig(theta=[th, th], psi=[np.radians(PSI1_DEG), np.radians(PSI2_DEG)],
                           sigma=[0.0, sigma2], z=[0.0, z2], r=[R1, r2], l=[L_BAR, L_BAR])


def chapter7_final_2_3(*, materials: str = "table_6_1", r2: float = R2_FIT, z2: float = Z2_FIT
                       ) -> System:
    """The final 2-3 configuration of Table 7.7 with sigma_2 from eq. 5.97.

    ``materials="table_6_1"``: membrane, bars and tendons of Table 6.1 (those of the 2-3
    preset); ``"chapter_7"``: wood bars (E = 11 GPa, 800 kg/m^3, 30 mm) and the tendons of
    Table 7.6, with the printed final rest lengths of Table 7.7.
    """
    from tmfem.system.materials import BarSection, TendonSection
    base = load_preset("2-3")
    sigma2 = np.radians(PSI2_DEG - PSI1_DEG)
    cfg = _config(r2, z2, sigma2)
    if materials == "table_6_1":
        bar, secs, rest = base.bar, dict(base.tendon_sections), None
    elif materials == "chapter_7":
        thin = TendonSection(E=2e9, d=0.254e-3, rho=1140.0)
        thick = TendonSection(E=2e9, d=0.4e-3, rho=1140.0)
        bar = BarSection(E=11e9, rho=800.0, d=0.03)
        secs = {"S": thin, "V": thin, "R": thin, "P": thin, "C": thick, "D": thick}
        rest = dict(TABLE_7_7_FINAL_REST)
    else:
        raise ValueError(f"materials: expected 'table_6_1' or 'chapter_7', found {materials!r}")
    return System.symmetric_system(
        name="2-3", N=3, config=cfg, r_mb=R_MB, membrane=base.membrane, bar=bar,
        tendon_sections=secs, rest_lengths=rest, printed=dict(base.printed),
        description="final 2-3 configuration of Table 7.7 (sigma_2 by eq. 5.97, r_2 and z_2 "
                    "fitted to its rest lengths): the design of Tables 6.5 and 6.7")


def fit_stage2_base(*, starts: int = 5, seed: int = 0) -> dict:
    """r_2, z_2 (and F_Delta) that make the printed final rest lengths of Table 7.7 those of
    the symmetric equilibrium (eqs. 3.8, 3.26) at sigma_2 = psi_2 - psi (eq. 5.97).

    Least squares on |d_g| - r_g (1 + T_g / EA_g) for the seven tendon groups, with T_g the
    null vector of the reduced matrix of 3.3.2 scaled by F_Delta. Returns r2, z2, F_Delta, the
    residuals [m] and Delta.
    """
    from scipy.linalg import null_space
    from scipy.optimize import least_squares

    from tmfem.equilibrium.general import symmetric_groups, symmetric_matrix
    from tmfem.equilibrium.symmetric import membrane_delta

    s0 = chapter7_final_2_3(materials="chapter_7")
    groups = symmetric_groups(s0)
    gi = [next(i for i, t in enumerate(s0.tendons) if t.group == g) for g in groups]
    rest = np.array([TABLE_7_7_FINAL_REST[g] for g in groups])
    EA = s0.tendon_EA[gi]

    def residual(p):
        r2, z2, F = p
        s = chapter7_final_2_3(materials="chapter_7", r2=r2, z2=z2)
        v = null_space(symmetric_matrix(s).A)[:, -1]
        v = v / v[-1]
        return s.tendon_lengths()[gi] - rest * (1.0 + F * v[:-1] / EA)

    rng = np.random.default_rng(seed)
    best = None
    for k in range(starts):
        p0 = np.array([0.5, 0.7, 2.0]) if k == 0 else np.array(
            [0.1 + 1.0 * rng.random(), 0.1 + 1.2 * rng.random(), 5.0 * rng.random()])
        r = least_squares(residual, p0, bounds=([0.02, 0.0, 0.0], [2.0, 2.5, 100.0]))
        if best is None or r.cost < best.cost:
            best = r
    r2, z2, F = best.x
    sg = np.radians(PSI2_DEG - PSI1_DEG)
    D = membrane_delta(l_M=L_BAR, theta_M=np.radians(THETA_DEG), psi_M=np.radians(PSI2_DEG),
                       sigma_M=sg, r_M=r2, r_mb=R_MB, N=3)
    return {"r2": float(r2), "z2": float(z2), "F_Delta": float(F), "Delta": float(D),
            "residual": residual(best.x), "groups": groups}


def scaled_consistent_rest_lengths(model, scale: float) -> np.ndarray:
    """Rest lengths that carry ``scale`` times the design-consistent forces of ``model``
    (:meth:`MTCModel.consistent_rest_lengths`) at the design lengths (Green-strain truss)."""
    from tmfem.fem.mtc import green_rest_length
    c = model.consistent_rest_lengths()
    return green_rest_length(c["tendon_length"], scale * c["tendon_force"], model.tendon_EA)

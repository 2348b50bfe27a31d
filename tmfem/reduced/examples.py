"""Example configurations for the control-oriented model."""
from __future__ import annotations

import numpy as np

from tmfem.system import load_preset
from tmfem.system.geometry import SymmetricConfig


def feasible_2_3():
    """A stable symmetric 2-3 equilibrium: stage 1, bars and membrane of Table 6.4, but the
    stage-2 base found by ``tmfem.equilibrium.symmetric_map.best_bases`` at theta = 63 deg,
    psi = 20 deg (r_2 = 0.364 m, z_2 = 0.551 m, sigma_2 = 162.6 deg, psi_2 = psi_1 + sigma_2,
    eq. 5.97); docs/errata.md. The printed 2-3 geometry has Delta < 0 (slack membrane)."""
    s = load_preset("2-3")
    c = s.symmetric
    th, ps, r2, z2, sg = np.radians(63.0), np.radians(20.0), 0.364, 0.551, np.radians(162.6)
    cfg = SymmetricConfig(theta=[th, th], psi=[ps, ps + sg], sigma=[0.0, sg], z=[0.0, z2],
                          r=[c.r[0], r2], l=c.l)
    notes = tuple(s.notes) + (
        "Stage-2 base r_2 = 0.364 m, z_2 = 0.551 m, sigma_2 = 162.6 deg, psi_2 = psi_1 + sigma_2 "
        "from tmfem.equilibrium.symmetric_map.best_bases at (63, 20) deg: Table 6.4's base gives "
        "Delta < 0 (docs/errata.md). Not the dissertation's design; Table 6.7 does not apply.",)
    return s.replace(q=cfg.to_q(3), symmetric=cfg, rest_lengths=None, printed={}, notes=notes,
                     description="2-3 with a feasible stage-2 base (tmfem.reduced.examples)")

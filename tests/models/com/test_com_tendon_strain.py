"""The control-oriented model against the MTC model when the tendons are strained by percents.

The COM's tendons are the linear springs of eqs. 3.8-3.9 (T = EA/r (|d| - r), rate EA/r); the
finite-element models' are total-Lagrangian trusses with the Green-Lagrange strain of eq. 4.7
(N = EA E l / r, E = (l^2 - r^2) / (2 r^2), rate EA/r (3 s^2 - 1) / 2 with s = l / r). They
agree to first order in the strain, so the two models' frequencies part with the tendon strain:
the 2-4 test system's tendons (E = 2 GPa, d = 0.6 mm) carry 1.7-7.5 % strain at the design.
Reference: the MTC model of the same system (an independent formulation), and the same system
with tendons 100 x stiffer (strains 100 x smaller), where the two tendon laws coincide.
"""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tmfem.models.com.model import ControlOrientedModel
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_system

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


def com_over_mtc(system) -> np.ndarray:
    """f_COM / f_MTC - 1 of the six lowest modes (K = 4, mesh 10, design rest lengths)."""
    com = ControlOrientedModel(system, membrane_modes=4, output_points=[])
    mtc = MTCModel(system, rest_lengths="design")
    f_mtc = mtc.modes(k=6, at=mtc.equilibrium()).freq_hz
    return com.linearization().frequencies_hz()[:6] / f_mtc - 1


@pytest.fixture(scope="module")
def tower():
    return load_system(SYSTEMS / "square-2-4.toml")


def test_the_2_4_tendons_are_strained_by_percents(tower):
    """Design tendon forces / EA: 1.7-7.5 % (the COM's design, eqs. 3.8-3.9)."""
    com = ControlOrientedModel(tower, membrane_modes=0, output_points=[])
    strain = com.design.tendon_forces / com.EA
    assert 0.015 < strain.min() and 0.07 < strain.max() < 0.08


@pytest.mark.slow
def test_com_meets_the_mtc_when_the_tendon_strain_is_small(tower):
    """As designed, the COM is 4-6 % below the MTC in every one of the six lowest modes; with the
    tendons 100 x stiffer (the same geometry and prestress, strains below 0.08 %) the two tendon
    laws agree and so do the models, within 1.5 % -- the gap is the tendon law, not the COM's
    rigid bars, mass or membrane."""
    gap = com_over_mtc(tower)
    assert np.all(gap < -0.04) and np.all(gap > -0.065)
    stiff = {k: dataclasses.replace(v, E=100 * v.E) for k, v in tower.tendon_sections.items()}
    close = com_over_mtc(dataclasses.replace(tower, tendon_sections=stiff))
    assert np.max(np.abs(close)) < 0.015

"""The default membrane-mode count K of the control-oriented model (tmfem.models.com.mode_count).

References: the finite-element models' frequencies (MTC, an independent formulation of the
same structure) and COMs built with each K (the truncation the search uses against a full build).
"""
import logging
from pathlib import Path

import numpy as np
import pytest

from tmfem.models.com import mode_count
from tmfem.models.com.model import ControlOrientedModel, default_membrane_modes
from tmfem.models.mtc.model import MTCModel
from tmfem.system import load_system
from tmfem.system.presets import list_presets, load_preset

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


@pytest.fixture(scope="module")
def kapton():
    return load_system(SYSTEMS / "kapton-1-4.toml")


def test_truncated_search_model_has_the_frequencies_of_a_com_built_with_k():
    """The search evaluates K < 16 as the leading blocks of the K = 16 linearisation (eq. 5.33);
    a COM built with K = 6 has the same frequencies (the same first six fixed-corner modes: K = 6
    keeps the triangle's 3.6062 Hz pair, modes 5 and 6, whole)."""
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    big = ControlOrientedModel(s, membrane_modes=16, output_points=[])
    small = ControlOrientedModel(s, membrane_modes=6, output_points=[])
    f = mode_count._truncated_hz(big.linearization(), big.nq + 6, 11)
    assert f == pytest.approx(small.linearization().frequencies_hz()[:11], rel=1e-6)


def test_the_search_never_keeps_part_of_a_repeated_membrane_frequency():
    """The triangle's membrane has the pairs 2-3, 5-6, 8-9 (three-fold symmetry, equal to 1e-9):
    K = 2, 5, 8 would keep one vector of a pair, an arbitrary one of its eigenspace."""
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    omega = ControlOrientedModel(s, membrane_modes=10, output_points=[]).membrane.omega
    assert np.allclose(omega[[1, 4, 7]], omega[[2, 5, 8]], rtol=1e-9)
    split = [K for K in range(1, 10) if mode_count.splits_repeated(omega, K)]
    assert split == [2, 5, 8]
    c = mode_count.choose_membrane_modes(s, model_class=ControlOrientedModel)
    assert c.K not in split and all(c.max_difference_by_K[K] is None for K in (5, 8))


@pytest.mark.slow
def test_kapton_gets_the_smallest_k_that_matches_the_mtc_band(kapton):
    """The 3 m Kapton 1-4 (a floppy membrane: many membrane modes among the 12 lowest): K = 4
    puts modes 8-12 up to 50 % above the MTC's; the chosen K brings all twelve within 5 % of an
    independent MTC modal analysis, and K - 1 does not."""
    c = mode_count.choose_membrane_modes(kapton, model_class=ControlOrientedModel)
    assert c.source == "automatic" and c.reference == "MTC" and not c.disagreeing_modes
    mtc = MTCModel(kapton, rest_lengths="design")
    ref = mtc.modes(k=12, at=mtc.equilibrium()).freq_hz
    com = ControlOrientedModel(kapton, membrane_modes=c.K, output_points=[])
    f = com.linearization().frequencies_hz()[:12]
    assert np.max(np.abs(f / ref - 1)) <= mode_count.TOLERANCE
    before = ControlOrientedModel(kapton, membrane_modes=c.K - 1, output_points=[])
    g = before.linearization().frequencies_hz()[:12]
    assert np.max(np.abs(g / ref - 1)) > mode_count.TOLERANCE
    old = c.max_difference_by_K[4]
    assert old > 0.3


@pytest.mark.slow
def test_a_band_that_no_k_brings_within_tolerance_is_named(caplog):
    """The 2-4 test system: its COM is 6 % below the MTC in modes 1-2 whatever K (rigid bars
    and a membrane attached at its corners only: docs/validation/errata.md); the choice keeps
    the smallest K whose band no longer changes and the warning names the modes."""
    s = load_system(SYSTEMS / "square-2-4.toml")
    with caplog.at_level(logging.WARNING, logger="tmfem.models.com.mode_count"):
        c = mode_count.choose_membrane_modes(s, model_class=ControlOrientedModel)
    assert c.K == mode_count.K_MIN and 1 in c.disagreeing_modes and 2 in c.disagreeing_modes
    assert "modes [1, 2" in caplog.text and "any K up to 16" in caplog.text
    assert "still differ" in c.text


def test_the_file_decides_when_it_declares_k(kapton):
    """`[models.com] membrane_modes` wins: no search (source "file"), the model records it."""
    s = load_preset("1-4")
    assert mode_count.membrane_mode_choice(s, model_class=ControlOrientedModel).source == "file"
    assert default_membrane_modes(s) == 5
    import dataclasses
    declared = dataclasses.replace(kapton, model_defaults={"com": {"membrane_modes": 6}})
    m = ControlOrientedModel(declared, output_points=[])
    assert m.K == 6 and m.membrane_mode_choice.source == "file"
    assert ControlOrientedModel(declared, membrane_modes=3, output_points=[]).membrane_mode_choice.source == "given"


@pytest.mark.parametrize("name", list_presets())
def test_every_preset_declares_its_k(name):
    """The presets keep the dissertation's K (6.4, 7.4: 5 for 1-4 and 1-6(D), 4 for 2-3, 3 for
    1-4(D)) whatever the automatic choice would give."""
    K = load_preset(name).model_defaults.get("com", {}).get("membrane_modes")
    assert K == {"1-4": 5, "1-4D": 3, "1-4D-initial": 3, "1-6D": 5, "1-6D-initial": 5}.get(name, 4)


def test_an_unstable_mode_never_agrees_and_the_json_has_no_nan():
    """A negative (unstable) frequency on either side counts as disagreeing; to_dict gives None
    for its difference, so the commands' JSON stays valid (allow_nan=False)."""
    import json
    rel = mode_count._relative([-0.1, 0.5], [0.2, 0.5])
    assert np.isinf(rel[0]) and rel[1] == 0
    c = mode_count.MembraneModeChoice(K=3, source="automatic", reference="MTC", band_modes=2,
                                      relative_difference=rel.tolist(), disagreeing_modes=[1],
                                      max_difference_by_K={3: float(np.inf)})
    d = c.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["relative_difference"][0] is None and "modes [1]" in mode_count.MembraneModeChoice(**d).text

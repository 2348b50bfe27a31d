"""The automatic membrane-mode count K kept on disk (tmfem.models.com.mode_count with
tmfem.cache): a new process reads it instead of running the finite-element model again.

References: the choice computed in this test (a read must return it unchanged), and a
finite-element band function that raises (a read must not call it).
"""
import dataclasses
import logging
from pathlib import Path

import pytest

from tmfem.models.com import mode_count
from tmfem.models.com.model import ControlOrientedModel
from tmfem.system import load_system
from tmfem.system.materials import TendonSection

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


class FEModelRun(Exception):
    """Raised by the finite-element band function when a test forbids it."""


def _forbid_fe(*args, **kwargs):
    raise FEModelRun


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """An empty cache directory and an empty in-process table (a new process)."""
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    return tmp_path


def _choice(system):
    return mode_count.membrane_mode_choice(system, model_class=ControlOrientedModel)


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """A cache directory holding the triangle's choice, computed once for the module."""
    d = tmp_path_factory.mktemp("stored-cache")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("TMFEM_CACHE_DIR", str(d))
        mp.setattr(mode_count, "_CHOICES", {})
        return d, _choice(load_system(SYSTEMS / "triangle-1-3.toml"))


@pytest.fixture
def with_entry(stored, fresh):
    """``fresh`` with a copy of the stored entry (a process after the one that computed it)."""
    import shutil
    shutil.copytree(stored[0], fresh, dirs_exist_ok=True)
    return fresh, stored[1]


def test_a_new_process_reads_the_choice_from_disk_without_the_fe_model(fresh, monkeypatch):
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    first = _choice(s)
    assert first.source == "automatic" and not first.cached and "cached" not in first.text
    assert len(list((fresh / "membrane-modes").glob("*.json"))) == 1
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    monkeypatch.setattr(mode_count, "_fe_band", _forbid_fe)
    second = _choice(s)
    assert second.cached and second.text.endswith(", cached)")
    assert {**second.to_dict(), "cached": False} == first.to_dict()
    assert ControlOrientedModel(s, output_points=[]).K == first.K


def test_another_tendon_diameter_is_another_entry(with_entry, monkeypatch):
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    monkeypatch.setattr(mode_count, "_fe_band", _forbid_fe)
    assert _choice(s).cached
    sections = {k: dataclasses.replace(v, d=1.2 * v.d) for k, v in s.tendon_sections.items()}
    assert all(isinstance(v, TendonSection) for v in sections.values())
    with pytest.raises(FEModelRun):
        _choice(dataclasses.replace(s, tendon_sections=sections))


def test_a_changed_constant_of_the_search_is_another_entry(with_entry, monkeypatch):
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    monkeypatch.setattr(mode_count, "_fe_band", _forbid_fe)
    assert _choice(s).cached
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    monkeypatch.setattr(mode_count, "TOLERANCE", 0.04)
    with pytest.raises(FEModelRun):
        _choice(s)


@pytest.mark.parametrize("text", ["{truncated", '{"key": 1}'])
def test_a_corrupt_entry_is_recomputed_and_replaced(with_entry, monkeypatch, caplog, text):
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    fresh, first = with_entry
    (entry,) = (fresh / "membrane-modes").glob("*.json")
    entry.write_text(text)
    with caplog.at_level(logging.INFO, logger="tmfem.cache"):
        again = _choice(s)
    assert "recomputing" in caplog.text
    # recomputed: the same choice, the frequencies equal to the iterative eigensolver's round-off
    assert not again.cached and again.K == first.K
    assert again.reference_hz == pytest.approx(first.reference_hz, rel=1e-8)
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    assert _choice(s).cached                                        # the entry was written again


def test_an_entry_that_is_not_a_choice_is_recomputed(fresh, monkeypatch, caplog):
    """Valid JSON under the right key but not a choice (an unknown field): logged, recomputed."""
    s = load_system(SYSTEMS / "triangle-1-3.toml")
    key = mode_count._cache_key(mode_count._fingerprint(s))
    mode_count._STORE.put(key, {"K": 4, "source": "automatic", "colour": "red"})
    with caplog.at_level(logging.INFO, logger="tmfem.models.com.mode_count"):
        c = _choice(s)
    assert not c.cached and "is not one" in caplog.text


def test_an_unwritable_cache_still_gives_the_choice(monkeypatch, tmp_path, caplog):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(blocker))
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    with caplog.at_level(logging.WARNING, logger="tmfem.cache"):
        c = _choice(load_system(SYSTEMS / "triangle-1-3.toml"))
    assert c.source == "automatic" and not c.cached and "not writable" in caplog.text


@pytest.mark.slow
def test_a_cached_choice_repeats_its_warning(fresh, monkeypatch, caplog):
    """The 2-4 test system's band disagrees whatever K (test_mode_count): the warning naming
    the modes comes also when the choice is read from disk."""
    s = load_system(SYSTEMS / "square-2-4.toml")
    first = _choice(s)
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    monkeypatch.setattr(mode_count, "_fe_band", _forbid_fe)
    with caplog.at_level(logging.WARNING, logger="tmfem.models.com.mode_count"):
        second = _choice(s)
    assert second.cached and second.disagreeing_modes == first.disagreeing_modes
    assert f"modes {first.disagreeing_modes}" in caplog.text and "any K up to 16" in caplog.text

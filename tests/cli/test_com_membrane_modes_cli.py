"""The COM's membrane-mode count K as the commands print it and write it to their JSON.

Reference: tmfem.models.com.mode_count.choose_membrane_modes on the same file (the library
function the commands call), and the preset's [models.com] table.
"""
import json
from pathlib import Path

from tmfem.cli import main
from tmfem.models.com.mode_count import choose_membrane_modes
from tmfem.models.com.model import ControlOrientedModel
from tmfem.system import load_system

SYSTEMS = Path(__file__).resolve().parents[1] / "data" / "systems"
TRIANGLE = str(SYSTEMS / "triangle-1-3.toml")


def test_modal_com_of_a_file_without_k_prints_the_chosen_k(capsys):
    """No [models.com]: K is the automatic choice (the 1-3: its 12 lowest frequencies need
    n_q + K >= 12), in the JSON with where it came from and in the text output."""
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "12", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    c = choose_membrane_modes(load_system(TRIANGLE), model_class=ControlOrientedModel)
    assert r["membrane_modes"] == c.K and r["membrane_mode_choice"]["source"] == "automatic"
    assert r["membrane_mode_choice"]["reference"] == "MTC" and len(r["freq_hz"]) == 12
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "4"]) == 0
    assert f"K = {c.K} membrane modes (chosen: the COM's 12 lowest" in capsys.readouterr().out


def test_the_option_and_the_preset_say_where_k_comes_from(capsys):
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "4", "--membrane-modes", "5", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["membrane_modes"] == 5 and r["membrane_mode_choice"]["source"] == "given"
    assert main(["modal", "--preset", "2-3", "--model", "com", "--modes", "4", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["membrane_modes"] == 4 and r["membrane_mode_choice"]["source"] == "file"


def test_a_second_run_says_the_choice_came_from_the_cache(capsys, monkeypatch, tmp_path):
    """A new process (empty in-process table) with the first run's cache directory reads K from
    disk and says so; the JSON records it."""
    from tmfem.models.com import mode_count
    monkeypatch.setenv("TMFEM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "4"]) == 0
    first = capsys.readouterr().out
    assert "tolerance 5 %)" in first and "cached" not in first
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "4", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["membrane_mode_choice"]["cached"] is True
    monkeypatch.setattr(mode_count, "_CHOICES", {})
    assert main(["modal", TRIANGLE, "--model", "com", "--modes", "4"]) == 0
    assert "tolerance 5 %, cached)" in capsys.readouterr().out

"""`[deployment] tension_floor`: the fraction f of its path elongation L_d - u_d that each
tendon of an over-actuated system keeps in the PFL's inversion (upper rest-length limit
|tendon| - f (L_d - u_d), tmfem.control.deployment.adaptive; default 0.5). Read from the
file, refused outside [0, 1) and on a system with a square B_q (eq. 5.46), and it changes the
run of the 3-3 of tests/data/systems/tower-3-3.toml."""
import json
import re
from pathlib import Path

import pytest

from tmfem.cli import main
from tmfem.errors import InputError
from tmfem.system import load_system

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


def with_floor(tmp_path, name: str, line: str) -> Path:
    text = (SYSTEMS / name).read_text()
    text = re.sub(r"^\[deployment\]$", "[deployment]\n" + line, text, count=1, flags=re.M)
    f = tmp_path / name
    f.write_text(text)
    return f


def test_the_floor_is_read_from_the_file_with_its_default(tmp_path):
    from tmfem.system.problem import TENSION_FLOOR
    assert load_system(SYSTEMS / "tower-3-3.toml").problem.deployment.floor == TENSION_FLOOR == 0.5
    p = load_system(with_floor(tmp_path, "tower-3-3.toml", "tension_floor = 0.25")).problem.deployment
    assert p.tension_floor == p.floor == 0.25


@pytest.mark.parametrize("value", ["1.0", "-0.1", "1.5", "true", '"half"', "nan"])
def test_a_floor_outside_zero_to_one_is_refused(tmp_path, value):
    with pytest.raises(InputError, match=re.escape("expected 'tension_floor' to be a number in [0, 1)")):
        load_system(with_floor(tmp_path, "tower-3-3.toml", f"tension_floor = {value}"))


def test_a_floor_on_a_square_system_is_refused(tmp_path, capsys):
    # the 1-5(D): 10 tendons for 10 bar coordinates, no spare tendon to keep a floor with
    f = with_floor(tmp_path, "pentagon-1-5D.toml", "tension_floor = 0.5")
    assert main(["deploy", str(f)]) == 2
    err = capsys.readouterr().err
    assert "tension_floor applies to an over-actuated system" in err and "10 tendons for 10" in err


def test_the_pfl_refuses_a_floor_outside_zero_to_one():
    from tmfem.control.deployment.adaptive import AdaptivePFL
    with pytest.raises(InputError, match=re.escape("tension_floor: expected a number in [0, 1)")):
        AdaptivePFL(model=None, reference=None, gains=None, rbf=None, w_bar=1.0, tension_floor=1.0)


@pytest.mark.slow
def test_the_floor_changes_the_run(tmp_path, capsys):
    # the first 2.4 s of the 3-3's PFL deployment (no switch): without a floor (f = 0, the
    # limits of 7.4) the solution closest to u_d lets tendons reach their tendon lengths
    # (margin 0, no tension); with the default f = 0.5 every tendon keeps a margin
    runs = {}
    for f in ("0.0", "0.5"):
        path = with_floor(tmp_path, "tower-3-3.toml", f"tension_floor = {f}")
        assert main(["deploy", str(path), "--controller", "adaptive", "--t-end", "2.4", "--dt", "0.02",
                     "--json"]) == 0
        runs[f] = json.loads(capsys.readouterr().out)
    assert runs["0.0"]["min_rest_length_margin_m"] == pytest.approx(0.0, abs=1e-9)
    assert runs["0.5"]["min_rest_length_margin_m"] > 1e-4
    assert runs["0.0"]["failure"] is None and runs["0.5"]["failure"] is None

"""``tmfem optimize`` on a system file with a [design] table: the optimum is written back as a
system file that ``tmfem equilibrium`` (every ch. 3 check passes), ``static`` and ``modal``
take, and their results agree with the optimiser's (tendon stress at its bound, the same
first frequency)."""
import json

import pytest
import tomli_w

from tmfem.cli import main
from tmfem.system import load_preset
from tmfem.system.spec import system_to_dict

LIMIT = 6.32e7


def run(argv, capsys):
    rc = main(argv + ["--json"])
    out = capsys.readouterr().out
    return rc, json.loads(out) if out.strip() else None


def design_file(tmp_path, design):
    d = system_to_dict(load_preset("1-4"))
    d["design"] = design
    path = tmp_path / "design-1-4.toml"
    path.write_bytes(tomli_w.dumps(d).encode())
    return path


def test_optimum_written_back_is_taken_by_static_and_modal(tmp_path, capsys):
    path = design_file(tmp_path, {"variables": {"S1": [1.40, 1.52]}, "objective": "max:freq",
                                  "constraints": [f"tendon_stress<={LIMIT}"], "aperture": 0.5})
    rc, r = run(["optimize", str(path), "--mesh", "4", "--out", str(tmp_path / "out")], capsys)
    assert rc == 0 and r["ok"]
    assert r["optimum_responses"]["tendon_stress"] == pytest.approx([LIMIT] * 4, rel=1e-5)
    assert r["units"]["optimum"] == "m" and r["units"]["optimum_responses"] == {"freq": "Hz", "tendon_stress": "Pa"}
    for name in ("history.csv", "history.png", "optimal.toml"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    lines = (tmp_path / "out" / "history.csv").read_text().splitlines()
    assert lines[0] == "iteration,objective,max_violation,step" and len(lines) == len(r["history"]) + 1
    opt = str(tmp_path / "out" / "optimal.toml")
    rc, st = run(["static", opt, "--mesh", "4"], capsys)
    assert rc == 0 and all(c["ok"] for c in st["checks"])
    assert st["tendon_stress_max"] == pytest.approx(LIMIT, rel=1e-5)
    rc, eq = run(["equilibrium", opt], capsys)                   # every check of ch. 3
    assert rc == 0 and eq["ok"] and all(c["ok"] for c in eq["checks"])
    rc, mo = run(["modal", opt, "--mesh", "4", "--modes", "4"], capsys)
    assert rc == 0
    assert mo["freq_hz"][0] == pytest.approx(r["optimum_responses"]["freq"][0], rel=1e-6)


def test_sbc_optimum_is_taken_by_static_on_the_sbc_model(tmp_path, capsys):
    path = design_file(tmp_path, {"variables": {"S1": [1.40, 1.52]}})
    rc, r = run(["optimize", str(path), "--model", "sbc", "--mesh", "4", "--objective", "max:freq",
                 "--constraint", f"tendon_stress<={LIMIT}", "--out", str(tmp_path / "sbc")], capsys)
    assert rc == 0 and r["ok"] and r["optimum_responses"]["freq"][0] > 1.25 * r["start_responses"]["freq"][0]
    rc, st = run(["static", str(tmp_path / "sbc" / "optimal.toml"), "--model", "sbc", "--mesh", "4"], capsys)
    assert rc == 0 and st["tendon_stress_max"] == pytest.approx(LIMIT, rel=1e-5)


def test_options_that_do_not_apply_are_refused(tmp_path, capsys):
    path = design_file(tmp_path, {"variables": {"S1": [1.40, 1.52]}})
    for argv, text in ((["--objective", "max:freq", "--variable", "sigma_1=0:1"], "only the angles"),
                       ([], "expected --objective"),
                       (["--objective", "max:freq", "--variable", "theta_11=50:70"], "a stage 1..1"),
                       (["--objective", "max:freq", "--variable", "S1=1.4"], "NAME=LOWER:UPPER")):
        rc = main(["optimize", str(path), "--mesh", "2"] + argv)
        assert rc == 2 and text in capsys.readouterr().err
    bad = design_file(tmp_path, {"variables": {"S1": [1.5, 1.4]}})
    rc = main(["optimize", str(bad), "--objective", "max:freq"])
    assert rc == 2 and "lower < upper" in capsys.readouterr().err


def test_a_constraint_the_optimum_cannot_meet_is_named_and_exits_1(tmp_path, capsys):
    """mass <= 1 kg on the 1-4 (44.7 kg) with the rest lengths as the only variables (they do not
    change the mass): the returned design violates it, the result names it (with the violation
    scaled by the bound, (mass - 1 kg) / 1 kg) and only it (not the rows of the bound
    formulation of max:freq), and the run exits 1 with it."""
    path = design_file(tmp_path, {"variables": {"S1": [1.40, 1.52]}, "objective": "max:freq",
                                  "constraints": ["mass<=1"]})
    rc, r = run(["optimize", str(path), "--mesh", "4", "--max-iter", "3"], capsys)
    assert rc == 1 and not r["ok"]
    (v,) = r["violated"]
    assert v["constraint"] == "mass<=1" and v["violation"] == pytest.approx(r["optimum_responses"]["mass"] - 1.0)
    assert "mass<=1 violated" in r["failed_checks"]
    assert main(["optimize", str(path), "--mesh", "4", "--max-iter", "3"]) == 1
    out = capsys.readouterr().out
    assert "VIOLATED at the returned design" in out and "mass [kg]" in out


def test_no_wrinkling_over_a_point_held_membrane_says_why_and_names_the_aperture(capsys):
    """`membrane_min_principal>=0` without an aperture on the 1-4 (corners held by points): the
    start design is already in compression (minor principal stress < 0, docs/guides/design.md:
    -57 kPa at mesh 10), the constraint stays violated, and the output says why in one line
    and names the aperture; with `--aperture 0.8` (taut there, +3.4 kPa at mesh 10) no such hint."""
    argv = ["optimize", "--preset", "1-4", "--objective", "max:freq", "--constraint",
            "membrane_min_principal>=0", "--variable", "S1=1.40:1.52", "--mesh", "4", "--max-iter", "5"]
    rc, r = run(argv, capsys)
    assert rc == 1 and r["start_responses"]["membrane_min_principal"] < 0
    (v,) = r["violated"]
    assert v["constraint"].startswith("membrane_min_principal>=0")
    assert "held at its corners by points" in v["hint"] and "--aperture" in v["hint"]
    assert main(argv + ["--quiet"]) == 1
    hints = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("hint:")]
    assert len(hints) == 1 and "compression near its corners" in hints[0] and "[design] aperture" in hints[0]
    rc, r = run(argv + ["--aperture", "0.8"], capsys)
    assert all("hint" not in v for v in r["violated"])

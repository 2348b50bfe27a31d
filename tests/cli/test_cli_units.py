"""Units in every output: JSON documents carry a ``units`` table, run-history CSV headers
carry ``[unit]`` (tmfem.io.units, tmfem.io.run.column_header)."""
import json

import pytest

from tmfem.cli import main
from tmfem.io.units import unit_of
from tmfem.io.run import column_header


def test_json_documents_state_their_units(capsys):
    assert main(["equilibrium", "--preset", "1-4", "--mesh", "4", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    u = d["units"]
    assert u["F_Delta"] == "N" and u["Delta"] == "m" and u["membrane_max_von_mises"] == "Pa"
    assert u["nodes"] == "m" and u["force_density"] == "N/m"      # eq. 3.30: T / L
    # every top-level number of the document has a unit (or is a count/flag)
    numeric = [k for k, v in d.items() if isinstance(v, float)]
    assert numeric and all(k in u for k in numeric), [k for k in numeric if k not in u]


def test_unit_rules():
    assert unit_of("theta_deg") == "deg" and unit_of("wall_time_s") == "s"
    assert unit_of("tendon_stress_max_MPa") == "MPa" and unit_of("freq_hz") == "Hz"
    assert unit_of("system") is None
    assert column_header("t") == "t [s]" and column_header("theta_11_dot") == "theta_11_dot [rad/s]"
    assert column_header("B_1,12_z") == "B_1,12_z [m]"
    # mass-normalised membrane modes (phi^T M phi = 1, docs/guides/com.md): eta = w / phi in kg^0.5 m
    assert column_header("eta_1") == "eta_1 [kg^0.5 m]" and column_header("eta_2_dot") == "eta_2_dot [kg^0.5 m/s]"


def _unitless_numbers(doc, inherited=False, path=""):
    """Paths of float values (or float lists) in ``doc`` whose key has no unit; a value under
    a key with a unit inherits it (e.g. rest_lengths: {tendon: value})."""
    bad = []
    if isinstance(doc, dict):
        for k, v in doc.items():
            has = inherited or unit_of(str(k)) is not None
            is_num = isinstance(v, float) or (isinstance(v, list) and v and all(isinstance(x, float) for x in v))
            if is_num and not has:
                bad.append(f"{path}/{k}")
            bad += _unitless_numbers(v, has, f"{path}/{k}")
    elif isinstance(doc, list):
        for v in doc[:3]:
            bad += _unitless_numbers(v, inherited, path + "[]")
    return bad



@pytest.mark.parametrize("argv", [
    ["static", "--preset", "1-4", "--mesh", "3"],
    ["modal", "--preset", "1-4", "--mesh", "3", "--modes", "2"],
    ["modal", "--model", "sbc", "--preset", "1-4", "--mesh", "3", "--modes", "2"],
    ["converge", "--preset", "1-4", "--mesh", "3", "--modes", "2"],
    ["vibrate", "--preset", "1-4", "--t-end", "0.03"],
    ["vibrate", "--model", "mtc", "--preset", "1-4", "--mesh", "3", "--t-end", "0.03"],
    ["deploy", "--preset", "1-4D", "--t-end", "0.03", "--controller", "adaptive-lqr"],
    ["control", "pbh", "--preset", "1-4D"],
    ["equilibrium", "--preset", "1-4", "--mesh", "3"],
])
def test_every_number_of_every_command_has_a_unit(argv, capsys):
    assert main(argv + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert _unitless_numbers({k: v for k, v in d.items() if k != "units"}) == []


def test_csv_headers_carry_units(tmp_path, capsys):
    import csv
    c = tmp_path / "c.csv"
    assert main(["converge", "--preset", "1-4", "--mesh", "3", "--modes", "2", "--csv", str(c)]) == 0
    head = next(csv.reader(open(c)))
    assert {"h [m]", "f1 [Hz]", "Delta_mm [mm]"} <= set(head) and open(c, newline="").read().count("\r") == 0
    v = tmp_path / "v.csv"
    assert main(["vibrate", "--preset", "1-4", "--t-end", "0.03", "--csv", str(v)]) == 0
    head = next(csv.reader(open(v)))
    # every column of the COM history has a unit, the membrane coordinates included
    assert all(h.endswith("]") for h in head) and "eta_1 [kg^0.5 m]" in head
    capsys.readouterr()


_UNIT = r"\S+ \[[^\]]+\]"


@pytest.mark.parametrize("argv", [
    ["--preset", "2-3-deploy", "--controller", "adaptive", "--t-end", "0.03"],
    ["--preset", "1-4D", "--controller", "adaptive-lqr", "--t-end", "0.03"],
])
def test_every_column_of_the_7_4_deployment_csv_has_a_unit(argv, tmp_path, capsys):
    # docs/guides/fe-plant.md, docs/guides/output.md: "units in the header"; the references q_d (eq. 5.68)
    # carry their signals' units (x_21_ref was bare), the controller label "-"
    import csv
    import re
    c = tmp_path / "d.csv"
    assert main(["deploy", *argv, "--csv", str(c)]) == 0
    capsys.readouterr()
    head = next(csv.reader(open(c)))
    assert [h for h in head if not re.fullmatch(_UNIT, h)] == []
    assert head[-1] == "controller [-]" and "theta_11_ref [rad]" in head
    if argv[1] == "2-3-deploy":
        assert {"x_21_ref [m]", "z_23_ref [m]", "x_21 [m]", "r_P_21 [m]", "L_S_11 [m]"} <= set(head)

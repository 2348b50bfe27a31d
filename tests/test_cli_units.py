"""Units in every output: JSON documents carry a ``units`` table, run-history CSV headers
carry ``[unit]`` (tmfem.cli.units, tmfem.io.run.column_header)."""
import json

from tmfem.cli import main
from tmfem.cli.units import unit_of
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
    # mass-normalised membrane modes (phi^T M phi = 1, docs/com.md): eta = w / phi in kg^0.5 m
    assert column_header("eta_1") == "eta_1 [kg^0.5 m]" and column_header("eta_2_dot") == "eta_2_dot [kg^0.5 m/s]"

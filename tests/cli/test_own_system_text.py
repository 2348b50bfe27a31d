"""Text outputs for a system of one's own: `tmfem report`'s deployment without a switch before
its end and the COM's disagreement with the FE model when K was chosen automatically (more
membrane modes do not help then) or declared in the file (they may); `tmfem modal --model com`'s
column name."""
import numpy as np

from tmfem.cli.report import format_text
from tmfem.reference.report import com_disagreement


def _result(**deployment):
    d = {"system": "mine", "controller": "adaptive-hinf", "uncertainty": "exact",
         "switch_time_s": None, "max_membrane_deflection_m": 7.8e-4, "final_tracking_error": 0.047}
    d.update(deployment)
    return {"system": "mine", "frequencies_hz": {"SBC designed": [3.5], "COM designed": [6.4]},
            "modes": 1, "statics": {"designed": {"tendon_stress_max_MPa": 30.0, "bar_load_max_N": 15.4,
                                                 "membrane_max_von_mises_MPa": 5.4}},
            "failed_checks": [], "out": "out/mine", "files": ["index.md"], "fe_model": "SBC",
            "deployment": d}


def test_a_deployment_without_a_switch_says_so_and_a_switch_time_has_its_unit():
    text = format_text(_result())
    assert "no switch before t_end" in text and "None" not in text
    assert "switch at 12.35 s" in format_text(_result(switch_time_s=12.3456))


def test_the_hint_of_the_com_disagreement_follows_where_K_came_from():
    """A 1-5(D) in CFRP, Dyneema and Kapton: the SBC model's beam bars bend at H_1j and keep 27 %
    of the design's Delta, the rigid-bar COM stays 75-100 % above it whatever K (the automatic
    choice took K = 8 after K = 7 ... 16 all left 95.7 %): 'more modes bring them closer' was
    wrong advice there, and the file said nothing of `[models.com]`."""
    freqs = {"SBC designed": np.array([3.50, 4.70, 5.27]), "COM designed": np.array([6.41, 7.78, 9.50])}
    auto = com_disagreement(freqs, "SBC", 8, declared=False)["message"]
    assert auto.startswith("COM frequencies of modes [1, 2, 3] differ from the SBC model's")
    assert "the automatic choice: more modes do not bring them closer" in auto
    assert "[models.com]" not in auto and "more modes bring" not in auto
    declared = com_disagreement(freqs, "SBC", 4)["message"]
    assert "[models.com] membrane_modes in the system file): more modes bring" in declared


def test_the_com_modal_table_names_its_column_by_the_model():
    """`tmfem modal --model com` on a file without printed values: the column is 'COM [Hz]'
    (the SBC and MTC tables name theirs so), not 'ours'."""
    from tmfem.post.com import format_modal
    r = {"system": "octagon", "sizes": {"n_z": 20, "n_q": 16}, "membrane_modes": 4,
         "prestress_scale": 1.0, "freq_hz": [0.3159, 1.5050]}
    text = format_modal(r)
    assert "mode   COM [Hz]" in text and "ours" not in text
    assert "   1     0.3159" in text


def _static(rest_lengths):
    return {"tendon_stress_max": 3.0e7, "bar_load_max": 15.4, "membrane_max_sigma_p1": 6.1e6,
            "membrane_max_von_mises": 5.4e6, "Delta": [5.3e-4] * 5, "rest_lengths": rest_lengths,
            "tendon_slack": []}


def test_the_report_statics_row_names_the_tendon_it_shows():
    """The statics table of `tmfem report` shows one tendon's rest length: it was labelled
    'rest length S_11' whatever the system, so a 1-N(D) system's SL_1 (0.44748 m) stood under
    the saddle tendon's name. The label is the tendon's own, and a preset keeps its printed
    value beside S_11 (1-4: S1 = 1.529 m, Table 6.3)."""
    from tmfem.reference.report import _statics_rows
    from tmfem.system import load_preset, load_system
    mine = load_system("tests/data/systems/pentagon-1-5D.toml")
    rows = _statics_rows(mine, {"designed": _static({"SL_1": 0.44748, "SU_1": 2.03858})})
    assert rows[-1] == ["rest length SL_1", "m", 0.44748]
    preset = load_preset("1-4")
    rows = _statics_rows(preset, {"designed": _static({"S_11": 1.5025, "S_12": 1.5025})})
    assert rows[-1][:4] == ["rest length S_11", "m", 1.529, 1.5025]


def test_a_deployment_beyond_its_strength_fails_the_report():
    """A two-stage 2-6 of titanium, aramid and PEN deployed from 73 deg: its run left the tendons
    at 24 GPa (yield 2.8 GPa), the bars at 2.3 x their Euler load and the membrane at 2.5 GPa;
    `tmfem deploy` exits 1 on these checks, and the report said 'checks passed' with exit 0.
    The report's failed checks carry the deployment's, as `deploy` names them."""
    from tmfem.reference.report import deployment_failures
    strength = ["tendon yield: D_24 at 2.396e+04 MPa (t = 0.36 s) above its yield stress 2800 MPa",
                "bar buckling: compression 2.494e+04 N (t = 0.2 s) above the Euler load 1.079e+04 N (eq. 5.31)"]
    assert deployment_failures({"failure": None, "strength_checks_failed": strength}) == [
        "deployment: " + c for c in strength]
    assert deployment_failures({"failure": "Newton diverged at t = 1.2 s", "strength_checks_failed": []}) == [
        "deployment: diverged (Newton diverged at t = 1.2 s)"]
    assert deployment_failures({"not_run": "slack tendon"}) == ["deployment not run"]
    assert deployment_failures({"failure": None, "strength_checks_failed": []}) == []
    assert deployment_failures(None) == []
    text = format_text({**_result(), "failed_checks": ["deployment: " + strength[0]]})
    assert text.startswith("report of mine: checks FAILED: deployment: tendon yield: D_24")

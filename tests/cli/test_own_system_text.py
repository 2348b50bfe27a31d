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

"""The text summary of `tmfem deploy`: entries that are null in the JSON (no switch before
t_end, no failure) are said in words, never as Python's `None`."""
from tmfem.cli.deploy import format_text


def _result(**over):
    r = {"system": "mine", "plant": "com", "controller": "adaptive-hinf", "uncertainty": "no-MG",
         "switch_time_s": None, "t_end_s": 3.0, "max_membrane_deflection_m": 0.002,
         "peak_bar_compression_N": 20.0, "bar_critical_load_N": 4650.0, "max_von_mises_Pa": 3e7,
         "max_tendon_stress_Pa": 1e8, "min_rest_length_margin_m": 0.01, "final_tracking_error": 0.1,
         "limits_active_s": 0.0, "max_eta_energy_J": 1e-3, "B_q_condition_max": 12.0,
         "wall_time_s": 4.2, "failure": None}
    r.update(over)
    return r


def test_null_entries_are_words_and_numbers_keep_six_digits():
    text = format_text(_result())
    assert "None" not in text
    assert "  switch_time_s: none (the switch condition was not met before t_end)" in text
    assert "  failure: none" in text
    assert "  bar_critical_load_N: 4650" in text and "  max_von_mises_Pa: 3e+07" in text


def test_a_switch_time_and_a_failure_are_printed_as_they_are():
    text = format_text(_result(switch_time_s=12.3456789, failure="slack tendon SL_2 at t = 3.1 s"))
    assert "  switch_time_s: 12.3457" in text
    assert "  failure: slack tendon SL_2 at t = 3.1 s" in text


def test_a_run_that_never_switches_with_saturated_rest_lengths_says_why():
    # a user 1-5(D) in CFRP/Dyneema/Kapton with omega_r = 0.5 rad/s: the rest lengths at their
    # limits for 19.1 of 20 s and no switch; the hint names the reference's speed
    from tmfem.cli.deploy import saturation_warning
    hint = saturation_warning(_result(t_end_s=20.0, limits_active_s=19.1), omega_r=0.5)
    assert "19.1 of 20 s" in hint and "omega_r = 0.5 rad/s" in hint and "[deployment] omega_r" in hint
    # no hint: a switch, a short saturation, or the adaptive controller (no switch by design)
    assert saturation_warning(_result(t_end_s=20.0, limits_active_s=19.1, switch_time_s=15.0), omega_r=0.5) is None
    assert saturation_warning(_result(t_end_s=20.0, limits_active_s=9.9), omega_r=0.5) is None
    assert saturation_warning(_result(t_end_s=20.0, limits_active_s=19.1, controller="adaptive"),
                              omega_r=0.5) is None

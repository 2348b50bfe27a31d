"""The tables of a system file beyond the structure ([packaged], [control], [deployment],
[report]): read, checked, written back."""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.system import dump_system, load_preset, load_system, system_from_dict
from tmfem.system.presets import preset_dict


@pytest.mark.parametrize("preset", ["1-4D", "1-6D", "2-3-deploy"])
def test_packaged_table_is_the_printed_initial_configuration(preset):
    """The [packaged] table of a deployed preset gives the initial configuration of Tables
    7.3, 7.5, 7.7 exactly as the separate preset '<name>-initial' does."""
    s, i = load_preset(preset).problem.packaged, load_preset(preset + "-initial")
    assert np.array_equal(s.q, i.q) and np.array_equal(s.rest_lengths, i.rest_lengths)


def test_a_file_round_trips_with_its_tables(tmp_path):
    s = load_preset("1-4D")
    dump_system(s, tmp_path / "s.toml")
    t = load_system(tmp_path / "s.toml")
    assert t.problem.control == s.problem.control and t.problem.deployment == s.problem.deployment
    assert np.array_equal(t.problem.packaged.q, s.problem.packaged.q)


@pytest.mark.parametrize("table, message", [
    ({"control": {"alpha": -1.0}}, "'alpha' to be a finite number > 0"),
    ({"control": {"gamma": 1.0}}, "unknown keys ['gamma']"),
    ({"deployment": {"gains": [1.0, 2.0]}}, "Table 7.1"),
    ({"deployment": {"xi_r": 0.7}}, "xi_r = 1"),
    ({"deployment": {"uncertainty": "some"}}, "'uncertainty' to be one of"),
    ({"report": {"deployment": {"t_end": 3.0}}}, "expected 'system'"),
])
def test_bad_tables_are_refused_with_one_line(table, message):
    d = {**preset_dict("1-4D"), **table}
    with pytest.raises(InputError, match=None) as e:
        system_from_dict(d)
    assert message in str(e.value)

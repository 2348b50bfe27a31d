"""`tmfem lpv`: input refusals (the synthesis itself: tests/test_lpv.py)."""
import pytest

from tmfem.cli import main


@pytest.mark.parametrize("argv, msg", [
    (["lpv", "--grid", "7x3"], "at most 6x3"),
    (["lpv", "--grid", "six"], "expected AxB"),
    (["lpv", "--refine", "2"], "expected >= 4"),
    (["lpv", "--preset", "2-3", "--grid", "1x1"], "printed LPV grid"),
])
def test_lpv_cli_refuses_bad_input(argv, msg, capsys):
    assert main(argv) == 2
    assert msg in capsys.readouterr().err

"""The ``vibrate`` plot title names the model's size in words ("K = 2 membrane modes
(given)"), not the Python keys of ``describe()`` ("membrane_modes 2, membrane_modes_from
given"). Reference: the model's own ``describe()`` values."""
import json

import pytest

import tmfem.post.plots
from tmfem.cli import main


@pytest.mark.parametrize("model, want", [("com", "K = 2 membrane modes (given)"),
                                         ("mtc", "mesh 4 x 4, {ndof:,} DOFs, 3 elements per tendon")])
def test_vibrate_title_reads_as_text(tmp_path, capsys, monkeypatch, model, want):
    titles = []
    monkeypatch.setattr(tmfem.post.plots, "plot_free_vibration",
                        lambda res, path, *, title: titles.append(title) or str(path))
    opts = ["--membrane-modes", "2"] if model == "com" else ["--mesh", "4"]
    assert main(["vibrate", "--preset", "1-4", "--model", model, *opts, "--t-end", "0.02", "--dt", "0.01",
                 "--perturb", "theta_12_dot=0.01", "--plot", str(tmp_path / "v.png"), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert titles == [f"1-4 {model.upper()} free vibration, {want.format(**r)}"]
    assert "_" not in titles[0].split(", ", 1)[1]

"""``tmfem benchmark beam-cantilever-moment`` (dissertation 4.5.2, 5 four-node beams).

Sources: the elastica (benchmarks.json ``elastica_end_moment_closed_form``; its function is
checked against the 'exact' columns of Sze et al. 2004 in tests/fem/test_shell_benchmarks.py).
"""
import json

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.reference.beam_benchmarks import cantilever_end_moment
from tmfem.reference.benchmarks.shell_cantilever_moment import elastica

@pytest.mark.parametrize("integration", ["reduced", "full"])
def test_roll_up_follows_the_elastica_within_one_percent(integration):
    r = cantilever_end_moment(n_elements=5, n_steps=20, integration=integration)
    assert r.lam[-1] == pytest.approx(1.0) and len(r.iterations) == 20 and r.rejected == 0
    err = np.hypot(r.u_tip - r.u_elastica, r.w_tip - r.w_elastica)
    ref = np.hypot(r.u_elastica, r.w_elastica)
    assert np.max(err[1:] / ref[1:]) < 0.01
    # closes into a full circle: the tip back at the root, u = -L, w = 0
    assert abs(r.u_tip[-1] + 12.0) < 0.01 * 12.0 and abs(r.w_tip[-1]) < 1e-3
    assert max(r.iterations) <= 15


def test_cli_rows_and_plot(tmp_path, capsys):
    png = tmp_path / "roll.png"
    assert main(["benchmark", "beam-cantilever-moment", "--reduced", "--json", "--plot", str(png)]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["units"]["u_tip"] == "m" and r["load_steps"] == 10
    lam = np.array([row["lambda"] for row in r["rows"]])
    np.testing.assert_allclose(lam, np.linspace(0, 1, 11), atol=1e-12)
    u, w = elastica(lam, 12.0)
    assert np.allclose([row["u_tip"] for row in r["rows"]], u, atol=0.01 * 12.0)
    assert np.allclose([row["w_tip"] for row in r["rows"]], w, atol=0.01 * 12.0)
    assert all(row["newton_iterations"] > 0 for row in r["rows"][1:])
    assert png.stat().st_size > 10000

"""``tmfem control lpv --solver CLARABEL|SCS`` prints the conic solve's estimate before it and
refuses (exit 3) one over ``--time-budget``, naming the option; ``--time-budget`` is accepted
with these solvers. The system: a 2-5 of our own on two grid points
(tests/data/systems/pentagon-2-5-lpv.toml); the estimate itself is checked against its sizes in
tests/control/lpv/test_lpv_conic_estimate.py."""
import re

import pytest

from tmfem.cli import main
from tests.cli.test_own_system_design import SYSTEMS


@pytest.mark.slow
def test_a_conic_lpv_synthesis_over_its_time_budget_is_refused_with_the_estimate(capsys):
    rc = main(["control", "lpv", str(SYSTEMS / "pentagon-2-5-lpv.toml"), "--grid", "2x1", "--solver", "CLARABEL",
               "--time-budget", "1e-6"])
    err = capsys.readouterr().err
    assert rc == 3, err
    assert "estimate of the CLARABEL solve: 8 LMIs" in err          # logged before the solve
    m = re.search(r"LPV state-feedback synthesis \(CLARABEL\): (\d+) states, 2 grid points x 4 rate vertices: "
                  r"the SDP \(8 LMIs of order (\d+), .* exceeds .*the time limit 1e-06 CPU s \(time_budget, "
                  r"`tmfem control lpv --time-budget` raises it\)", err)
    assert m, err
    # the estimate is logged before the refusal, with the same numbers
    est = re.search(r"estimate of the CLARABEL solve: (.*)\n", err).group(1)
    assert err.index(est) < err.index("error:") and f"the SDP ({est})" in err

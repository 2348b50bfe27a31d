"""The reduced report directory shared by the report tests (test_report.py, test_report_html.py):
mesh 4, 0.2 s of vibration, 0.3 s of deployment under the LQR switch instead of the LMI
H-infinity design, no renders, to stay fast; the full run is `make demo`."""
import pytest

from tmfem.cli import main


@pytest.fixture(scope="session")
def report(tmp_path_factory):
    from tmfem.reference import report as rep
    out = tmp_path_factory.mktemp("report") / "1-4"
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(rep.REPORT_DEPLOYMENT, "1-4", {**rep.REPORT_DEPLOYMENT["1-4"], "t_end": 0.3,
                                                  "controller": "adaptive-lqr"})
        rc = main(["report", "--preset", "1-4", "--out", str(out), "--mesh", "4", "--t-end", "0.2",
                   "--modes", "6", "--no-render", "--json"])
    assert rc == 0
    return out

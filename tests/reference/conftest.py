"""The reduced report directory of `tmfem report` shared by tests/reference/test_report.py
and tests/reference/test_report_html.py (built once per test process)."""
import pytest

from tmfem.cli import main


@pytest.fixture(scope="session")
def report(tmp_path_factory):
    """The report of the 1-4 at mesh 4 (0.2 s of vibration, 0.3 s of deployment under the
    LQR switch instead of the LMI H-infinity design, no renders): its directory."""
    from tmfem.reference import report as rep
    out = tmp_path_factory.mktemp("report") / "1-4"
    with pytest.MonkeyPatch.context() as mp:
        own = rep.report_deployment
        mp.setattr(rep, "report_deployment",
                   lambda s: {**own(s), "t_end": 0.3, "controller": "adaptive-lqr"})
        rc = main(["report", "--preset", "1-4", "--out", str(out), "--mesh", "4", "--t-end", "0.2",
                   "--modes", "6", "--no-render", "--json"])
    assert rc == 0
    return out

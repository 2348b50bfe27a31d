"""The reduced report directory of `tmfem report` shared by tests/reference/test_report.py
and tests/reference/test_report_html.py.

It is built once per test run: under pytest-xdist the first worker that needs it builds it in
the base temp directory the workers share, holding a lock file, and the others wait for the
lock and read the same directory (the tests only read it)."""
import shutil

import pytest

from tests.shared import locked, shared_dir
from tmfem.cli import main


def _build(out):
    """The report of the 1-4 at mesh 4 (0.2 s of vibration, 0.3 s of deployment under the
    LQR switch instead of the LMI H-infinity design, no renders) into ``out``."""
    from tmfem.reference import report as rep
    with pytest.MonkeyPatch.context() as mp:
        own = rep.report_deployment
        mp.setattr(rep, "report_deployment",
                   lambda s: {**own(s), "t_end": 0.3, "controller": "adaptive-lqr"})
        rc = main(["report", "--preset", "1-4", "--out", str(out), "--mesh", "4", "--t-end", "0.2",
                   "--modes", "6", "--no-render", "--json"])
    assert rc == 0


@pytest.fixture(scope="session")
def report(tmp_path_factory):
    """The reduced report's directory (:func:`_build`), shared by the xdist workers of this run."""
    root = shared_dir(tmp_path_factory) / "report"
    root.mkdir(exist_ok=True)
    out, done = root / "1-4", root / "done"
    with locked(root / "lock"):
        if not done.exists():
            shutil.rmtree(out, ignore_errors=True)  # what a failed build of another worker left
            _build(out)
            done.touch()
    return out

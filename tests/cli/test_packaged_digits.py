"""``tmfem equilibrium FILE --packaged THETA --json`` prints psi with the digits of its scan
step, not the binary noise of the accumulated scan (37.34999999999282). Reference: the
library's own result (tmfem.control.deployment.packaged.packaged_configurations), whose psi
values lie on the scan grid -89 + k step_deg to within floating-point error."""
from tmfem.control.deployment.packaged import packaged_configurations
from tmfem.system import load_system
from tests.cli.test_own_system_design import SYSTEMS, run


def test_packaged_psi_is_printed_on_the_scan_grid(capsys):
    f = SYSTEMS / "pentagon-1-5D.toml"
    r, _ = run(["equilibrium", str(f), "--packaged", "87.6", "--json"], capsys)
    lib = packaged_configurations(load_system(f), theta_deg=87.6)
    step = r["step_deg"]
    assert step == lib["step_deg"] == 0.05
    printed = [r["psi_deg"]] + [v for band in r["psi_deg_bands"] for v in band]
    raw = [lib["psi_deg"]] + [v for band in lib["psi_deg_bands"] for v in band]
    for p, q in zip(printed, raw, strict=True):
        assert abs(p - q) < 1e-9                                  # the same value ...
        assert len(repr(p).split(".")[1]) <= 2                    # ... with the step's digits

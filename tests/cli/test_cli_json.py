"""--json output is strict JSON (RFC 8259: no NaN or Infinity tokens)."""
import json

from tmfem.cli import main


def _reject(token):
    raise AssertionError(f"non-standard JSON token {token}")


def test_infeasible_design_json_has_no_nan(capsys):
    # Table 6.4 as printed: tendons that would push have no rest length (eqs. 3.8-3.9);
    # the document must say so with null, not NaN
    rc = main(["equilibrium", "--preset", "2-3", "--as-printed", "--allow-infeasible",
               "--mesh", "3", "--json"])
    out = capsys.readouterr().out
    assert rc == 0
    doc = json.loads(out, parse_constant=_reject)
    assert doc["ok"] is False
    pushing = [t for t in doc["tendons"] if t["force"] < 0]
    assert pushing and all(t["rest_length"] is None for t in pushing)

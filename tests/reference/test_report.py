"""`tmfem report` (the main job, `make demo`): one directory whose index.md links every file.
Reduced here (mesh 4, 0.2 s of vibration, 0.3 s of deployment under the LQR switch instead of
the LMI H-infinity design, no renders) to stay fast; the full run is `make demo`."""
import csv
import json
import re

import pytest

# one worker runs the tests of the shared report (no worker waits for another's build)
pytestmark = pytest.mark.xdist_group("report")


def test_index_links_every_file(report):
    index = (report / "index.md").read_text()
    links = set(re.findall(r"\]\(([^)]+)\)", index))
    # every link points to a file that exists ...
    assert links and all((report / l).is_file() for l in links), \
        [l for l in links if not (report / l).is_file()]
    # ... and every file written (tables, plots, animation, ParaView collections) is linked
    written = {str(p.relative_to(report)) for p in report.rglob("*")
               if p.is_file() and (p.parent == report or p.suffix == ".pvd")}
    # report.html shows the index (tests/reference/test_report_html.py)
    assert written - {"index.md", "report.html"} <= links, written - {"index.md", "report.html"} - links
    for f in ("deploy-1-4D.csv", "deploy-1-4D.png", "deploy-1-4D.gif", "deploy-1-4D/1-4D.pvd",
              "vibration_com/com_1-4.pvd", "modes.vtu", "statics.csv", "frequencies.csv"):
        assert f in links, f
    assert "## Why ours and the printed values differ" in index and "docs/validation/errata.md" in index


def test_tables_carry_units_and_both_prestress_levels(report):
    rows = list(csv.reader(open(report / "frequencies.csv")))
    assert rows[0][:5] == ["mode", "MTC designed [Hz]", "MTC implied [Hz]", "SBC designed [Hz]",
                           "SBC implied [Hz]"]
    assert len(rows) == 1 + 6
    st = {r["quantity"]: r for r in csv.DictReader(open(report / "statics.csv"))}
    # implied prestress: r_1^S = 1.5025 m (docs/validation/errata.md), shorter than the design's, so the
    # tendons carry more force than at the designed rest length (eq. 3.8)
    assert float(st["rest length S_11"]["MTC implied"]) == 1.5025
    assert float(st["rest length S_11"]["MTC designed"]) > 1.5025
    assert float(st["max tendon stress"]["MTC implied"]) > float(st["max tendon stress"]["MTC designed"])
    assert st["max tendon stress"]["unit"] == "MPa" and float(st["max tendon stress"]["printed"]) == 37.98
    r = json.loads((report / "report.json").read_text())
    assert r["statics"]["implied"]["slack_tendons"] == [] and r["vibration"]["COM"]["steps"] == 20
    # the SBC and MTC models share the membrane mesh and rest lengths: their two lowest
    # (bar and membrane rigid-body) modes agree closely (Table 6.6 prints both at 0.1386 Hz)
    f = r["frequencies_hz"]
    assert f["SBC implied"][0] == pytest.approx(f["MTC implied"][0], rel=5e-3)
    d = r["deployment"]
    assert d["system"] == "1-4D" and d["t_end_s"] == pytest.approx(0.3)
    head = next(csv.reader(open(report / "deploy-1-4D.csv")))
    assert head[0] == "t [s]" and "w_1 [m]" in head and "eta_energy [J]" in head
    assert all("[" in h for h in head) and head[-1] == "controller [-]"


def test_one_membrane_displacement_field_in_every_file(report):
    # tmfem.io.fields.DISPLACEMENT_FIELD: floating-frame displacement in the design, the MTC
    # statics and the COM series; no other displacement name in any ParaView file
    import meshio
    from tmfem.io.fields import DISPLACEMENT_FIELD
    frames = sorted((report / "vibration_com").glob("*.vtu"))[:1]
    for f in [report / "configuration.vtu", report / "static_designed.vtu"] + frames:
        names = {n for n in meshio.read(f).point_data if "displacement" in n}
        assert names == {DISPLACEMENT_FIELD}, (f.name, names)

"""No NaN or infinity in any output: a battery of CLI runs writes every kind of file (CSV,
JSON, Markdown, VTU, PVD, PNG) and prints text and JSON; every file and every printed line is
scanned. The VTU files' convention for data not defined on a kind of cell or point (a bar
has no rest length: NaN, "no value" in ParaView, docs/guides/output.md) is the only NaN allowed:
all or none of the cells of one ``kind`` (points of one ``node_kind``)."""
import json
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from tests.cli.test_cli_misuse import run
from tests.system.test_validate import general_2_3, write

NONFINITE = re.compile(r"(?i)(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])")
NONE = re.compile(r"(?<![\w'\"])None(?![\w'\"])")


def battery(tmp_path):
    o = tmp_path / "out"
    gen = write(tmp_path, general_2_3(), "gen.toml")            # a system without [printed]
    return [
        ["equilibrium", "--preset", "1-4", "--mesh", "4"],
        ["equilibrium", str(gen), "--mesh", "4", "--json"],
        ["static", "--preset", "1-4", "--mesh", "4", "--vtk", o / "s.vtu", "--png", o / "s.png",
         "--stress-plot", o / "sp.png"],
        ["static", "--preset", "1-4", "--mesh", "4", "--json"],
        ["static", str(gen), "--mesh", "4"],
        ["static", "--model", "sbc", "--preset", "1-4", "--mesh", "3", "--vtk", o / "sbc.vtu"],
        ["modal", "--preset", "1-4", "--mesh", "4", "--modes", "6", "--vtk", o / "m.vtu"],
        ["modal", "--model", "com", "--preset", "2-3", "--modes", "6", "--json"],
        ["modal", "--model", "com", str(gen), "--modes", "4"],
        ["vibrate", "--preset", "1-4", "--t-end", "0.2", "--csv", o / "v.csv", "--plot", o / "v.png",
         "--vtk", o / "vs", "--vtk-every", "5"],
        ["vibrate", "--model", "mtc", "--preset", "1-4", "--mesh", "3", "--t-end", "0.03",
         "--csv", o / "vm.csv", "--json"],
        ["study", "--preset", "1-4", "--out", o / "study", "--mesh", "4", "--map-grid", "0"],
        ["export", "--preset", "1-4", o / "e.vtu"],
    ]


def scan_text(text, where):
    assert not NONFINITE.search(text), f"{where}: {NONFINITE.search(text).group(0)!r}"


def scan_json(text, where):
    def refuse(c):
        raise AssertionError(f"{where}: {c} in JSON")
    json.loads(text, parse_constant=refuse)


def scan_vtu(path):
    import meshio
    m = meshio.read(path)
    assert np.all(np.isfinite(m.points)), path
    kinds = m.cell_data.get("kind")
    for name, blocks in m.cell_data.items():
        for b, a in enumerate(blocks):
            a = np.asarray(a, dtype=float).reshape(len(a), -1)
            assert not np.any(np.isinf(a)), (path, name)
            groups = np.asarray(kinds[b]) if kinds is not None else np.zeros(len(a))
            for g in np.unique(groups):
                nan = np.isnan(a[groups == g])
                assert nan.all() or not nan.any(), (path, name, g)
    node_kind = m.point_data.get("node_kind")
    for name, a in m.point_data.items():
        a = np.asarray(a, dtype=float).reshape(len(a), -1)
        assert not np.any(np.isinf(a)), (path, name)
        groups = np.asarray(node_kind) if node_kind is not None else np.zeros(len(a))
        for g in np.unique(groups):
            nan = np.isnan(a[groups == g])
            assert nan.all() or not nan.any(), (path, name, g)


@pytest.mark.slow
def test_no_nonfinite_value_in_any_output(tmp_path, capsys):
    for argv in battery(tmp_path):
        rc, out, err = run([str(a) for a in argv], capsys)
        assert rc in (0, 1), (argv, err)                # 1: a design check failed, printed
        where = " ".join(map(str, argv))
        scan_text(out, where)
        assert not NONE.search(out), f"{where}: None printed as a value"
        if "--json" in argv:
            scan_json(out, where)
    files = [p for p in (tmp_path / "out").rglob("*") if p.is_file()]
    kinds = {p.suffix for p in files}
    assert {".csv", ".json", ".md", ".vtu", ".pvd", ".png"} <= kinds, kinds
    for p in files:
        assert not p.name.endswith(".partial") and ".tmp-" not in p.name and p.name != ".tmfem.lock"
        if p.suffix in (".csv", ".md"):
            scan_text(p.read_text(), p)
        elif p.suffix == ".json":
            scan_json(p.read_text(), p)
        elif p.suffix == ".vtu":
            scan_vtu(p)
        elif p.suffix == ".pvd":
            times = [float(d.attrib["timestep"]) for d in ET.parse(p).getroot().iter("DataSet")]
            assert times and np.all(np.isfinite(times))
        elif p.suffix == ".png":
            assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("text, bad", [("x = nan m", True), ("-inf", True), ("infinity", True),
                                       ("inflation, finance, nano", False), ("1e-9", False)])
def test_the_scan_finds_nonfinite_tokens(text, bad):
    assert bool(NONFINITE.search(text)) == bad

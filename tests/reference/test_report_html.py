"""report.html of `tmfem report`: one self-contained page, checked against the files of its
directory and opened in headless Chromium (Debian's ``chromium``, installed by
scripts/install_browser.sh; the browser tests skip where it is absent).

The page is the reduced report of tests/reference/conftest.py (its ``report`` fixture). In the browser: the page
loads without script errors (its own error handler and Chromium's console log), every image
decodes, every table and 3-D view is there and drew its elements, and (through the DevTools
protocol) every control, rotation, zoom, pick and playback of every view changes it;
screenshots of the page and of its 3-D views are kept under the test's tmp dir and, when
``TMFEM_ARTEFACTS`` names a directory, copied there."""
import base64
import json
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

# one worker runs the tests of the shared report (no worker waits for another's build)
pytestmark = pytest.mark.xdist_group("report")


BROWSERS = ("chromium", "chromium-browser", "google-chrome")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars"]


def _browser():
    return next((shutil.which(b) for b in BROWSERS if shutil.which(b)), None)


def _run(browser, tmp_path, url, *args):
    profile = tmp_path / f"profile-{len(list(tmp_path.glob('profile-*')))}"
    r = subprocess.run([browser, *FLAGS, "--virtual-time-budget=4000", f"--user-data-dir={profile}",
                        "--enable-logging=stderr",
                        "--v=0", *args, url], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r


class DevTools:
    """A page of headless Chromium driven through the DevTools protocol on a pipe
    (``--remote-debugging-pipe``: JSON messages ending in NUL on the child's fds 3 and 4), so
    that the test needs no client library. Collects uncaught exceptions and console errors."""

    def __init__(self, browser, profile):
        r_cmd, self._w = os.pipe()
        self._r, w_evt = os.pipe()

        def fds():                                   # the child reads fd 3, writes fd 4
            a, b = os.dup(r_cmd), os.dup(w_evt)
            os.dup2(a, 3)
            os.dup2(b, 4)
            os.set_inheritable(3, True)
            os.set_inheritable(4, True)
        self.proc = subprocess.Popen([browser, *FLAGS, f"--user-data-dir={profile}", "--remote-debugging-pipe",
                                      "--window-size=1100,800"], preexec_fn=fds,
                                     close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(r_cmd)
        os.close(w_evt)
        self._buf, self._id, self.errors = b"", 0, []
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Runtime", "Log", "Page"):
            self.call(f"{domain}.enable", session=True)

    def call(self, method, session=False, **params):
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params}
        if session:
            msg["sessionId"] = self.session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            while b"\0" in self._buf:
                raw, self._buf = self._buf.split(b"\0", 1)
                m = json.loads(raw)
                if m.get("method") == "Runtime.exceptionThrown":
                    self.errors.append(m["params"]["exceptionDetails"].get("exception", {}).get("description", "?"))
                elif m.get("method") == "Log.entryAdded" and m["params"]["entry"]["level"] == "error":
                    self.errors.append(m["params"]["entry"]["text"])
                elif m.get("id") == self._id:
                    assert "error" not in m, m["error"]
                    return m["result"]
            self._buf += os.read(self._r, 1 << 20)
        raise TimeoutError(method)

    def evaluate(self, js):
        r = self.call("Runtime.evaluate", session=True, expression=js, awaitPromise=True, returnByValue=True)
        assert "exceptionDetails" not in r, r["exceptionDetails"]
        return r["result"].get("value")

    def open(self, url):
        self.call("Page.navigate", session=True, url=url)
        for _ in range(200):
            if self.evaluate("!!document.documentElement && document.documentElement.hasAttribute('data-images')"):
                return
            time.sleep(0.05)
        raise TimeoutError(url)

    def close(self):
        self.proc.kill()
        self.proc.wait()


#: the script that works every control of the page's 3-D views (returns check -> bool)
INTERACT = (Path(__file__).parent / "report_interact.js").read_text()


def _keep(png, name):
    """Copy a screenshot to $TMFEM_ARTEFACTS (if set)."""
    keep = os.environ.get("TMFEM_ARTEFACTS")
    if keep:
        os.makedirs(keep, exist_ok=True)
        shutil.copy(png, os.path.join(keep, name))


def _decode(s, dtype):
    return np.frombuffer(base64.b64decode(s), dtype=dtype)


def _counts(directory):
    """Tables, images and 3-D views that the page must hold, counted from its sources: the
    Markdown tables and images of index.md, the CSV files it links with at most
    TABLE_MAX_ROWS rows, one configuration view, one per modes file, one per collection."""
    from tmfem.post.html_report import TABLE_MAX_ROWS
    index = (directory / "index.md").read_text()
    links = set(re.findall(r"\]\(([^)\s]+)\)", index))
    md_tables = len(re.findall(r"^\|[-| :]+\|$", index, flags=re.M))
    images = len(re.findall(r"!\[[^\]]*\]\(", index))
    csvs = [f for f in links if f.endswith(".csv")
            and sum(1 for _ in open(directory / f)) - 1 <= TABLE_MAX_ROWS]
    views = 1 + sum(f.endswith(".pvd") or f == "modes.vtu" for f in links)
    return md_tables + len(csvs) + 1, images, views       # + 1: the summary of report.json


def test_page_is_one_file_with_every_image_table_and_view(report):  # noqa: F811
    html = (report / "report.html").read_text()
    tables, images, views = _counts(report)
    # images embedded: no image refers to a file
    srcs = re.findall(r'<img[^>]*src="([^"]+)"', html)
    assert len(srcs) == images and all(s.startswith("data:image/") for s in srcs)
    assert html.count("<table") == tables
    assert len(re.findall(r'<div class="viewer"', html)) == views
    # the ParaView files are linked beside the page
    for f in re.findall(r'href="([^"#]+\.(?:vtu|pvd))"', html):
        assert (report / f).is_file(), f
    assert "http://" not in html and "https://" not in html        # nothing from the network


def test_scenes_carry_the_files_geometry_and_fields(report):  # noqa: F811
    # an independent read of the ParaView files (meshio) against the arrays in the page
    import meshio
    from tmfem.post.html_report import configuration_scene, modes_scene, pvd_frames, series_scene
    conf = meshio.read(report / "configuration.vtu")
    sc = configuration_scene({"design": report / "configuration.vtu"})["sets"][0]
    assert np.allclose(_decode(sc["points"], np.float32).reshape(-1, 3), conf.points, atol=1e-6)
    vm = {f["name"]: _decode(f["data"], np.float32) for f in sc["tri_fields"]}["von_mises"]
    membrane = np.concatenate([a for a, b in zip(conf.cell_data["von_mises"], conf.cells)
                               if b.type != "line"])
    # two triangles per membrane quad, each with its quad's value [MPa]
    assert vm.size == 2 * membrane.size
    assert np.allclose(np.sort(vm), np.sort(np.repeat(1e-6 * membrane, 2)), rtol=1e-6)
    m = modes_scene(report / "modes.vtu")
    mesh = meshio.read(report / "modes.vtu")
    assert [x["hz"] for x in m["modes"]] == pytest.approx(list(np.ravel(mesh.field_data["frequency_hz"])))
    s1 = _decode(m["modes"][0]["shape"], np.float32).reshape(-1, 3)
    # mode 1 drawn at the system's size: its largest nodal displacement equals m["size"]
    assert np.max(np.linalg.norm(s1, axis=1)) == pytest.approx(m["size"], rel=1e-6)
    assert np.allclose(np.cross(s1, mesh.point_data["mode_1"]), 0.0, atol=1e-6 * m["size"])
    pvd = report / "deploy-1-4D" / "1-4D.pvd"
    s = series_scene(pvd)
    frames = pvd_frames(pvd)
    last = meshio.read(frames[-1][1])
    assert s["times"][-1] == frames[-1][0] and s["n_frames"] == len(frames)
    X = _decode(s["frames"], np.float32).reshape(s["n_frames"], -1, 3)
    assert np.allclose(X[-1], last.points, atol=1e-6)
    w = _decode(s["w"], np.float32).reshape(s["n_frames"], -1)
    # NaN (no membrane) at the labelled nodes: drawn undeflected
    assert np.allclose(w[-1], 1e3 * np.nan_to_num(last.point_data["displacement_Of"][:, 2]), atol=1e-6)
    assert s["has_membrane"]              # the deployment's frames carry the deflected membrane


@pytest.fixture(scope="module")
def browser():
    b = _browser()
    if b is None:
        pytest.skip("no chromium: scripts/install_browser.sh installs Debian's package")
    return b


def test_page_loads_in_chromium_without_script_errors(report, browser, tmp_path):  # noqa: F811
    url = (report / "report.html").as_uri()
    r = _run(browser, tmp_path, url, "--dump-dom")
    dom = r.stdout
    root = re.search(r"<html[^>]*>", dom).group(0)
    assert 'data-loaded="1"' in root and "data-errors" not in root, root
    assert re.search(r'<pre id="script-errors"></pre>', dom)
    assert not re.search(r"Uncaught|SyntaxError|ReferenceError|TypeError", r.stderr), r.stderr[-2000:]
    tables, images, views = _counts(report)
    assert f'data-images="{images}/{images}"' in root, root      # every image decoded
    assert dom.count("<table") == tables
    drawn = re.findall(r'<div class="viewer" id="([^"]+)"[^>]*data-ready="1"', dom)
    assert len(drawn) == views, drawn
    counts = [int(n) for n in re.findall(r'<canvas[^>]*data-primitives="(\d+)"', dom)]
    assert len(counts) == views and min(counts) > 0, counts
    # the controls of the views: a data-set and field selector, a mode selector, a time slider
    assert dom.count('type="range"') >= views - 1 and dom.count("<select") >= 2


@pytest.mark.slow
def test_screenshots_of_the_page_and_its_views(report, browser, tmp_path):  # noqa: F811
    from PIL import Image
    url = (report / "report.html").as_uri()
    _, _, views = _counts(report)
    for name, suffix, size in (("report.png", "", "1280,1600"),
                               ("report-views.png", "#only=views", f"1100,{640 * views + 140}")):
        png = tmp_path / name
        _run(browser, tmp_path, url + suffix, f"--screenshot={png}", f"--window-size={size}")
        im = np.asarray(Image.open(png).convert("RGB"))
        assert im.shape[:2] == tuple(int(v) for v in size.split(","))[::-1]
        # drawn, not blank: a colour-mapped membrane and the text give many distinct colours
        assert len(np.unique(im.reshape(-1, 3), axis=0)) > 200, name
        _keep(png, name)


def test_a_directory_without_models_gives_a_page_without_views(tmp_path):
    # an index with one table and one plot and nothing for ParaView: the page holds the table
    # and the embedded plot and no 3-D view; a directory without index.md is refused
    from matplotlib.figure import Figure

    from tmfem.errors import InputError
    from tmfem.post.html_report import write_html_report
    Figure(figsize=(2, 2)).savefig(tmp_path / "p.png")
    (tmp_path / "index.md").write_text("# Report: x\n\n## 1. Part\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n![p](p.png)\n")
    html = write_html_report(tmp_path).read_text()
    assert html.count("<table") == 1 and '<div class="viewer"' not in html
    assert re.search(r'<img alt="p" src="data:image/png;base64,', html)
    with pytest.raises(InputError, match="expected index.md"):
        write_html_report(tmp_path / "nothing")


def test_every_control_of_every_view_works(report, browser, tmp_path):  # noqa: F811
    # through the DevTools protocol: the selectors (data set, membrane field, mode), the
    # sliders (amplitude, time, deflection scale), rotation, zoom, picking and playback each
    # change the view; no exception and no console error on the way
    page = DevTools(browser, tmp_path / "profile")
    try:
        page.open((report / "report.html").as_uri())
        checks = page.evaluate(INTERACT)
    finally:
        page.close()
    _, _, views = _counts(report)
    assert sum(k.endswith(": rotate") for k in checks) == views
    assert any("select mode" in k for k in checks) and any("slider t" in k for k in checks)
    assert any(k.endswith(": playback") for k in checks)
    assert all(checks.values()), {k: v for k, v in checks.items() if not v}
    assert page.errors == []

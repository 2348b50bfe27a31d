"""``report.html``: a report directory as one self-contained web page.

:func:`write_html_report` reads what ``tmfem report`` wrote into a directory (``index.md``
with the explanations and tables, the CSV tables, the PNG and GIF plots, the ParaView files)
and writes ``report.html`` beside it: the Markdown index as HTML (python-markdown), every
image embedded as a data URI, every small CSV table as a sortable table, the ParaView files
as relative links, and interactive 3-D views of the VTU/PVD files placed in the section that
links them:

* a configuration (``configuration.vtu``, ``static_*.vtu``): membrane coloured by an element
  stress, bars and tendons by their axial force;
* the mode shapes (``modes.vtu``: point data ``mode_k``, field data ``mode_k_hz``): a mode
  selector, an amplitude slider and an oscillation;
* a time series (``.pvd`` collection): a time slider and playback, the membrane coloured by its
  deflection w in O_f and its deflection drawn enlarged by a stated factor.

The views are drawn by a small script of the package (``templates/viewer.js``) on a 2-D
canvas (depth-sorted, flat-shaded triangles and lines): no WebGL, no network, no server,
so the page opens from the disk in any current browser and in headless Chromium without a
GPU. Drag rotates, the wheel zooms, shift-drag pans, a click picks an element and shows its
value. Geometry travels as base64 float32 arrays inside the page.
"""
from __future__ import annotations

import base64
import csv
import json
import logging
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from tmfem.errors import InputError

log = logging.getLogger(__name__)

#: cell data ``kind`` of the configuration files (:data:`tmfem.io.codes.KIND_CODES`)
BAR, TENDON, MEMBRANE = 0, 1, 2
#: membrane cell fields offered in a configuration view, in this order, and their units
MEMBRANE_FIELDS = {"von_mises": ("von Mises stress", "MPa", 1e-6),
                   "sigma_p1": ("first principal stress", "MPa", 1e-6),
                   "sigma_p2": ("second principal stress", "MPa", 1e-6)}
#: CSV files larger than this are linked, not shown as a table (time histories)
TABLE_MAX_ROWS = 200
#: most frames of a time series kept in the page (evenly spaced)
MAX_FRAMES = 60
#: the transverse deflection of a series is drawn so that its largest value is this part of the
#: plan size of the drawing
DEFLECTION_DRAWN = 0.04


def _b64(a, dtype) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def _read(path: Path):
    import meshio
    try:
        return meshio.read(path)
    except Exception as exc:                      # meshio raises several kinds on a bad file
        raise InputError(f"{path}: expected a readable VTU file, found {exc}") from exc


def _topology(mesh) -> dict:
    """Lines (bars, tendons) and membrane triangles of a meshio mesh with cell data ``kind``
    (cells without it: lines are tendons, polygons and quads membrane)."""
    lines, line_kind, line_cell, tris, tri_cell = [], [], [], [], []
    kinds = mesh.cell_data.get("kind")
    offset = 0
    for b, block in enumerate(mesh.cells):
        c = np.asarray(block.data)
        kind = np.asarray(kinds[b]).ravel() if kinds is not None else None
        if block.type == "line":
            lines.append(c)
            line_kind.append(kind if kind is not None else np.full(len(c), TENDON))
            line_cell.append(offset + np.arange(len(c)))
        elif c.ndim == 2 and c.shape[1] >= 3:
            fan = np.concatenate([c[:, [0, k, k + 1]] for k in range(1, c.shape[1] - 1)])
            tris.append(fan)
            tri_cell.append(np.tile(offset + np.arange(len(c)), c.shape[1] - 2))
        offset += len(c)
    cat = (lambda v, w: np.concatenate(v) if v else np.zeros((0, w), dtype=int))  # noqa: E731
    lines, tris = cat(lines, 2), cat(tris, 3)
    return {"lines": lines, "line_kind": np.concatenate(line_kind) if line_kind else np.zeros(0),
            "line_cell": np.concatenate(line_cell) if line_cell else np.zeros(0, dtype=int),
            "tris": tris, "tri_cell": np.concatenate(tri_cell) if tri_cell else np.zeros(0, dtype=int)}


def _cell_field(mesh, name: str):
    """Cell data ``name`` concatenated over the blocks (NaN where a block lacks it)."""
    if name not in mesh.cell_data:
        return None
    return np.concatenate([np.asarray(a, dtype=float).reshape(len(b.data), -1)[:, 0]
                           for a, b in zip(mesh.cell_data[name], mesh.cells)])


def _geometry(topo: dict, points) -> dict:
    return {"points": _b64(np.asarray(points)[:, :3], np.float32), "n_points": int(len(points)),
            "lines": _b64(topo["lines"], np.int32), "line_kind": _b64(topo["line_kind"], np.uint8),
            "tris": _b64(topo["tris"], np.int32)}


def configuration_scene(paths: dict) -> dict:
    """The scene of one or more configuration files ``{label: path}`` (same system): each a
    dataset with its points, membrane fields (:data:`MEMBRANE_FIELDS`, per triangle) and the
    axial force of every line."""
    sets = []
    for label, path in paths.items():
        mesh = _read(path)
        topo = _topology(mesh)
        fields = []
        for key, (title, unit, f) in MEMBRANE_FIELDS.items():
            v = _cell_field(mesh, key)
            if v is not None and topo["tris"].size:
                fields.append({"name": key, "title": title, "unit": unit,
                               "data": _b64(f * v[topo["tri_cell"]], np.float32)})
        force = _cell_field(mesh, "axial_force")
        line_field = None if force is None or not topo["lines"].size else \
            {"title": "axial force", "unit": "N", "data": _b64(force[topo["line_cell"]], np.float32)}
        sets.append({"label": label, **_geometry(topo, mesh.points), "tri_fields": fields,
                     "line_field": line_field})
    return {"type": "configuration", "sets": sets}


def modes_scene(path: Path) -> dict:
    """The scene of a modes file: base geometry, ``mode_k`` shapes and their frequencies; the
    membrane coloured by the displacement magnitude of the mode (per triangle, mean of its
    nodes, scaled to the largest of the mode)."""
    mesh = _read(path)
    topo = _topology(mesh)
    keys = sorted((k for k in mesh.point_data if re.fullmatch(r"mode_\d+", k)),
                  key=lambda k: int(k.split("_")[1]))
    if not keys:
        raise InputError(f"{path}: expected point data mode_1, mode_2, ..., found {sorted(mesh.point_data)}")
    shapes = np.array([np.asarray(mesh.point_data[k], dtype=float)[:, :3] for k in keys])
    hz = [float(np.ravel(mesh.field_data.get(f"{k}_hz", [np.nan]))[0]) for k in keys]
    size = float(np.max(np.ptp(mesh.points, axis=0)))
    modes = []
    for k, s, f in zip(keys, shapes, hz):
        peak = float(np.max(np.linalg.norm(s, axis=1))) or 1.0
        mag = np.linalg.norm(s, axis=1) / peak
        modes.append({"label": f"mode {k.split('_')[1]}: {f:.4g} Hz", "hz": f,
                      "shape": _b64(s / peak * size, np.float32),
                      "tri_field": _b64(mag[topo["tris"]].mean(axis=1) if topo["tris"].size else [], np.float32)})
    return {"type": "modes", **_geometry(topo, mesh.points), "modes": modes,
            "amplitude": 0.1, "size": size}


def pvd_frames(pvd: Path) -> list[tuple[float, Path]]:
    """(time, file) of the data sets of a ParaView collection, in its order."""
    try:
        root = ET.parse(pvd).getroot()
    except (ET.ParseError, OSError) as exc:
        raise InputError(f"{pvd}: expected a ParaView collection (.pvd), found {exc}") from exc
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def series_scene(pvd: Path, *, max_frames: int = MAX_FRAMES) -> dict:
    """The scene of a time series (a ``.pvd`` whose frames share one topology): node
    positions per frame, the transverse membrane deflection w (point data
    ``displacement_Of``, third component) per frame with the membrane's normal to draw it
    enlarged, the axial force of every line per frame."""
    frames = pvd_frames(pvd)
    if not frames:
        raise InputError(f"{pvd}: expected at least one data set, found none")
    pick = np.unique(np.linspace(0, len(frames) - 1, min(max_frames, len(frames))).astype(int))
    first = _read(frames[pick[0]][1])
    topo = _topology(first)
    X, W, N, F, times = [], [], [], [], []
    for k in pick:
        t, path = frames[k]
        mesh = first if k == pick[0] else _read(path)
        if len(mesh.points) != len(first.points):
            raise InputError(f"{path}: expected {len(first.points)} points as the first frame, "
                             f"found {len(mesh.points)}")
        X.append(mesh.points[:, :3])
        d = mesh.point_data.get("displacement_Of")
        w = np.zeros(len(mesh.points)) if d is None else np.nan_to_num(np.asarray(d, dtype=float)[:, 2])
        W.append(w)
        N.append(_normal(mesh.points[:, :3], topo["tris"]))
        f = _cell_field(mesh, "axial_force")
        F.append(np.zeros(len(topo["lines"])) if f is None else f[topo["line_cell"]])
        times.append(t)
    X, W = np.array(X), np.array(W)
    size = float(np.max(np.ptp(X.reshape(-1, 3), axis=0)))
    w_max = float(np.max(np.abs(W)))
    scale = _nice(DEFLECTION_DRAWN * size / w_max) if w_max > 0 else 1.0
    return {"type": "series", **_geometry(topo, X[0]), "times": times, "n_frames": len(times),
            "frames": _b64(X, np.float32), "w": _b64(1e3 * W, np.float32),
            "normals": _b64(np.array(N), np.float32), "line_force": _b64(np.array(F), np.float32),
            "w_max_mm": 1e3 * w_max, "deflection_scale": scale, "has_membrane": bool(topo["tris"].size)}


def _normal(x, tris) -> list:
    """Unit normal of the least-squares plane through the membrane's nodes (z if none)."""
    if not tris.size:
        return [0.0, 0.0, 1.0]
    p = x[np.unique(tris)]
    n = np.linalg.svd(p - p.mean(axis=0), full_matrices=False)[2][2]
    return (n if n[2] >= 0 else -n).tolist()


def _nice(f: float) -> float:
    """The largest of 1, 2, 5 times a power of ten that is <= f (at least 1)."""
    if f <= 1:
        return 1.0
    e = 10.0 ** np.floor(np.log10(f))
    return float(max(m * e for m in (1, 2, 5) if m * e <= f))


def csv_table(path: Path) -> dict | None:
    """Header and rows of a CSV file with at most :data:`TABLE_MAX_ROWS` rows (else None)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or len(rows) - 1 > TABLE_MAX_ROWS:
        return None
    return {"name": path.name, "header": rows[0], "rows": rows[1:]}


def _data_uri(path: Path) -> str:
    mime = {".png": "image/png", ".gif": "image/gif", ".jpg": "image/jpeg", ".svg": "image/svg+xml"}
    return f"data:{mime[path.suffix.lower()]};base64," + base64.b64encode(path.read_bytes()).decode("ascii")


def _sections(html: str) -> list[dict]:
    """The HTML of the index cut at its ``<h2>`` headings: [{title, id, html}] (the part
    before the first heading has title None)."""
    parts = re.split(r"(<h2[^>]*>.*?</h2>)", html, flags=re.S)
    out = [{"title": None, "id": "top", "html": parts[0]}]
    for head, body in zip(parts[1::2], parts[2::2]):
        title = re.sub(r"<[^>]+>", "", head).strip()
        out.append({"title": title, "id": re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-"),
                    "html": body})
    return out


def _embed_images(html: str, out: Path) -> str:
    def repl(m):
        p = out / m.group(2)
        return f'{m.group(1)}{_data_uri(p)}"' if p.is_file() and p.suffix.lower() in (".png", ".gif") else m.group(0)
    return re.sub(r'(<img[^>]*?src=")([^":]+)"', repl, html)


def scenes(out: Path, files: list[str]) -> list[dict]:
    """The 3-D views of the files of a report directory: one configuration view of the
    configuration files (``configuration.vtu`` and ``static_*.vtu``), one per modes file,
    one per ParaView collection; each with the file that places it in the page."""
    views = []
    config = {f: out / f for f in files if f.endswith(".vtu") and
              (f == "configuration.vtu" or re.fullmatch(r"static_\w+\.vtu", f))}
    if config:
        labels = {f: "design (ch. 3)" if f == "configuration.vtu" else
                  "MTC equilibrium, " + f[len("static_"):-4] + " prestress" for f in config}
        views.append({"id": "view-configuration", "title": "Configuration: stresses and forces",
                      "anchor": next(iter(config)),
                      "scene": configuration_scene({labels[f]: p for f, p in config.items()})})
    for f in files:
        if f.endswith(".vtu") and "modes" in Path(f).stem:
            views.append({"id": "view-" + Path(f).stem, "title": f"Mode shapes ({f})", "anchor": f,
                          "scene": modes_scene(out / f)})
        elif f.endswith(".pvd"):
            stem = Path(f).stem
            views.append({"id": "view-" + re.sub(r"[^A-Za-z0-9]+", "-", stem), "anchor": f,
                          "title": f"Time series ({f})", "scene": series_scene(out / f)})
    return views


def write_html_report(out, *, files=None, title: str | None = None) -> Path:
    """Write ``report.html`` into the report directory ``out`` and return its path.

    Parameters
    ----------
    out : Path
        A directory written by :func:`tmfem.reference.report.write_report` (it reads
        ``index.md``, the files it links and ``report.json``).
    files : list of str, optional
        Files of the directory (relative paths) to show; default those that ``index.md``
        links and the ``.pvd`` and CSV files beside it.
    title : str, optional
        The page title; default the index's first heading.
    """
    import markdown
    from jinja2 import Environment, PackageLoader, select_autoescape

    out = Path(out)
    index = out / "index.md"
    if not index.is_file():
        raise InputError(f"report directory {str(out)!r}: expected index.md, found none")
    text = index.read_text()
    links = re.findall(r"\]\(([^)\s:]+)\)", text)
    files = list(dict.fromkeys(files if files is not None else links))
    files = [f for f in files if (out / f).is_file()]
    first = re.search(r"^# (.+)$", text, flags=re.M)
    body = markdown.markdown(text, extensions=["tables", "fenced_code"])
    body = _embed_images(body, out)
    body = re.sub(r"<table>", '<table class="sortable">', body)
    body = re.sub(r"<h1>.*?</h1>", "", body, count=1, flags=re.S)
    sections = _sections(body)
    views = scenes(out, files)
    for v in views:                 # each view goes at the end of the section that links its file
        home = next((s for s in sections[1:] if f'href="{v["anchor"]}"' in s["html"]), None)
        (home or sections[-1]).setdefault("views", []).append(v)
    shown = set(re.findall(r'href="([^"]+\.csv)"', body))
    tables = [t for t in (csv_table(out / f) for f in files if f.endswith(".csv") and f in shown) if t]
    summary = json.loads((out / "report.json").read_text()) if (out / "report.json").is_file() else {}
    env = Environment(loader=PackageLoader("tmfem.post", "templates"),
                      autoescape=select_autoescape(["html"]))
    html = env.get_template("report.html.j2").render(
        title=title or (first.group(1) if first else out.name), sections=sections, tables=tables,
        views=[{"id": v["id"], "scene": v["scene"]} for v in views],
        summary=_summary_rows(summary),
        script=(Path(__file__).parent / "templates" / "viewer.js").read_text(),
        style=(Path(__file__).parent / "templates" / "report.css").read_text())
    path = out / "report.html"
    path.write_text(html)
    log.info("wrote %s (%.1f MB)", path, path.stat().st_size / 1e6)
    return path


def _summary_rows(summary: dict) -> list[tuple[str, str]]:
    """The scalar entries of ``report.json`` (its top level and its ``deployment``) as
    (name, value) rows for the page's summary box."""
    rows = []
    for key, v in summary.items():
        if isinstance(v, (str, int, float, bool)):
            rows.append((key, f"{v:.5g}" if isinstance(v, float) else str(v)))
    dep = summary.get("deployment") or {}
    for key, v in dep.items():
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            rows.append((f"deployment {key}", f"{v:.5g}" if isinstance(v, float) else str(v)))
    return rows

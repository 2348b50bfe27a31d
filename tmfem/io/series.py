"""Time series for ParaView: one ``.vtu`` per frame and the ``.pvd`` collection."""
from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from tmfem.errors import InputError
from tmfem.io.atomic import write_text
from tmfem.io.meshes import block_data, normalize_cells, to_meshio
from tmfem.io.writer import write_configuration, write_mesh


#: Comment of a ``.pvd`` collection whose run has not ended (or stopped early).
INCOMPLETE = "incomplete: the run has not reached its end"


class SeriesWriter:
    """A time series of ``.vtu`` files and the ``.pvd`` collection that lists them.

    Every :meth:`append` writes one frame file and rewrites the ``.pvd`` (atomically), so
    a run that stops early leaves a valid collection of the frames written so far; until
    :meth:`finish` the collection carries the comment :data:`INCOMPLETE` (a run that
    stopped early keeps it).
    """

    def __init__(self, directory, *, name: str = "frame"):
        directory = Path(directory)
        if directory.exists() and not directory.is_dir():
            raise InputError(f"series directory {str(directory)!r} is a file")
        if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
            raise InputError(f"series name {name!r}: expected letters, digits, '_', '-', '.'")
        directory.mkdir(parents=True, exist_ok=True)
        self.directory = directory
        self.name = name
        self.pvd = directory / f"{name}.pvd"
        self.entries: list[tuple[float, str]] = []
        self.complete = False

    def _next(self) -> Path:
        return self.directory / f"{self.name}_{len(self.entries):05d}.vtu"

    def _commit(self, time: float, path: Path) -> Path:
        self.entries.append((float(time), path.name))
        self._write_pvd()
        return path

    def _write_pvd(self) -> None:
        rows = "".join(f'    <DataSet timestep="{t!r}" group="" part="0" file="{f}"/>\n'
                       for t, f in self.entries)
        mark = "" if self.complete else f"<!-- {INCOMPLETE} -->\n"
        write_text(self.pvd, '<?xml version="1.0"?>\n' + mark + '<VTKFile type="Collection" '
                   f'version="0.1">\n  <Collection>\n{rows}  </Collection>\n</VTKFile>\n')

    def finish(self) -> None:
        """The run reached its end: the collection loses its :data:`INCOMPLETE` mark."""
        self.complete = True
        self._write_pvd()

    def _check_time(self, time) -> float:
        time = float(time)
        if not np.isfinite(time):
            raise InputError(f"series time must be finite, found {time}")
        if self.entries and time <= self.entries[-1][0]:
            raise InputError(f"series times must increase: frame {len(self.entries)} at "
                             f"t={time} after t={self.entries[-1][0]}")
        return time

    def append(self, time, points, cells, *, point_data=None, cell_data=None) -> Path:
        """Write one frame: points (3, n), cells as for :func:`write_modes`."""
        time = self._check_time(time)
        X = np.asarray(points, dtype=float)
        if X.ndim != 2 or X.shape[0] != 3:
            raise InputError(f"points: expected shape (3, n), found {X.shape}")
        blocks = normalize_cells(cells, X.shape[1])
        pdata, cdata = block_data(point_data, cell_data, blocks, X.shape[1])
        path = write_mesh(self._next(), to_meshio(X, blocks, point_data=pdata, cell_data=cdata))
        return self._commit(time, path)

    def append_configuration(self, time, system, **kwargs) -> Path:
        """Write one frame with :func:`write_configuration` (same keyword arguments)."""
        time = self._check_time(time)
        path = write_configuration(self._next(), system, **kwargs)
        return self._commit(time, path)


def write_series(directory, frames, *, name: str = "frame") -> Path:
    """Write frames one by one as they come; returns the ``.pvd`` path.

    ``frames`` is an iterable (a generator from a running simulation is fine) of
    ``(time, points (3, n), cells)`` or ``(time, points, cells, point_data)`` tuples.
    """
    w = SeriesWriter(directory, name=name)
    for fr in frames:
        if len(fr) == 3:
            w.append(fr[0], fr[1], fr[2])
        elif len(fr) == 4:
            w.append(fr[0], fr[1], fr[2], point_data=fr[3])
        else:
            raise InputError(f"series frame: expected (time, points, cells[, point_data]), "
                             f"found a tuple of {len(fr)}")
    w.finish()
    return w.pvd


def read_pvd(path) -> list[tuple[float, Path]]:
    """Times and frame files listed in a ``.pvd`` collection."""
    path = Path(path)
    root = ET.parse(path).getroot()
    return [(float(d.attrib["timestep"]), path.parent / d.attrib["file"])
            for d in root.iter("DataSet")]

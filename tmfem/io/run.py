"""Outputs of a time run written as it goes: CSV history, ParaView series, smallest tendon force.

Every row is flushed and every ParaView frame committed when it is computed, so a run that
stops early (an error, Ctrl-C, SIGTERM) leaves everything computed so far on disk -- marked
as incomplete: the CSV is written as ``NAME.csv.partial`` and renamed to ``NAME.csv`` when
the run ends (:meth:`RunOutputs.close` with ``complete=True``), and the ``.pvd`` collection
carries an ``incomplete`` comment until then (docs/guides/cli.md, "Partial files").
"""
from __future__ import annotations

import csv
import os
import re
from pathlib import Path

import numpy as np

from tmfem.errors import ConvergenceError, InputError, shorten
from tmfem.io.series import SeriesWriter


#: Units of the named signals of a run. ``eta_k``: the COM's membrane modal coordinates; the
#: modes are mass-normalised (phi^T M phi = 1, M in kg, docs/guides/com.md), so eta = w / phi
#: carries kg^0.5 m. ``ur_k``/``vr_k``/``wr_k``: membrane point coordinates (eq. 5.17).
_UNITS = [(r"t", "s"), (r"(theta|psi|sigma)_\d+", "rad"), (r"w_\d+", "m"),
          (r"[xyz]_\d+", "m"), (r"[A-Z]+_[\d,]+_[xyz]", "m"), (r"tendon_deflection", "m"),
          (r"(kinetic|strain|eta)_energy", "J"), (r"eta_\d+", "kg^0.5 m"), (r"[uvw]r_\d+", "m"),
          (r"u_.+|r_.+|L_.+", "m"), (r"T_.+|force_.+", "N")]


def column_header(name: str) -> str:
    """``name [unit]`` for the CSV header of a run history (``theta_11`` -> ``theta_11 [rad]``,
    ``theta_11_dot`` -> ``theta_11_dot [rad/s]``, ``B_12_z`` -> ``B_12_z [m]``, ``eta_1`` ->
    ``eta_1 [kg^0.5 m]``, see :data:`_UNITS`); the reference of a signal (``x_21_ref``: q_d of
    eq. 5.68) has the signal's unit; a name without a known unit stays bare."""
    base, rate = (name[:-4], True) if name.endswith("_dot") else (name, False)
    base = base[:-4] if base.endswith("_ref") else base
    for pattern, unit in _UNITS:
        if re.fullmatch(pattern, base):
            return f"{name} [{unit}/s]" if rate else f"{name} [{unit}]"
    return name


def partial_name(path) -> Path:
    """The name of a time series while its run is under way: ``NAME.csv.partial``."""
    path = Path(path)
    return path.with_name(path.name + ".partial")


class RunOutputs:
    """Per-step outputs of a simulation run, shared by every model's runs (6.5, 7.4).

    Parameters
    ----------
    csv_path : path or None
        CSV history: header ``columns`` with their units (:func:`column_header`), one row
        per recorded step, flushed; ``\n`` line endings.
    columns : list of str
    vtk_dir : path or None
        ParaView series (:class:`tmfem.io.series.SeriesWriter`), a frame every ``vtk_every`` steps.
    vtk_every : int
    name : str
        Name of the ParaView series (parentheses dropped).
    """

    def __init__(self, *, csv_path, columns, vtk_dir, vtk_every, name: str):
        self.series = None
        if vtk_dir is not None:
            if not (isinstance(vtk_every, int) and vtk_every >= 1):
                raise InputError(f"vtk_every: expected an integer >= 1, found {vtk_every!r}")
            self.series = SeriesWriter(vtk_dir, name=name.replace("(", "").replace(")", ""))
        self.csv_path = Path(csv_path) if csv_path else None
        self.fh = None
        if self.csv_path is not None:
            if self.csv_path.exists():             # no earlier run's file beside this one's
                self.csv_path.unlink()
            self.fh = open(partial_name(self.csv_path), "w", newline="")
        self.writer = csv.writer(self.fh, lineterminator="\n") if self.fh else None
        if self.writer:
            self.writer.writerow([column_header(c) for c in columns])
        self.columns = list(columns)
        self.vtk_every = vtk_every
        self.count = 0
        self.min_force = [np.inf, 0.0, ""]        # smallest tendon force, its time and tendon

    def frame_due(self) -> bool:
        """True when the current step is written as a ParaView frame."""
        return self.series is not None and self.count % self.vtk_every == 0

    def tendon_forces(self, t: float, force: np.ndarray, names) -> None:
        """Keep the smallest of ``force`` (one per member, ``names[k]`` its tendon) over time."""
        k = int(np.argmin(force))
        if force[k] < self.min_force[0]:
            self.min_force[:] = [float(force[k]), float(t), names[k]]

    def row(self, t: float, values: np.ndarray) -> None:
        """Write the CSV row of time t (when a CSV is asked) and count the step.

        Raises
        ------
        ConvergenceError
            when a value is NaN or infinite (the run diverged): no such row is written, the
            files keep their partial mark.
        """
        values = np.asarray(values, dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size or not np.isfinite(t):
            names = [self.columns[1 + k] for k in bad] if bad.size else ["t"]
            raise ConvergenceError(f"t = {t:.6g} s: non-finite values of {shorten(names)} (the "
                                   "run diverged; nothing non-finite is written)")
        self.count += 1
        if self.writer:
            self.writer.writerow([f"{t:.6g}"] + [f"{v:.10g}" for v in values])
            self.fh.flush()

    def close(self, *, complete: bool) -> None:
        """Close the files; ``complete``: the run reached its end, so the CSV gets its final
        name and the ``.pvd`` loses its ``incomplete`` mark (else both stay marked)."""
        if self.fh:
            self.fh.close()
            self.fh = None
            if complete:
                os.replace(partial_name(self.csv_path), self.csv_path)
        if complete and self.series is not None:
            self.series.finish()

    def stats(self, sim) -> dict:
        """Step and Newton counts of the simulation ``sim``, the smallest tendon force, the .pvd."""
        out = {**sim.stats, "min_tendon_force": self.min_force[0],
               "min_tendon_force_time": self.min_force[1],
               "min_tendon_force_tendon": self.min_force[2]}
        if self.series is not None:
            out["pvd"] = str(self.series.pvd)
        return out

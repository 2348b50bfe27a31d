"""The result of a nonlinear run of a structure: its converged states and why it stopped.

A :class:`Path` is the list of converged :class:`~tmfem.fem.structure.model.StructureState`
(the start first) of load control, displacement control or arc length, with the reason the
run stopped (:data:`tmfem.solvers.continuation.REASONS`), the method and controls that made
it, and what a continuation needs (the last increment and arc).
:meth:`tmfem.fem.structure.Structure.resume` continues it.
"""
from __future__ import annotations

import numpy as np


class Path(list):
    """Converged states of one run (a list, the start first) with ``method`` ("load",
    "displacement", "arc-length"), ``controls`` (the keyword arguments of the run),
    ``reason`` and ``message`` (why it stopped), ``increment`` and ``dl`` (the last
    converged increment and the next arc, for :meth:`Structure.resume`)."""

    def __init__(self, states, *, method: str, controls: dict, reason: str, message: str,
                 increment=None, dl: float | None = None):
        super().__init__(states)
        self.method = method
        self.controls = dict(controls)
        self.reason = reason
        self.message = message
        self.increment = increment
        self.dl = dl

    @property
    def completed(self) -> bool:
        """True when the run reached its target (load factor, displacement or stop())."""
        return self.reason in ("completed", "stopped")

    def check(self) -> "Path":
        """This path when it is complete; a :class:`~tmfem.errors.ConvergenceError` with the
        reason and message otherwise (for callers that need the target reached)."""
        if not self.completed:
            from tmfem.errors import ConvergenceError
            raise ConvergenceError(f"{self.method} control: expected to reach the target, stopped "
                                   f"({self.reason}): {self.message}")
        return self

    @property
    def lam(self) -> np.ndarray:
        """Load factor of every converged state."""
        return np.array([s.lam for s in self])

    @property
    def iterations(self) -> np.ndarray:
        """Newton iterations of every step (0 at the start)."""
        return np.array([s.iterations for s in self])

    @property
    def residuals(self) -> np.ndarray:
        """Last residual norm of every step (NaN where none was recorded)."""
        return np.array([s.residual_history[-1] if s.residual_history else np.nan for s in self])

    @property
    def events(self) -> list:
        """(index, event) of the steps that passed a limit point or a bifurcation indicator, or
        (load control, ``on_snap="mark"``) jumped a snap-through."""
        return [(i, s.event) for i, s in enumerate(self) if s.event]

    def __repr__(self) -> str:
        return (f"Path({self.method}, {len(self)} states, lam {self.lam[0]:g} -> {self.lam[-1]:g}, "
                f"{self.reason}: {self.message})")

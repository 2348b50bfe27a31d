"""Exception types of tmfem.

Every message states what was expected and what was found, with numbers, so that a
user can act on it without reading a traceback. The CLI prints ``str(exc)`` on one
line and exits with :attr:`TmfemError.exit_code` (the contract is in docs/guides/cli.md):

====  ==========================================================================
0     success (with ``--allow-infeasible``: also when checks failed; they are listed)
1     the analysis says no: infeasible design, slack tendon or membrane, a failed
      design check, no convergence
2     bad input: malformed system file, option out of range, unwritable output path, an
      output directory in use by another run
3     the job would not fit this machine (estimated memory/time over the limit)
4     an optional backend or dependency is not installed
130   interrupted (Ctrl-C, SIGINT)
143   terminated (SIGTERM)
====  ==========================================================================
"""


def shorten(items, limit: int = 4) -> str:
    """``a, b, c, d, ... (9 in all)``: the first ``limit`` items of a list, then an ellipsis
    and the count -- never a list cut off silently (messages and the CLI's text)."""
    items = [str(x) for x in items]
    head = ", ".join(items[:limit])
    return head if len(items) <= limit else f"{head}, ... ({len(items)} in all)"


class TmfemError(Exception):
    """Base class of all tmfem errors."""

    exit_code = 1


class InputError(TmfemError, ValueError):
    """Malformed input: a spec file, a preset name, an argument out of its range."""

    exit_code = 2


class InfeasibleDesign(TmfemError):
    """A design outside the equilibrium conditions (e.g. eqs. 3.35-3.37, 3.41)."""


class SlackTendon(InfeasibleDesign):
    """A tendon that would have to push (non-positive force density or force)."""


class SlackMembrane(InfeasibleDesign):
    """A membrane that is not stretched (corner displacement Delta <= 0, eq. 3.36)."""


class CollapsedStructure(InfeasibleDesign):
    """A static equilibrium that is no tensegrity: bars fallen flat or through their lower
    ends, non-finite results (:func:`tmfem.system.collapse.check_standing`)."""


class ConvergenceError(TmfemError):
    """An iterative solve (Newton, arc length, constraint projection) that did not converge."""


class BackendUnavailable(TmfemError):
    """An optional backend (PETSc/SLEPc) that is not installed."""


class InfeasibleController(TmfemError):
    """A controller synthesis whose LMIs are infeasible, whose solver did not reach an
    optimal status, or whose recovered controller fails its closed-loop checks (eqs. 5.63-5.67)."""


class SingularInputMatrix(TmfemError):
    """The actuated input matrix B_q of the collocated partial feedback linearisation (eq.
    5.46) is not square or not invertible at a configuration (its condition number exceeds
    the limit)."""
    exit_code = 4


class OutputBusy(InputError):
    """An output directory in use by another tmfem run (:mod:`tmfem.io.lock`); the message
    names that run."""


class ResourceLimit(InputError):
    """A job whose estimated memory or run time exceeds what this machine can give; the
    message states the estimate and the limit."""

    exit_code = 3

"""Exception types of tmfem.

Every message states what was expected and what was found, with numbers, so that a
user can act on it without reading a traceback. The CLI prints ``str(exc)`` on one
line and exits with :attr:`TmfemError.exit_code`.
"""


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

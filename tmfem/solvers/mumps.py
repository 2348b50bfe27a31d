"""MUMPS's return codes: what a failed analysis or factorisation means.

MUMPS reports a failure in INFOG(1) < 0 with a detail in INFOG(2) (MUMPS 5.5 users' guide,
"Error diagnostics"). PETSc turns a failed factorisation into a failed preconditioner (KSP
``DIVERGED_PC_FAILED``, SNES ``DIVERGED_LINEAR_SOLVE``), which says nothing of the cause:
a singular matrix, a workspace estimate that ran short, memory that ran out, or an option
this MUMPS cannot honour. :func:`mumps_failure` reads the code of a KSP's MUMPS factor and
:func:`describe` says what it means and what to change. Only INFOG(1) = -10 (a numerically
singular matrix) is a property of the matrix that a regularisation can cure; every other
code fails again for any matrix of the pattern.
"""
from __future__ import annotations

from tmfem.errors import ConvergenceError, InputError, ResourceLimit, TmfemError

#: INFOG(1) of a numerically singular matrix (a zero pivot)
SINGULAR = -10

#: INFOG(1) of a structurally singular matrix
STRUCTURALLY_SINGULAR = -6

#: codes of a workspace estimated in the analysis that ran short in the factorisation or
#: the solve; MUMPS's remedy: a larger memory relaxation ICNTL(14) [percent]
_WORKSPACE = (-8, -9, -11, -12, -14, -15, -17, -20)

_MEANING = {
    -5: "memory ran out in the analysis (real workspace of INFOG(2) entries)",
    STRUCTURALLY_SINGULAR: "the matrix is structurally singular (structural rank INFOG(2))",
    -7: "memory ran out in the analysis (integer workspace of INFOG(2) entries)",
    SINGULAR: "the matrix is numerically singular (a zero pivot)",
    -13: "memory ran out in the factorisation (an allocation of |INFOG(2)| entries, "
         "x 1e6 when INFOG(2) < 0, failed)",
    -19: "the working memory limit ICNTL(23) is below what the factorisation needs "
         "(INFOG(2) entries short, x 1e6 when negative; -mat_mumps_icntl_23 sets the limit in MB, "
         "-st_mat_mumps_icntl_23 that of the eigen solve's factorisation)",
    -38: "the parallel analysis ICNTL(28) = 2 asks for PT-SCOTCH or ParMETIS, which this "
         "MUMPS was not built with (-mat_mumps_icntl_28 1: the sequential analysis)",
}


def mumps_factor(ksp):
    """The MUMPS factor matrix of a KSP, or None (the preconditioner is not a MUMPS
    factorisation, or has no factor yet)."""
    pc = ksp.getPC()
    try:
        if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
            return None
        return pc.getFactorMatrix()
    except Exception:                  # no factor matrix (the analysis never ran)
        return None


def mumps_failure(ksp) -> tuple[int, int] | None:
    """``(INFOG(1), INFOG(2))`` of the failed MUMPS factorisation of a KSP, or None (no
    MUMPS factorisation, or it succeeded)."""
    F = mumps_factor(ksp)
    if F is None:
        return None
    code = int(F.getMumpsInfog(1))
    return (code, int(F.getMumpsInfog(2))) if code < 0 else None


def describe(code: int, detail: int) -> str:
    """What the MUMPS failure ``(INFOG(1), INFOG(2))`` means and what to change."""
    if code in _WORKSPACE:
        what = ("the workspace that MUMPS estimated in its analysis ran short (the memory "
                "relaxation ICNTL(14), in percent of the estimate: raise it with "
                "-mat_mumps_icntl_14, for example 50 or 100; -st_mat_mumps_icntl_14 for the eigen "
                "solve's factorisation)")
    else:
        what = _MEANING.get(code, "see the MUMPS users' guide, error diagnostics")
    return f"MUMPS INFOG(1) = {code}, INFOG(2) = {detail}: {what}"


def is_singular(code: int) -> bool:
    """Whether the MUMPS failure code is that of a singular matrix (numerically or
    structurally), the one failure a shift of the matrix can cure."""
    return code in (SINGULAR, STRUCTURALLY_SINGULAR)


def mumps_error(code: int, detail: int, what: str) -> TmfemError:
    """The named error of a MUMPS failure other than a singular matrix: memory that ran
    out is a :class:`~tmfem.errors.ResourceLimit`, an option this MUMPS cannot honour (a
    working memory limit below the need, a parallel analysis it was not built with) an
    :class:`~tmfem.errors.InputError`, anything else a
    :class:`~tmfem.errors.ConvergenceError`."""
    cls = ResourceLimit if code in (-5, -7, -13) else InputError if code in (-19, -38) \
        else ConvergenceError
    return cls(f"{what}: expected the MUMPS factorisation to succeed, found {describe(code, detail)}")

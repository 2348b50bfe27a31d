"""``--exclude-uncontrollable`` of ``tmfem control hinf``, ``tmfem deploy`` and ``tmfem report``:
the H-infinity design (7.3) without the modes no tendon reaches (PBH, eq. 5.71), the choice a
system file makes with ``[control] uncontrollable = "exclude"`` (docs/guides/system-file.md).
The excluded modes stay open loop: the linear controller neither damps nor excites them.
"""
from __future__ import annotations

from tmfem.errors import InputError

#: the deployment controller whose switch is the H-infinity design of 7.3
#: (:data:`tmfem.reference.deployments.CONTROLLERS`)
HINF_SWITCH = "adaptive-hinf"


def add_uncontrollable_arg(parser, *, what: str) -> None:
    """The ``--exclude-uncontrollable`` flag; ``what``: the design it applies to."""
    parser.add_argument("--exclude-uncontrollable", action="store_true", default=None,
                        help=f"design {what} for the plant without the modes no tendon reaches (named "
                             "in the output; they stay open loop, neither damped nor excited by the "
                             "controller); default: the file's [control] uncontrollable, else refuse "
                             "such a plant naming the modes")


def with_uncontrollable(system, *, exclude: bool | None, controller: str):
    """``system`` with ``[control] uncontrollable = "exclude"`` when ``exclude``; refused for a
    deployment ``controller`` other than :data:`HINF_SWITCH` (no H-infinity design of 7.3 to
    leave the modes out of)."""
    if not exclude:
        return system
    if controller != HINF_SWITCH:
        raise InputError(f"--exclude-uncontrollable applies to the H-infinity switch of --controller "
                         f"{HINF_SWITCH}, found --controller {controller}")
    from tmfem.control.linear.deployed_design import with_uncontrollable as with_choice
    return with_choice(system, "exclude")


def excluded_text(frequencies_hz) -> str:
    """One line naming the excluded modes [Hz]."""
    return ("modes no tendon reaches, left out of the H-infinity switch (open loop, neither damped "
            "nor excited by it): " + ", ".join(f"{f:.4g} Hz" for f in frequencies_hz))

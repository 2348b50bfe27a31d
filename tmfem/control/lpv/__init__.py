"""Gridded linear parameter-varying control (dissertation ch. 8): the LPV plant on a grid,
state- and output-feedback synthesis with rate bounds, bounds, bisection, certificates,
off-grid verification, the gain-scheduled controller and the LPV deployment."""
from tmfem.control.lpv.gridded_synthesis import Basis, lpvsyn  # noqa: F401,E402  (the general gridded synthesis)

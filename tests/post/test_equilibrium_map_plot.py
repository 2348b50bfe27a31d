"""The drawn feasible region of an equilibrium map (tmfem.post.equilibrium_map) contains a
design that the equilibrium design of ch. 3 finds feasible, also where the region is thinner
than the map's grid step."""
import numpy as np

from tmfem.equilibrium import design_equilibrium
from tmfem.equilibrium.symmetric_map import equilibrium_map
from tmfem.post.equilibrium_map import _feasible_region, plot_equilibrium_map
from tmfem.system import load_preset


def test_the_2_3_design_lies_inside_the_drawn_region(tmp_path):
    s = load_preset("2-3")
    d = design_equilibrium(s)                  # source: the design is feasible (Delta = 1 mm > 0)
    assert d.ok and d.Delta > 0
    c = s.symmetric
    th0, ps0 = c.theta[0], c.psi[0] - c.sigma[0]
    # a 5 x 5 map whose rows straddle the design: the sampled booleans put the design (0.05 deg
    # above Delta = 0) in a cell with infeasible corners
    emap = equilibrium_map(s, theta=th0 + np.radians(np.linspace(-1.2, 1.0, 5)),
                           psi=ps0 + np.radians(np.linspace(-1.0, 1.2, 5)))
    r = np.searchsorted(emap.theta, th0)
    k = np.searchsorted(emap.psi, ps0)
    assert not emap.feasible[r - 1:r + 1, k - 1:k + 1].all()
    fps, fth, inside = _feasible_region(emap, refine=16)
    i = np.argmin(np.abs(fth - np.degrees(th0)))
    j = np.argmin(np.abs(fps - np.degrees(ps0)))
    assert inside[i, j] == 1.0
    assert 0 < inside.mean() < 1                  # both sides of the boundary are in the window
    assert plot_equilibrium_map(tmp_path / "m.png", emap, mark=(th0, ps0), detail=emap).stat().st_size > 0

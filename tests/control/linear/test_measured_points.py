"""The membrane points of the deployed plant's coordinates v (eq. 5.18) when the file gives
fewer than K: chosen inside the membrane, away from its edges and corners.

Reference: the distance of a point to the lines of the polygon's edges (n_j . (x - p_j) with
n_j the edge's unit normal), a formula independent of the segment distance the choice uses.
"""
from pathlib import Path

import numpy as np
import pytest

from tmfem.control.linear.generalized_plant import EDGE_CLEARANCE, deployed_plant, interior_nodes
from tmfem.system import load_system
from tmfem.system.presets import load_preset

SYSTEMS = Path(__file__).resolve().parents[2] / "data" / "systems"


def line_distances(corners, x):
    """(N,) distances of the point x to the lines through the edges of a convex polygon."""
    P = np.asarray(corners, dtype=float)
    E = np.roll(P, -1, axis=1) - P
    n = np.vstack([E[1], -E[0]]) / np.linalg.norm(E, axis=0)
    return np.abs(np.sum(n * (np.asarray(x, dtype=float)[:, None] - P), axis=0))


def test_interior_nodes_of_a_square_keep_the_clearance():
    """Unit square (inradius 0.5), clearance 0.25: the nodes of an 11 x 11 grid at least 0.125
    from every edge are the 7 x 7 inner ones (0.2 ... 0.8)."""
    g = np.linspace(0.0, 1.0, 11)
    X = np.array(np.meshgrid(g, g)).reshape(2, -1)
    idx = interior_nodes(X, np.array([[0, 1, 1, 0], [0, 0, 1, 1]]), clearance=0.25)
    assert len(idx) == 49
    assert np.all(X[:, idx] >= 0.2 - 1e-12) and np.all(X[:, idx] <= 0.8 + 1e-12)


@pytest.mark.parametrize("file", ["pentagon-1-5.toml", "kapton-1-4.toml"])
def test_default_points_lie_inside_away_from_edges(file):
    """A file without [control] or [monitor] points: every one of the K points of the plant is
    at least EDGE_CLEARANCE x the inradius from every edge (the greedy choice once took edge
    nodes of the 1-5), and T_v_eta of eq. 5.17 stays invertible (the plant builds)."""
    s = load_system(SYSTEMS / file)
    p = deployed_plant(s, membrane_modes=6)
    P = s.membrane_corners
    r_in = np.min(line_distances(P, P.mean(axis=1)))
    assert len(p.points) == 6
    for x in p.points:
        assert np.min(line_distances(P, x)) >= EDGE_CLEARANCE * r_in - 1e-9, x
    assert np.isfinite(p.model.T_veta_cond) and p.model.T_veta_cond < 1e6


@pytest.mark.slow
def test_presets_keep_the_points_of_their_plants():
    """1-6D and 2-3-deploy measure eq. 5.74/5.75's three points and complete K with the mesh
    nodes their file pins (`[control] coordinate_points`: edge nodes, as the greedy choice
    without clearance took them), so their plants (Tables 7.4-7.7, f_max of 7.4) are unchanged."""
    for name, K in (("1-6D", 5), ("2-3-deploy", 4)):
        s = load_preset(name)
        p = deployed_plant(s)
        c = s.problem.control
        assert len(p.points) == K
        assert np.allclose(p.points[3:], c.coordinate_points, atol=1e-12)
        assert np.min(line_distances(s.membrane_corners, p.points[-1])) < 1e-6

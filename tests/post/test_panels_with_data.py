"""The free-vibration plot (tmfem.post.plots.plot_free_vibration) draws a panel only where there
is something to show: a figure of n panels is 2.4 n + 0.8 in high at 120 dpi."""
from types import SimpleNamespace

import matplotlib.image as plt_image
import numpy as np

from tmfem.post.plots import plot_free_vibration

T = np.linspace(0.0, 2.0, 101)


def _result(nodes, n_w):
    z = np.stack([0.01 * np.sin(3 * T), 0.02 * np.sin(2 * T), 1e-3 * np.sin(T), 0.1 * np.sin(T)], axis=1)
    return SimpleNamespace(t=T, nodes=nodes, w=1e-3 * np.ones((T.size, n_w)), z=z,
                           columns=["t", "theta_11", "psi_11", "z_11", "eta_1"])


def _height(png):
    return plt_image.imread(str(png)).shape[0]


def test_free_vibration_panels_follow_the_monitored_points(tmp_path):
    node = {"B_11": 1e-3 * np.ones((T.size, 3))}
    cases = [(node, 2, 2),          # a node and the membrane deflections
             (node, 0, 1),          # no membrane points: no empty w panel
             ({}, 2, 1),            # no monitored node
             ({}, 0, 2)]            # neither: the angles and the positions of the bars
    for k, (nodes, n_w, panels) in enumerate(cases):
        png = plot_free_vibration(_result(nodes, n_w), tmp_path / f"v{k}.png", title="t")
        assert _height(png) == round((2.4 * panels + 0.8) * 120), (k, panels)

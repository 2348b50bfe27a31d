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


def test_many_bar_coordinates_keep_the_title_and_the_histories_in_view(tmp_path, monkeypatch):
    """A 1-7 system without monitored points plots its 14 bar angles: the legend stands beside
    the panel (it hides no history) and a long title is wrapped inside the figure."""
    import tmfem.post.plots as plots
    names = [f"{a}_1{j}" for j in range(1, 8) for a in ("theta", "psi")]
    z = 1e-3 * np.sin(np.outer(T, np.arange(1, 15)))
    res = SimpleNamespace(t=T, nodes={}, w=np.zeros((T.size, 0)), z=z, columns=["t"] + names)
    figs = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, png: figs.append(fig) or png)
    plot_free_vibration(res, tmp_path / "v.png", title="a-user-system COM free vibration, " * 3)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    fig = figs[0]
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    ax = fig.axes[0]
    renderer = canvas.get_renderer()
    legend, axes_box = ax.get_legend().get_window_extent(renderer), ax.get_window_extent(renderer)
    assert legend.x0 >= axes_box.x1                        # beside the panel, not over it
    title = ax.title.get_window_extent(renderer)
    assert 0 <= title.x0 and title.x1 <= fig.bbox.width and legend.x1 <= fig.bbox.width
    assert len({(line.get_color(), line.get_linestyle()) for line in ax.get_lines()}) == 14

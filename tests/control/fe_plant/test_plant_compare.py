"""One deployment on two plants (docs/guides/fe-plant.md): the deviation between the runs
(tmfem.control.fe_plant.compare) against its definition on synthetic records, and the layout of
the comparison plot (tmfem.post.plant_compare_plot)."""
from types import SimpleNamespace

import numpy as np
import pytest

from tmfem.control.fe_plant.compare import deviation_summary, plant_deviation
from tmfem.errors import InputError
from tmfem.post.plant_compare_plot import comparison_figure, switch_label_places

Q = ["theta_11", "psi_11", "theta_21", "psi_21"]


def _run(t_end, dq=0.0, dw=0.0, du=0.0, switch=None, dt=0.01):
    """A record of 2-3-like signals on [0, t_end]: q(t), q_d = q at dq = 0, three membrane
    points, two tendons and their forces; offsets dq(t), dw, du added to every signal."""
    t = np.arange(round(t_end / dt) + 1) * dt
    base = np.column_stack([1.4 - 0.4 * (1 - np.exp(-t / 5)), 2.27 + 0 * t, 1.4 + 0 * t, 0.17 + 0 * t])
    w = 1e-3 * np.column_stack([np.sin(2 * np.pi * k * t) for k in (1, 2, 3)])
    u = np.column_stack([0.62 + 0.02 * t, 0.5 + 0.034 * t])
    off = dq(t) if callable(dq) else np.full(t.size, dq)
    force = np.column_stack([20.0 + 2.0 * np.sin(3 * t), 8.0 + 0 * t])
    return SimpleNamespace(t=t, z=base + off[:, None], q_d=base, w=w + dw, u=u + du,
                           tendon_force=force,
                           names={"q": Q, "w": ["w_1", "w_2", "w_3"], "tendons": ["S_11", "P_21"]},
                           switch_time=switch, failure=None)


def test_plant_deviation_is_the_largest_difference_over_the_common_record():
    # run B: q off by 2 mrad * t / 2 s, w by 0.5 mm, u by 3 mm, and 0.5 s shorter; the
    # deviation is taken over B's 1.5 s: d_q(t) = 1e-3 t, largest 1.5 mrad at 1.5 s
    a = _run(2.0)
    b = _run(1.5, dq=lambda t: 1e-3 * t, dw=5e-4, du=3e-3)
    dev = plant_deviation(a, b)
    assert dev["t"][-1] == pytest.approx(1.5)
    assert np.allclose(dev["q"], 1e-3 * dev["t"], atol=1e-15)
    s = deviation_summary(dev)
    assert s["common_record_s"] == pytest.approx(1.5)
    assert s["max_bar_deviation_deg"] == pytest.approx(np.degrees(1.5e-3))
    assert s["max_bar_deviation_time_s"] == pytest.approx(1.5)
    assert s["bar_deviation_at_times_deg"]["1"] == pytest.approx(np.degrees(1e-3))
    assert "2" not in s["bar_deviation_at_times_deg"]
    assert s["max_membrane_deflection_deviation_m"] == pytest.approx(5e-4)
    assert s["max_rest_length_deviation_m"] == pytest.approx(3e-3)
    assert np.isnan(dev["bases"]).all() and "max_base_deviation_m" not in s
    c = _run(1.0)
    c.names = {**c.names, "q": Q[::-1]}
    with pytest.raises(InputError, match="expected two runs of one deployment"):
        plant_deviation(a, c)


def test_bar_angles_and_base_positions_deviate_apart():
    # a base position 5 mm off and the angles 1 mrad: the angle deviation is 1 mrad, the base
    # one 5 mm -- not max(1e-3 rad, 5e-3 m) (radians against metres) as one maximum over q
    a, b = _run(1.0), _run(1.0, dq=1e-3)
    for r in (a, b):
        r.names = {**r.names, "q": ["theta_11", "psi_11", "x_21", "theta_21"]}
    b.z[:, 2] = a.z[:, 2] + 5e-3
    dev = plant_deviation(a, b)
    assert np.allclose(dev["q"], 1e-3) and np.allclose(dev["bases"], 5e-3)
    s = deviation_summary(dev)
    assert s["max_bar_deviation_deg"] == pytest.approx(np.degrees(1e-3))
    assert s["max_base_deviation_m"] == pytest.approx(5e-3)
    assert s["base_deviation_at_times_m"]["0.3"] == pytest.approx(5e-3)


@pytest.mark.parametrize("switches", [(17.33, 17.46), (17.46, 17.33), (2.0, 2.1), (5.0, 15.0)])
def test_switch_labels_do_not_overlap_and_stay_inside_the_axes(switches):
    """Two switches 0.13 s apart over 20 s (the SBC and COM runs of the 2-3 deployment,
    docs/guides/fe-plant.md), either order, near the start, or far apart: the rendered labels are
    disjoint and inside the top panel."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    a, b = _run(20.0, switch=switches[0]), _run(20.0, dq=1e-3, dw=1e-4, switch=switches[1])
    fig = comparison_figure(a, b, plant_deviation(a, b), labels=("sbc", "com"), title="x\ny")
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    ax = fig.axes[0]
    r = canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t in ax.texts if t.get_text().startswith("switch")]
    assert len(boxes) == 2
    assert not boxes[0].overlaps(boxes[1])
    frame = ax.get_window_extent(r)
    for bb in boxes:
        assert frame.x0 <= bb.x0 and bb.x1 <= frame.x1 and frame.y0 <= bb.y0 and bb.y1 <= frame.y1


def test_legends_hide_no_data_and_stay_inside_the_figure():
    """The attitudes of the 2-3 runs (80 -> 57 deg, 130 deg, 10 deg; the legend of the top
    panel covered the 130 deg line, docs/guides/fe-plant.md): rendered, no legend box contains a
    point of any plotted line of the figure, and every legend lies inside the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    a, b = _run(20.0, switch=17.33), _run(20.0, dq=1e-3, dw=1e-4, switch=17.46)
    fig = comparison_figure(a, b, plant_deviation(a, b), labels=("sbc", "com"), title="x\ny")
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    legends = [x.get_legend() for x in fig.axes if x.get_legend() is not None]
    assert len(legends) == 7    # attitudes, errors, w, rest lengths, forces, the two deviations
    points = np.vstack([line.get_transform().transform(line.get_xydata())
                        for x in fig.axes for line in x.get_lines() if len(line.get_xydata())])
    assert len(points) > 10 * a.t.size
    frame = fig.bbox
    for leg in legends:
        bb = leg.get_window_extent(r)
        inside = ((points[:, 0] >= bb.x0) & (points[:, 0] <= bb.x1)
                  & (points[:, 1] >= bb.y0) & (points[:, 1] <= bb.y1))
        assert not inside.any(), (leg.get_texts()[0].get_text(), points[inside][:3])
        assert frame.x0 <= bb.x0 and bb.x1 <= frame.x1 and frame.y0 <= bb.y0 and bb.y1 <= frame.y1


def test_switch_label_places_stack_close_switches_only():
    # same side and within 20 % of the span: one above the other; far apart: the same height
    assert switch_label_places([17.33, 17.46], 20.0) == [(0.02, "right"), (0.11, "right")]
    assert switch_label_places([5.0, 15.0], 20.0) == [(0.02, "left"), (0.02, "right")]

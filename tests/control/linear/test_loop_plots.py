"""The closed-loop analysis figure of `tmfem control hinf --plot`: a synthesis route that was
refused is said so inside its panel, whatever the scale of the gamma bars."""
import warnings
from types import SimpleNamespace

from matplotlib.backends.backend_agg import FigureCanvasAgg

from tmfem.control.linear.loop_plots import _routes
from tmfem.post.plots import new_figure


def test_a_refused_route_is_written_inside_the_panel_and_the_layout_holds():
    """Routes at gamma 0.5 (the feedthrough bound) and one refused: the bars' panel spans
    0.49-0.51, and the refusal's text stands at its foot, not at gamma = 0 far below it
    (which collapsed the constrained layout of the whole figure)."""
    fig = new_figure(figsize=(6, 4))
    a = fig.subplots()
    routes = {"riccati": (0.5005, 0.5), "lmi": "the LMI of eq. 5.67 has no solution at this size",
              "slicot": (0.5, 0.5)}
    _routes(a, routes, SimpleNamespace(gamma=0.5005), 0.5, True)
    canvas = FigureCanvasAgg(fig)
    with warnings.catch_warnings():
        warnings.simplefilter("error")       # "constrained_layout not applied ..." is a UserWarning
        canvas.draw()
    box = a.get_window_extent(canvas.get_renderer())
    (text,) = [t for t in a.texts if t.get_text().startswith("refused")]
    tb = text.get_window_extent(canvas.get_renderer())
    assert box.y0 <= tb.y0 and tb.y1 <= box.y1

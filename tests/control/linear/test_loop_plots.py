"""The closed-loop analysis figure of `tmfem control hinf --plot`: a synthesis route that was
refused is said so inside its panel, whatever the scale of the gamma bars; the regulation
panel is the closed loop released from an offset of each tracked coordinate."""
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
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


def oscillator_of_figure_7_1(*, W_e=0.5, W_d=1e-3, u_m=0.1):
    """A 1-DOF undamped oscillator x'' = -4 x + u in the form of Fig. 7.1: w = [ref_x, n_x,
    n_xd], p = [ed_x = W_e (ref_x - x), eu_r = u / u_m], y = [x + W_d n_x - ref_x, xd + W_d n_xd]."""
    from tmfem.control.linear.partitioned_plant import GeneralizedPlant
    return GeneralizedPlant(
        A=np.array([[0.0, 1.0], [-4.0, 0.0]]), B1=np.zeros((2, 3)), B2=np.array([[0.0], [1.0]]),
        C1=np.array([[-W_e, 0.0], [0.0, 0.0]]), C2=np.eye(2),
        D11=np.array([[W_e, 0, 0], [0, 0, 0]]), D12=np.array([[0.0], [1 / u_m]]),
        D21=np.array([[-1.0, W_d, 0], [0, 0, W_d]]), D22=np.zeros((2, 1)),
        state_names=["x", "xd"], w_names=["ref_x", "n_x", "n_xd"], u_names=["r"],
        p_names=["ed_x", "eu_r"], y_names=["y_x", "y_xd"])


def test_regulation_panel_is_the_closed_loop_released_from_an_offset(tmp_path):
    """The lower-left panel of `control hinf --plot`: the tracked coordinate x released from
    x(0) = 1 with the controller at rest, equal to the first state of expm(A_cl t) [1, 0, 0..]
    (A_cl assembled by hand from the plant and the controller, independent of python-control's
    interconnect), never a panel of zeros, with the envelope exp(-alpha_1 t) drawn; the
    reference step that panel used to show is zero for this design class (the controller
    leaves x at rest: ed_x = W_e ref_x)."""
    import control
    from scipy.linalg import expm
    from tmfem.control.linear.hinf_synthesis import hinfsyn
    from tmfem.control.linear.loop_plots import _regulation, plot_design
    P = oscillator_of_figure_7_1()
    alpha = 0.5
    d = hinfsyn(P, 2, 1, alpha=alpha).design
    K = d.controller
    Acl = np.block([[P.A + P.B2 @ K.D @ P.C2, P.B2 @ K.C], [K.B @ P.C2, K.A]])
    fig = new_figure(figsize=(6, 4))
    a = fig.subplots()
    _regulation(a, d.closed_loop, d)
    lines = {ln.get_label(): ln for ln in a.get_lines()}
    line = lines["x released from x(0) = 1"]
    t, s = line.get_xdata(), line.get_ydata()
    x0 = np.zeros(Acl.shape[0])
    x0[0] = 1.0
    ref = np.array([(expm(Acl * tk) @ x0)[0] for tk in t[::100]])
    assert s[::100] == pytest.approx(ref, abs=1e-6)
    assert np.max(np.abs(s)) == pytest.approx(1.0) and abs(s[-1]) < 1e-2
    env = lines[f"+- exp(-alpha_1 t), alpha_1 = {alpha:g} 1/s"]
    assert env.get_ydata() == pytest.approx(np.exp(-alpha * t))
    assert a.get_xlabel() == "t [s]" and "[-]" in a.get_ylabel()
    step = control.step_response(d.closed_loop[0, 0], T=t)        # ref_x -> ed_x
    assert np.squeeze(step.outputs) == pytest.approx(0.5, abs=1e-6)  # x stays at 0
    plot_design(d, open_loop=P, path=tmp_path / "loop.png")
    assert (tmp_path / "loop.png").stat().st_size > 10_000


def test_poles_panel_is_linear_with_ticks_when_the_poles_lie_within_one_per_second():
    """A lightly damped structure with alpha_1 = 0.2 1/s puts every pole within |Re s| < 1, the
    linear part of a symlog axis, which then carries only its two end ticks (-8.7e-1 and
    4.2e-2 on an eight-bar system): the axis is linear there with readable ticks, and symlog
    only when the real parts span decades (beyond 10 1/s)."""
    from tmfem.control.linear.loop_plots import _poles
    pol = np.array([0.0 + 2.0j, 0.0 - 2.0j, 0.0 + 80.0j, 0.0 - 80.0j])
    pcl = np.array([-0.87 + 10j, -0.87 - 10j, -0.4 + 40j, -0.4 - 40j])
    fig = new_figure(figsize=(6, 4))
    a = fig.subplots()
    _poles(a, pol, pcl, 0.2)
    FigureCanvasAgg(fig).draw()
    assert a.get_xscale() == "linear"
    lo, hi = a.get_xlim()
    ticks = [t for t in a.get_xticks() if lo <= t <= hi]
    assert len(ticks) >= 3
    assert "Re s = -alpha_1 = -0.2 1/s" in [ln.get_label() for ln in a.get_lines()]
    fig = new_figure(figsize=(6, 4))
    a = fig.subplots()
    _poles(a, pol, np.array([-250.0 + 1j, -250.0 - 1j, -0.4 + 40j, -0.4 - 40j]), 0.2)
    assert a.get_xscale() == "symlog"


def test_a_refusal_is_wrapped_at_words_and_shortened_visibly():
    """The refusal of a 90-state plant by the LMI route was cut every 28 characters ("90 state"
    / "s by the lmi route") and after 112 characters without a mark: the text is broken at word
    boundaries only, at most six lines, and a shortened one ends in "..."."""
    from tmfem.control.linear.loop_plots import _wrapped
    msg = ("hinfsyn: a plant of 90 states by the lmi route: the LMI synthesis (an SDP in two n x n "
           "symmetric unknowns) needs about 16 GiB, expected at most 40 states for this route; use "
           "--method riccati or --method slicot, which take any size")
    out = _wrapped(msg)
    rows = out.split("\n")
    assert len(rows) == 6 and all(len(r) <= 30 for r in rows)
    assert out.endswith("...")
    words = set(msg.split())
    assert all(w in words for w in " ".join(rows)[:-4].split())      # no word cut in two
    assert _wrapped("Solver 'CLARABEL' failed.") == "Solver 'CLARABEL' failed."


def test_the_route_comparison_leaves_out_a_route_beyond_its_budget():
    """`control hinf --plot` compares the synthesis routes on the design's plant; the LMI route
    grows as n^5.5 (tmfem.resources.synthesis_seconds: 2.2 s at 20 states, about a minute at
    36), so the figure leaves out a route whose estimate exceeds the budget and says so, and
    runs the others (on the oscillator the Riccati route reaches the feedthrough bound W_e = 0.5
    times (1 + 0.0005)^2: the bisection's margin and the central controller's)."""
    from tmfem.control.linear.loop_plots import route_levels
    from tmfem.resources import synthesis_seconds
    P = oscillator_of_figure_7_1()
    t_lmi = synthesis_seconds(route="lmi", n=2)
    out = route_levels(P, alpha=0.5, routes=("lmi",), budget_s=0.5 * t_lmi)
    assert out["lmi"].startswith("not run for this figure") and "2 states" in out["lmi"]
    gamma, norm = route_levels(P, alpha=0.5, routes=("riccati",))["riccati"]
    assert gamma == pytest.approx(0.5 * 1.0005 ** 2, rel=1e-6) and norm <= gamma
    assert synthesis_seconds(route="lmi", n=36) > 10.0 > synthesis_seconds(route="lmi", n=20)


def test_the_route_comparison_takes_the_design_s_own_route_as_it_is(tmp_path, monkeypatch):
    """`control hinf --plot` (method auto) designed with hinfsyn's Riccati route and then ran
    that route again for the comparison panel (13 s more on a 90-state 2-6): the design's
    own route enters the panel with its gamma and verified norm, the others are synthesised."""
    from tmfem.control.linear import loop_plots
    from tmfem.control.linear.hinf_synthesis import hinfsyn
    P = oscillator_of_figure_7_1()
    res = hinfsyn(P, 2, 1, alpha=0.5)
    d = res.design
    d.info["route"] = {"method": res.info["method"]}
    called = []
    real = loop_plots.hinfsyn
    monkeypatch.setattr(loop_plots, "hinfsyn",
                        lambda *a, method, **k: called.append(method) or real(*a, method=method, **k))
    routes = loop_plots.route_levels(P, alpha=0.5, known=loop_plots._own_route(d))
    assert res.info["method"] not in called and called
    assert routes[res.info["method"]] == (pytest.approx(res.gamma), pytest.approx(res.info["verified_norm"]))
    assert loop_plots._own_route(SimpleNamespace(info={}, gamma=1.0, closed_loop_norm=0.5)) == {}

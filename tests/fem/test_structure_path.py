"""Path following of a structure: load control, displacement control and arc length
(tmfem.solvers.continuation, tmfem.fem.structure.path).

Sources: the total-Lagrangian two-bar (von Mises) truss, P(w) = (EA / L0^3)(b - w)(2 b w - w^2)
(benchmarks.json von_mises_truss_formulas; tmfem.reference.element_benchmarks.arch_load_green),
its tangent dP/dw (negative between the two limit points: one negative pivot there under
load control), and the same truss in series with a soft bar (a spring) loaded at the
spring's top: the top displacement v = w + (spring shortening) snaps back when the spring
is softer than -min dP/dw = EA b^2 / L0^3 (equilibrium of the spring with the truss: the
spring force from its own Green strain equals P(w)).
"""
import numpy as np
import pytest

from tmfem.fem.structure import Structure
from tmfem.fem.truss import TrussElement, TrussSet
from tmfem.reference.element_benchmarks import arch_load_green

A, B, EA = 1.0, 0.5, 1.0
LS, EAS = 10.0, 0.5                  # spring: k = EAS / LS = 0.05 < EA B^2 / L0^3 = 0.179
L0 = np.hypot(A, B)


def arch(spring=False):
    """Supports at (-A, 0, 0) and (A, 0, 0), apex (0, 0, B); with ``spring`` a bar of length LS
    on top of the apex. A unit downward load on the top node (the apex without spring)."""
    pts = [[-A, 0, 0], [A, 0, 0], [0, 0, B]] + ([[0, 0, B + LS]] if spring else [])
    s = Structure(points=np.array(pts, float).T, dofs=3)
    conn = [[0, 1], [2, 2]] if not spring else [[0, 1, 2], [2, 2, 3]]
    L = [L0, L0] + ([LS] if spring else [])
    ea = [EA, EA] + ([EAS] if spring else [])
    s.add(TrussElement(TrussSet(conn=np.array(conn), L=np.array(L), EA=np.array(ea), rhoA=np.zeros(len(L)),
                                tension_only=np.zeros(len(L), bool)), s.dofmap))
    s.fix([0, 1])
    top = 3 if spring else 2
    s.fix([2] + ([3] if spring else []), ["ux", "uy"])
    s.point_load([top], force=(0, 0, -1.0))
    return s, top


def _w(s, st, node=2):
    return -(st.x[2, node] - s.X[2, node])


def test_arc_length_through_the_limit_points_of_the_two_bar_truss():
    s, _ = arch()
    path = s.solve_arc_length(dl=0.02, max_steps=400, stop=lambda st, lam: st.x[2, 2] < -1.2 * B)
    assert path.reason == "stopped", path.message
    w = np.array([_w(s, st) for st in path])
    P = path.lam
    np.testing.assert_allclose(P, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)
    assert np.all(np.diff(w) > 0)                                     # never retraces
    assert [e for _, e in path.events] == ["limit point", "limit point"]
    # one negative pivot exactly where dP/dw < 0 (between the limit points)
    slope = np.gradient(arch_load_green(w, a=A, b=B, EA=EA), w)
    piv = np.array([st.negative_pivots for st in path])
    assert np.all(piv[slope < -1e-3] == 1) and np.all(piv[slope > 1e-3] == 0)
    assert np.all(path.iterations[1:] <= 6) and np.all(path.residuals[1:] <= 1e-8 * 1.0)


def test_arc_length_through_a_snap_back():
    s, top = arch(spring=True)
    path = s.solve_arc_length(dl=0.05, max_steps=600, stop=lambda st, lam: st.x[2, 2] < -1.2 * B)
    assert path.reason == "stopped", path.message
    w = np.array([_w(s, st) for st in path])
    v = np.array([_w(s, st, top) for st in path])
    P = path.lam
    np.testing.assert_allclose(P, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)
    l = LS - (v - w)                                                  # spring length
    np.testing.assert_allclose(P, EAS * (LS**2 - l**2) / (2 * LS**2) * l / LS, atol=1e-7)
    assert np.all(np.diff(w) > 0)
    dv = np.diff(v)
    assert np.sum(np.diff(np.sign(dv[np.abs(dv) > 1e-9])) != 0) == 2  # v turns twice: snap-back


def test_load_control_stops_at_the_limit_point_and_arc_length_continues():
    s, _ = arch()
    P_max = arch_load_green(B * (1 - 1 / np.sqrt(3)), a=A, b=B, EA=EA)
    path = s.solve(steps=20, lam_end=1.2 * P_max, min_step=1e-3)
    assert path.reason == "limit point" and not path.completed
    assert 0.95 * P_max < path.lam[-1] <= P_max
    w = np.array([_w(s, st) for st in path])
    np.testing.assert_allclose(path.lam, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)
    on = s.solve_arc_length(start=path, dl=0.02, lam_max=2 * P_max, max_steps=400)
    assert on.reason == "completed" and on.lam[-1] >= 2 * P_max
    w2 = np.array([_w(s, st) for st in on])
    assert w2[0] == w[-1] and np.all(np.diff(w2) > 0)
    np.testing.assert_allclose(on.lam, arch_load_green(w2, a=A, b=B, EA=EA), atol=1e-7)


def test_a_stopped_run_is_resumed_on_the_same_path():
    s, _ = arch()
    short = s.solve_arc_length(dl=0.02, max_steps=15)
    assert short.reason == "budget" and len(short) == 16
    whole = s.resume(short, max_steps=300, stop=lambda st, lam: st.x[2, 2] < -1.2 * B)
    assert whole.reason == "stopped" and whole[:16] == list(short)
    w = np.array([_w(s, st) for st in whole])
    assert np.all(np.diff(w) > 0)
    np.testing.assert_allclose(whole.lam, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)


def test_displacement_control_through_the_limit_point():
    s, _ = arch()
    path = s.solve_displacement_control(node=2, dof="uz", increment=-0.03, target=-2.2 * B)
    assert path.reason == "completed"
    w = np.array([_w(s, st) for st in path])
    assert w[-1] == pytest.approx(2.2 * B, abs=1e-12)
    np.testing.assert_allclose(path.lam, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)
    assert [e for _, e in path.events] == ["limit point", "limit point"]
    # resumed from a shorter run, the target is the same displacement
    short = s.solve_displacement_control(node=2, dof="uz", increment=-0.03, target=-2.2 * B, max_steps=5)
    assert short.reason == "budget"
    whole = s.resume(short, max_steps=100)
    assert _w(s, whole[-1]) == pytest.approx(2.2 * B, abs=1e-12) and whole.reason == "completed"


def test_load_control_that_jumps_a_snap_through_stops_at_the_limit_point():
    # five load steps of 0.24 P_max to 1.2 P_max: the fifth converges on the inverted branch
    s, _ = arch()
    P_max = arch_load_green(B * (1 - 1 / np.sqrt(3)), a=A, b=B, EA=EA)
    path = s.solve(steps=5, lam_end=1.2 * P_max)
    assert path.reason == "limit point" and "solve_arc_length" in path.message
    assert path.lam[-1] == pytest.approx(0.96 * P_max)            # the last step below P_max
    w = np.array([_w(s, st) for st in path])
    assert np.all(w < B * (1 - 1 / np.sqrt(3)))                    # all on the first stable branch
    np.testing.assert_allclose(path.lam, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)
    # kept with on_snap="mark": the jumped state is on the far stable branch (w > b (1 + 1/sqrt 3))
    marked = s.solve(steps=5, lam_end=1.2 * P_max, on_snap="mark")
    assert marked.reason == "completed" and marked.events == [(5, "snap-through")]
    w_far = _w(s, marked[5])
    assert w_far > B * (1 + 1 / np.sqrt(3))
    assert marked.lam[5] == pytest.approx(arch_load_green(w_far, a=A, b=B, EA=EA), abs=1e-7)
    # a smooth load-controlled path below the limit point raises no event
    below = s.solve(steps=5, lam_end=0.9 * P_max)
    assert below.reason == "completed" and below.events == []


def test_load_control_that_jumps_a_snap_through_resumes_by_arc_length():
    s, _ = arch()
    P_max = arch_load_green(B * (1 - 1 / np.sqrt(3)), a=A, b=B, EA=EA)
    path = s.solve(steps=5, lam_end=1.2 * P_max)
    on = s.solve_arc_length(start=path, dl=0.02, max_steps=400, stop=lambda st, lam: st.x[2, 2] < -1.2 * B)
    assert on.reason == "stopped"
    w = np.array([_w(s, st) for st in on])
    assert np.all(np.diff(w) > 0) and on.lam[w < B].max() == pytest.approx(P_max, rel=5e-3)
    assert w[-1] > B * (1 + 1 / np.sqrt(3))                       # past the limit points
    np.testing.assert_allclose(on.lam, arch_load_green(w, a=A, b=B, EA=EA), atol=1e-7)


def test_load_control_refuses_bad_snap_controls():
    from tmfem.errors import InputError
    s, _ = arch()
    with pytest.raises(InputError, match="on_snap"):
        s.solve(on_snap="ignore")
    for bad in (0.5, "large", float("nan")):
        with pytest.raises(InputError, match="snap_ratio"):
            s.solve(snap_ratio=bad)

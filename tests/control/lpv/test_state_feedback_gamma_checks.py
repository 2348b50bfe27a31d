"""The pointwise state-feedback optimum of the LPV bounds (``state_feedback_gamma`` through
:func:`tmfem.control.lpv.bounds.pointwise_state_feedback_bound`) checked independently.

References, on the frozen plants of the oscillator interconnection (Fig. 8.1):
* the LTI state-feedback optimum of :func:`tmfem.control.hinfsyn_state` at each grid point by
  its two routes: the LMI route (Clarabel SDP, a formulation independent of the Riccati test
  the bound uses) and the verified Riccati bisection, whose certified lower bound the bound
  may not undercut;
* the closed loops of the gains: the bound's own gain at the worst point and the LPV design's
  gains K(rho_i), whose frozen closed-loop norms (python-control ``norm``, SLICOT AB13DD) lie
  between the pointwise optimum and the design's certified gamma;
* a time simulation of the worst frozen loop driven at its peak frequency: the steady
  output-to-input amplitude ratio approaches the frozen norm from below.
"""
import control
import numpy as np
import pytest

from tests.control.lpv.test_lpv_controller import oscillator
from tmfem.control import hinfsyn_state
from tmfem.control.lpv.bounds import pointwise_state_feedback_bound
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback


@pytest.fixture(scope="module")
def oscillator_design():
    gp = interconnection_8_1(oscillator(), tracked=["x"])
    return gp, pointwise_state_feedback_bound(gp), synthesize_state_feedback(gp)


def _frozen(gp, i):
    """The frozen plant at grid point i: inputs [w, u], outputs p."""
    return control.ss(gp.A[i], np.hstack([gp.B1[i], gp.B2[i]]), gp.C1[i], np.hstack([gp.D11[i], gp.D12[i]]))


def test_pointwise_gamma_equals_the_lti_state_feedback_optimum(oscillator_design):
    gp, b, _ = oscillator_design
    nu = gp.B2.shape[-1]
    for i in range(gp.grid_shape[0]):
        P = _frozen(gp, i)
        lmi = hinfsyn_state(P, nu, method="lmi")
        ric = hinfsyn_state(P, nu, method="riccati")
        # never below the certified lower bound; equal to the SDP's level within the LMI
        # route's relaxation (gamma_tol 1e-3) and the bound's bisection (rtol 1e-5)
        assert b.gamma[i] >= ric.info["gamma_lower"] * (1 - 1e-9)
        assert b.gamma[i] == pytest.approx(lmi.info["verified_norm"], rel=2e-3)
        assert b.gamma[i] <= lmi.gamma * (1 + 1e-5)


def test_gains_bracket_the_pointwise_gamma(oscillator_design):
    gp, b, design = oscillator_design
    k = int(np.argmax(b.gamma))
    # the bound's gain designed at 1.01 x the bound at the worst point
    assert b.gamma[k] <= b.achieved_norm <= 1.01 * b.gamma[k] * (1 + 1e-9)
    for i, rho in enumerate(gp.axes[0]):
        K = design.gain([rho])
        T = control.ss(gp.A[i] + gp.B2[i] @ K, gp.B1[i], gp.C1[i] + gp.D12[i] @ K, gp.D11[i])
        assert np.max(T.poles().real) < 0
        nrm = float(control.norm(T, p="inf"))
        # no static gain beats the frozen optimum; the LPV level covers every frozen loop
        assert b.gamma[i] * (1 - 1e-5) <= nrm <= design.gamma * (1 + 1e-6)


def test_simulated_worst_frozen_loop_stays_below_its_norm(oscillator_design):
    gp, b, design = oscillator_design
    k = int(np.argmax(b.gamma))
    K = design.gain([gp.axes[0][k]])
    T = control.ss(gp.A[k] + gp.B2[k] @ K, gp.B1[k], gp.C1[k] + gp.D12[k] @ K, gp.D11[k])
    nrm = float(control.norm(T, p="inf"))
    # the input direction and frequency of the peak
    w = np.logspace(-3, 3, 2000)
    H = T(1j * w)                                      # (p, w, frequencies)
    sv = [np.linalg.svd(H[:, :, j]) for j in range(w.size)]
    j = int(np.argmax([s[1][0] for s in sv]))
    v = sv[j][2][0].conj()
    wk = w[j]
    period = 2 * np.pi / wk
    t = np.linspace(0, 60 * period, 6000 * 4)
    # a real input with the peak direction's magnitudes and phases
    u = np.abs(v)[:, None] * np.cos(wk * t[None, :] + np.angle(v)[:, None])
    y = control.forced_response(T, T=t, U=u).outputs
    y = np.atleast_2d(y)
    tail = t >= t[-1] - 10 * period                    # steady state
    ratio = np.sqrt(np.mean(np.sum(y[:, tail] ** 2, axis=0)) / np.mean(np.sum(u[:, tail] ** 2, axis=0)))
    assert ratio <= nrm * (1 + 1e-3)
    assert ratio >= 0.5 * nrm                          # a real input reaches at least half the peak gain

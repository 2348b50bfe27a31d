"""The regression family of H-infinity plants (shared by the tests and benchmarks/bench_hinf.py).

Random plants of several sizes and kinds, textbook plants with a closed-form optimum, a
published mixed-sensitivity design and its near-integrating and ill-conditioned variants, and
COMPleib plants (regular and singular). Each entry: name -> (python-control StateSpace with
inputs [w, u] and outputs [p, y], nmeas, ncon, reference gamma or None). A reference is given
where it is known independently of tmfem (closed form or publication); otherwise the
reference is the LMI optimum computed by the test.
"""
from __future__ import annotations

import control
import numpy as np

from tests.data.compleib import compleib


def random_plant(seed: int, n: int, *, nw: int = 3, nu: int = 2, np_: int = 4, ny: int = 2,
                 kind: str = "regular"):
    """A random generalised plant (StateSpace, inputs [w, u], outputs [p, y]).

    kind: "regular" (D12 = [0; I], D21 = [0, I], D11 = 0), "d11" (D11 != 0), "singular_d12"
    (D12 = 0), "singular_d21" (D21 = 0), "badly_scaled" (states scaled by 1e-3 .. 1e3),
    "near_integrator" (an extra weight state with pole -2.5e-5 on the first performance
    output), "unstable" (several modes in the right half plane).
    """
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    shift = 2.0 if kind == "unstable" else 0.3
    A -= (np.sort(np.linalg.eigvals(A).real)[-min(n, 3 if kind == "unstable" else 1)] - shift) * np.eye(n)
    B1 = rng.standard_normal((n, nw))
    B2 = rng.standard_normal((n, nu))
    C1 = np.vstack([rng.standard_normal((np_ - nu, n)), np.zeros((nu, n))])
    C2 = rng.standard_normal((ny, n))
    D11 = np.zeros((np_, nw))
    D12 = np.vstack([np.zeros((np_ - nu, nu)), np.eye(nu)])
    D21 = np.hstack([np.zeros((ny, nw - ny)), np.eye(ny)])
    if kind == "d11":
        D11 = 0.5 * rng.standard_normal((np_, nw))
    elif kind == "singular_d12":
        C1 = rng.standard_normal((np_, n))
        D12 = np.zeros((np_, nu))
    elif kind == "singular_d21":
        D21 = np.zeros((ny, nw))
    elif kind == "badly_scaled":
        t = np.logspace(-3, 3, n)
        A, B1, B2 = A * t[None, :] / t[:, None], B1 / t[:, None], B2 / t[:, None]
        C1, C2 = C1 * t[None, :], C2 * t[None, :]
    elif kind == "near_integrator":
        # x_w' = -2.5e-5 x_w + C1[0] x, p_0 = x_w: an integrating performance weight
        A = np.block([[A, np.zeros((n, 1))], [C1[:1], -2.5e-5 * np.ones((1, 1))]])
        B1, B2 = np.vstack([B1, np.zeros((1, nw))]), np.vstack([B2, np.zeros((1, nu))])
        C1 = np.hstack([C1, np.zeros((np_, 1))])
        C1[0] = 0.0
        C1[0, -1] = 1.0
        C2 = np.hstack([C2, np.zeros((ny, 1))])
    elif kind != "regular" and kind != "unstable":
        raise ValueError(kind)
    return control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]),
                      np.block([[D11, D12], [D21, np.zeros((ny, nu))]]))


def first_order(a: float):
    """x' = a x + w1 + u, p = [x; u], y = x + w2 (Zhou, Doyle & Glover, Robust and Optimal
    Control, 1996, Thm. 16.4 with n = 1).

    X and Y solve 2 a X + (gamma^-2 - 1) X^2 + 1 = 0 (the same scalar equation), so
    X = Y = (a + sqrt(a^2 + 1 - gamma^-2)) / (1 - gamma^-2), and the coupling condition
    rho(X Y) = X^2 < gamma^2 becomes X(gamma) < gamma. At the optimum X = gamma:
    (gamma - 1/gamma - a)^2 = a^2 + 1 - gamma^-2, i.e. (gamma^2 - 1)(gamma^2 - 2 a gamma - 2)
    = 0, so gamma_opt = a + sqrt(a^2 + 2) (sqrt 2 for the integrator a = 0).
    """
    P = control.ss([[a]], [[1.0, 0.0, 1.0]], [[1.0], [0.0], [1.0]],
                   [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    return P, 1, 1, a + np.sqrt(a * a + 2.0)


def first_order_state_feedback(a: float):
    """x' = a x + w + u, p = [x; u], u = k x (state feedback). T_pw = [1; k] / (s - a - k):
    ||T||_inf = sqrt(1 + k^2) / |a + k| at omega = 0 for a stable loop (k < -a). For a < 0
    the minimum over k is at k = 1/a: gamma_opt = 1 / sqrt(1 + a^2); for a >= 0 the norm
    decreases to 1 as k -> -inf: gamma_opt = 1 (an infimum, not attained)."""
    P = control.ss([[a]], [[1.0, 1.0]], [[1.0], [0.0]], [[0.0, 0.0], [0.0, 1.0]])
    return P, 1, 1.0 / np.sqrt(1.0 + a * a) if a < 0 else 1.0


def skogestad_postlethwaite_2_17(design: int):
    """S/KS mixed-sensitivity design of Skogestad & Postlethwaite, Multivariable Feedback
    Control, 2nd ed. (2005), Example 2.17 (1st ed. Example 2.11): G = 200 / ((10 s + 1)
    (0.05 s + 1)^2), W_u = 1, design 1: W_p = (s/M + w_B) / (s + w_B A), design 2: W_p =
    (s/sqrt(M) + w_B)^2 / (s + w_B sqrt(A))^2, M = 1.5, w_B = 10, A = 1e-4 (weights as in
    the book's script Expl2_17.m). Printed optimal H-infinity norms: 1.37 and 2.21.
    The weight of design 1 has its pole at -1e-3: a near-integrating weight."""
    s = control.tf("s")
    G = 200 / ((10 * s + 1) * (0.05 * s + 1) ** 2)
    M, wb, A = 1.5, 10.0, 1e-4
    Wp = (s / M + wb) / (s + wb * A) if design == 1 else \
        (s / np.sqrt(M) + wb) ** 2 / (s + wb * np.sqrt(A)) ** 2
    P = control.augw(control.ss(G), w1=control.ss(Wp), w2=control.ss(control.tf(1, 1)))
    return P, 1, 1, {1: 1.37, 2: 2.21}[design]


def compleib_plant(name: str):
    """A COMPleib example (tests/data/compleib.py: F. Leibfritz, COMPleib 1.1, 2005) as a
    generalised plant; no reference gamma (the optimum is bracketed by the test)."""
    A, B1, B2, C1, C2, D11, D12, D21 = compleib(name)
    ny, nu = C2.shape[0], B2.shape[1]
    P = control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]),
                   np.block([[D11, D12], [D21, np.zeros((ny, nu))]]))
    return P, ny, nu, None


def near_integrating_mixed_sensitivity(A_w: float, W_u: float):
    """The S/KS design of :func:`skogestad_postlethwaite_2_17` (design 1) with the weight's
    pole moved to -w_B A_w and the input weight W_u: A_w = 1e-6 puts the pole at -1e-5 (a
    near-integrating weight, the Riccati test meets Hamiltonian eigenvalues within 1e-5 of
    the imaginary axis; the LMI solution of this plant is inaccurate), W_u = 0.01 makes the
    plant ill-conditioned (Lyapunov matrices with entries of 1e8: a trace penalty of 1e-4 on
    them gives a controller 18 times above the optimum). No reference gamma."""
    s = control.tf("s")
    G = 200 / ((10 * s + 1) * (0.05 * s + 1) ** 2)
    Wp = (s / 1.5 + 10.0) / (s + 10.0 * A_w)
    P = control.augw(control.ss(G), w1=control.ss(Wp), w2=control.ss(control.tf(W_u, 1)))
    return P, 1, 1, None


#: COMPleib members (regular: AC4; D21 = 0 or rank deficient: the others; REA3 has a double
#: eigenvalue at 0, a Jordan block the PBH test must not mistake for an uncontrollable mode)
COMPLEIB = ("AC1", "AC2", "AC3", "AC4", "HE1", "HE2", "HE3", "REA1", "REA2", "REA3", "DIS1", "DIS2")

#: random members: name -> (seed, n, kind)
RANDOM = {
    "regular-3": (1, 3, "regular"), "regular-6": (2, 6, "regular"),
    "regular-10": (3, 10, "regular"), "regular-16": (4, 16, "regular"),
    "d11-5": (5, 5, "d11"), "d11-12": (6, 12, "d11"),
    "singular-d12-4": (7, 4, "singular_d12"), "singular-d12-10": (8, 10, "singular_d12"),
    "singular-d21-4": (9, 4, "singular_d21"), "singular-d21-10": (10, 10, "singular_d21"),
    "badly-scaled-6": (11, 6, "badly_scaled"), "badly-scaled-12": (12, 12, "badly_scaled"),
    "near-integrator-5": (13, 5, "near_integrator"), "near-integrator-9": (14, 9, "near_integrator"),
    "unstable-6": (15, 6, "unstable"), "unstable-14": (16, 14, "unstable"),
}


def family() -> dict:
    """Every member: name -> (P, nmeas, ncon, reference gamma or None)."""
    out = {name: (random_plant(seed, n, kind=kind), 2, 2, None) for name, (seed, n, kind) in RANDOM.items()}
    for a in (-1.0, 0.0, 1.0):
        out[f"first-order-a{a:+g}"] = first_order(a)
    for d in (1, 2):
        out[f"skogestad-2.17-design{d}"] = skogestad_postlethwaite_2_17(d)
    out["mixed-sensitivity-pole-1e-5"] = near_integrating_mixed_sensitivity(1e-6, 1.0)
    out["ill-conditioned-mixed-sensitivity"] = near_integrating_mixed_sensitivity(1e-6, 0.01)
    for name in COMPLEIB:
        out[f"compleib-{name}"] = compleib_plant(name)
    return out

"""Plants of COMPleib (F. Leibfritz, "COMPleib: COnstrained Matrix-optimization Problem library",
version 1.1, 09.03.2005; the MATLAB file COMPleib.m, function ``COMPleib(ex)``), transcribed
for the H-infinity regression family.

COMPleib's data: A, B1 (w), B (u), C1 (p), C (y), D11, D12, D21, with D22 = 0. Where an
example gives only A, B, C, COMPleib completes it as B1 = I, C1 = I, D11 = 0, D21 = 0 and
D12 = [0; I_nu] (the last nu rows of p also carry u), which :func:`compleib` repeats. Most
examples have D21 = 0 (noise-free measurements) or rank-deficient D12: they are singular
problems for the Riccati formulae.

The original sources of each model are named in COMPleib.m and here.
"""
from __future__ import annotations

import numpy as np

_S2 = 1.0 / np.sqrt(2.0)

# (AC1)/(AC2): Y. S. Hung and A. G. J. MacFarlane, "Multivariable feedback: a quasi-classical
# approach", LNCIS, Springer, 1982
_AC_A = [[0, 0, 1.132, 0, -1], [0, -0.0538, -0.1712, 0, 0.0705], [0, 0, 0, 1, 0],
         [0, 0.0485, 0, -0.8556, -1.013], [0, -0.2909, 0, 1.0532, -0.6859]]
_AC_B = [[0, 0, 0], [-0.12, 1, 0], [0, 0, 0], [4.419, 0, -1.665], [1.575, 0, -0.0732]]
_AC_C = [[1, 0, 0, 0, 0], [0, 1, 0, 0, 0], [0, 0, 1, 0, 0]]
_AC_B1 = [[3.593e-2, 0, 1.672e-2], [0, 9.89e-3, 0], [0, -7.548e-2, 0], [0, 0, 5.635e-2],
          [1.45e-3, 0, 6.743e-2]]
_REA12_B = [[0, 0], [5.679, 0], [1.136, -3.146], [1.136, 0]]

#: name -> dict of the matrices COMPleib.m gives (the rest completed by :func:`compleib`)
DATA = {
    "AC1": dict(A=_AC_A, B=_AC_B, C=_AC_C, B1=_AC_B1,
                C1=_S2 * np.array(_AC_C)[1:3], D12=_S2 * np.array([[1, 0, 0], [0, 1, 0]])),
    # AC2: AC1 with changed C1, D12
    "AC2": dict(A=_AC_A, B=_AC_B, C=_AC_C, B1=_AC_B1,
                C1=_S2 * np.array([[0, 1, 0, 0, 0], [0, 0, 1, 0, 0]] + [[0] * 5] * 3),
                D12=_S2 * np.vstack([np.zeros((2, 3)), np.eye(3)])),
    # AC3: L-1011 aircraft in cruise flight; C. Edwards and S. K. Spurgeon, IJC 59(5), 1994
    "AC3": dict(A=[[0, 0, 1, 0, 0], [0, -0.154, -0.0042, 1.54, 0], [0, 0.249, -1, -5.2, 0],
                   [0.0386, -0.996, -0.0003, -0.117, 0], [0, 0.5, 0, 0, -0.5]],
                B=[[0, 0], [-0.744, -0.032], [0.337, -1.12], [0.02, 0], [0, 0]],
                C=[[0, 1, 0, 0, -1], [0, 0, 1, 0, 0], [0, 0, 0, 1, 0], [1, 0, 0, 0, 0]]),
    # AC4: missile autopilot; B. Fares, P. Apkarian and D. Noll, IJC 74(4)
    "AC4": dict(A=[[-0.876, 1, -0.1209, 0], [8.9117, 0, -130.75, 0], [0, 0, -150, 0], [-1, 0, 0, -0.05]],
                B=[[0], [0], [150], [0]], C=[[-1, 0, 0, 0], [0, -1, 0, 0]],
                B1=[[0, 0], [0, 0], [0, 0], [0, 1]], C1=[[-0.25, 0, 0, 3.487], [0, 0, -3, 0]],
                D11=[[0, 0.25], [0, 0]], D12=[[0], [3]], D21=[[0, 1], [0.01, 0]]),
    # HE1: longitudinal motion of a VTOL helicopter; S. N. Singh and A. A. R. Coelho,
    # J. Dyn. Syst. Meas. Control 106, 1984
    "HE1": dict(A=[[-0.0366, 0.0271, 0.0188, -0.4555], [0.0482, -1.01, 0.0024, -4.0208],
                   [0.1002, 0.3681, -0.7070, 1.42], [0, 0, 1, 0]],
                B=[[0.4422, 0.1761], [3.5446, -7.5922], [-5.52, 4.49], [0, 0]], C=[[0, 1, 0, 0]],
                B1=[[4.678e-2, 0], [4.572e-2, 9.88e-3], [4.369e-2, 1.11e-3], [-2.179e-2, 0]],
                C1=_S2 * np.array([[2, 0, 0, 0], [0, 1, 0, 0]]), D12=_S2 * np.eye(2)),
    # HE2: AH-64 helicopter at 130 knots; Ph. M. Fitzsimons, Automatica 31, 1995
    "HE2": dict(A=[[-0.0649, 0.0787, 0.1705, -0.5616], [0.0386, -0.939, 4.2277, 0.0198],
                   [0.1121, -0.4254, -0.7968, 0], [0, 0, 1, 0]],
                B=[[-0.9454, 0.5313], [-8.6476, -10.769], [19.0824, -2.8959], [0, 0]],
                C=[[1, 0, 0, 0], [0, 0, 0, 1]]),
    # HE3: Bell 201A-1 helicopter; D.-W. Gu, P. Hr. Petkov and M. M. Konstantinov, SLICOT
    # Working Note 1999-12
    "HE3": dict(A=[[-0.0046, 0.038, 0.3259, -0.0045, -0.402, -0.073, -9.81, 0],
                   [-0.1978, -0.5667, 0.357, -0.0378, -0.2149, 0.5683, 0, 0],
                   [0.0039, -0.0029, -0.2947, 0.007, 0.2266, 0.0148, 0, 0],
                   [0.0133, -0.0014, -0.4076, -0.0654, -0.4093, 0.2674, 0, 9.81],
                   [0.0127, -0.01, -0.8152, -0.0397, -0.821, 0.1442, 0, 0],
                   [-0.0285, -0.0232, 0.1064, 0.0709, -0.2786, -0.7396, 0, 0],
                   [0, 0, 1, 0, 0, 0, 0, 0], [0, 0, 0, 0, 1, 0, 0, 0]],
                B=[[0.0676, 0.1221, -0.0001, -0.0016], [-1.1151, 0.1055, 0.0039, 0.0035],
                   [0.0062, -0.0682, 0.001, -0.0035], [-0.017, 0.0049, 0.1067, 0.1692],
                   [-0.0129, 0.0106, 0.2227, 0.143], [0.139, 0.0059, 0.0326, -0.407],
                   [0, 0, 0, 0], [0, 0, 0, 0]],
                C=np.eye(8)[[1, 6, 7, 5, 2, 4]],
                C1=np.vstack([np.eye(8)[[1, 6, 7, 5, 2, 4]], np.zeros((4, 8))]),
                D12=np.vstack([np.zeros((6, 4)), np.eye(4)]),
                B1="B[:, :1]", D21=0.1 * np.array([[0], [1], [0], [0], [0.5], [0]])),
    # REA1: chemical reactor; Hung and MacFarlane 1982
    "REA1": dict(A=[[1.38, -0.2077, 6.715, -5.676], [-0.5814, -4.29, 0, 0.675],
                    [1.067, 4.273, -6.654, 5.893], [0.048, 4.273, 1.343, -2.104]],
                 B=_REA12_B, C=[[1, 0, 1, -1], [0, 1, 0, 0], [0, 0, 1, -1]]),
    # REA2: REA1 with rounded data and the last row of C left out
    "REA2": dict(A=[[1.4, -0.208, 6.715, -5.676], [-0.581, -4.29, 0, 0.675],
                    [1.067, 4.273, -6.654, 5.893], [0.048, 4.273, 1.343, -2.104]],
                 B=_REA12_B, C=[[1, 0, 1, -1], [0, 1, 0, 0]]),
    # REA3: nuclear reactor; L. F. Miller, R. G. Cochran and J. W. Howze, IEEE TAC 19, 1974
    "REA3": dict(A=[[-0.4044, 0, 0, 0.4044, 0, 0, 0, 0, 0, 0, 0, 0],
                    [0, -0.4044, 0, 0, 0.4044, 0, 0, 0, 0, 0, 0, 0],
                    [0, 0, -0.4044, 0, 0, 0.4044, 0, 0, 0, 0, 0, 0],
                    [0.01818, 0, 0, -0.5363, 0, 0, 0.4045, 0, 0, 0, 0, 0],
                    [0, 0.0818, 0, 0.4545, -0.5363, 0, 0, 0, 0, 0, 0, 0],
                    [0, 0, 0.0818, 0, 0.4545, -0.5363, 0, 0, 0, 0, 0, 0],
                    [0, 0, 0, 0, 0.15, 0, -0.15, 0, 0, 0, 0, 0],
                    [0] * 12,
                    [0, -7.5, 0, 0, 75, 0, 0, 600, -74.995, 0.033, 0.346, 0.621],
                    [0, 0, 0, 0, 0, 0, 0, 0, 2.475, -0.033, 0, 0],
                    [0, 0, 0, 0, 0, 0, 0, 0, 25.95, 0, -0.346, 0],
                    [0, 0, 0, 0, 0, 0, 0, 0, 46.57, 0, 0, -0.621]],
                 B=np.eye(12)[:, [7]], C=np.eye(12)[[6, 7, 8]]),
    # DIS1: decentralized interconnected system; H. Singh, R. H. Brown and D. S. Naidu,
    # Optim. Control Appl. Methods 22, 2001
    "DIS1": dict(A=np.block([[np.array([[0.144, -0.058, 0.056, 0.042], [-0.506, -0.236, -0.020, -0.012],
                                        [0, 0, -0.278, 0.291], [0, 0, 0, -0.330]]),
                              np.array([[0.120, 2.1454, 0, 0.080], [-0.06, -0.909, 1.093, -0.040],
                                        [0, 0, 0, 0.580], [0, 0, 0, 0]])],
                             [np.array([[0, 0, 0.303, 0.029], [-0.154, 0.133, -0.006, -0.004],
                                        [-0.345, 0.304, -0.018, -0.014], [0, 0, 0, 0.247]]),
                              np.array([[-1.67, 0, 0, 0.092], [-0.014, -1.688, 0.236, 0.013],
                                        [-0.032, -0.611, -1.824, -0.024], [0, 0, 0, -1.978]])]]),
                 B=np.block([[np.array([[-0.076, 0.02], [0.588, -0.006], [0, 0.152], [0, 1.45]]), np.zeros((4, 2))],
                             [np.zeros((4, 2)), np.array([[0, 0.012], [0.162, -0.002], [0.414, -0.008],
                                                          [0, 0.248]])]]),
                 C=np.eye(8)[:4], C1=np.vstack([np.eye(8)[:4], np.zeros((4, 8))]),
                 B1=[[1], [0], [1], [0], [1], [0], [1], [0]], D12=np.vstack([np.zeros((4, 4)), np.eye(4)])),
    # DIS2: decentralized system with 2 control stations; W. Q. Liu and V. Sreeram, JOTA 93
    "DIS2": dict(A=[[-4, 2, 1], [3, -2, 5], [-7, 0, 3]], B=[[1, 0], [1, 0], [0, 1]],
                 C=[[0, 1, 0], [0, 0, 1]]),
}


def compleib(name: str):
    """COMPleib example ``name`` as (A, B1, B2, C1, C2, D11, D12, D21) float arrays, completed
    as COMPleib.m does (module docstring)."""
    d = {k: (v if isinstance(v, str) else np.array(v, dtype=float)) for k, v in DATA[name].items()}
    A, B2, C2 = d["A"], d["B"], d["C"]
    n, nu, ny = A.shape[0], B2.shape[1], C2.shape[0]
    if isinstance(d.get("B1"), str):                      # HE3: B1 = B(:, 1)
        d["B1"] = B2[:, :1].copy()
    if "B1" not in d:
        d["B1"], d["C1"] = np.eye(n), np.eye(n)
        d["D12"] = np.vstack([np.zeros((n - nu, nu)), np.eye(nu)])
    B1, C1 = d["B1"], d["C1"]
    D11 = d.get("D11", np.zeros((C1.shape[0], B1.shape[1])))
    D21 = d.get("D21", np.zeros((ny, B1.shape[1])))
    return A, B1, B2, C1, C2, D11, d["D12"], D21

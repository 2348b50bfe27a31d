"""Stresses and section forces at the nodes, as engineers read them.

Shells (MITC4): the 2nd Piola-Kirchhoff stresses [s11, s22, s12, s13, s23] at the bottom,
middle and top surfaces (r_3 = -1, 0, 1) and the resultants N (membrane forces [N/m]), M
(bending moments [N m/m]) and Q (transverse shear forces [N/m]) are evaluated at the 2 x 2
Gauss points of every element (:meth:`tmfem.fem.mitc4.MITC4Shell.stresses`, results frame
of eq. 4.16: e_1 = e_y x e_3, e_2 = e_3 x e_1), extrapolated to the element's corners by the
inverse of the bilinear interpolation, v_nodes = (H^T)^-1 v_gauss with H_kg = h_k(xi_g)
(exact for fields linear over the element), and averaged over the elements that share a
node. On a flat mesh the frames of neighbouring elements agree; on a curved one they turn
with the surface, and the averaged components are those of neighbouring frames (the
invariants below are frame independent at each element). From the averaged components:
in-plane principal stresses s_I >= s_II = (s11 + s22)/2 +- sqrt(((s11 - s22)/2)^2 + s12^2)
and the von Mises stress of eq. 5.30 with the transverse shear.

Beams: the section forces N, M1, M2, Q1, Q2, T at the Gauss points
(:meth:`tmfem.fem.beam.BeamElement.section_forces`) are fitted by the polynomial of degree
n_gp - 1 through them and evaluated at the element's 4 nodes (exact for a polynomial
section-force distribution of that degree), then averaged at shared nodes.

Nodes outside a shell (or beam) hold NaN in its fields.
"""
from __future__ import annotations

import numpy as np

from tmfem.fem.mitc4 import quad_shape
from tmfem.fem.plane_stress import von_mises

SURFACES = ("bottom", "mid", "top")
_G = 0.5 / np.sqrt(3.0)
#: the 2 x 2 Gauss points of the unit square (scikit-fem reference element of eq. 4.13)
GAUSS_2X2 = np.array([[0.5 - _G, 0.5 + _G, 0.5 + _G, 0.5 - _G], [0.5 - _G, 0.5 - _G, 0.5 + _G, 0.5 + _G]])


def _average(conn: np.ndarray, per_element_node: np.ndarray, n_nodes: int) -> np.ndarray:
    """Nodal averages (n_nodes, ...) of values (ne, k, ...) at the k nodes ``conn`` (k, ne)."""
    shape = per_element_node.shape[2:]
    acc = np.zeros((n_nodes,) + shape)
    cnt = np.zeros(n_nodes)
    np.add.at(acc, conn.T.ravel(), per_element_node.reshape((-1,) + shape))
    np.add.at(cnt, conn.T.ravel(), 1.0)
    out = np.full((n_nodes,) + shape, np.nan)
    used = cnt > 0
    out[used] = acc[used] / cnt[used].reshape((-1,) + (1,) * len(shape))
    return out


def principal_in_plane(s: np.ndarray) -> np.ndarray:
    """In-plane principal stresses (..., 2) [s_I, s_II] of components (..., >= 3) [s11, s22, s12, ...]."""
    c = 0.5 * (s[..., 0] + s[..., 1])
    r = np.hypot(0.5 * (s[..., 0] - s[..., 1]), s[..., 2])
    return np.stack([c + r, c - r], axis=-1)


def shell_nodal_results(shell, state, n_nodes: int) -> dict:
    """Nodal fields of one MITC4 element set (module docstring): ``sigma_<surface>``
    (n_nodes, 5) [Pa], ``principal_<surface>`` (n_nodes, 2) [Pa], ``von_mises_<surface>``
    (n_nodes,) [Pa], ``N`` (n_nodes, 3) [N/m], ``M`` (n_nodes, 3) [N m/m], ``Q`` (n_nodes,
    2) [N/m]."""
    H = quad_shape(GAUSS_2X2)[0]                                       # (4 nodes, 4 points)
    E = np.linalg.inv(H.T)                                              # nodes from points
    at = [shell.stresses(state, xi=GAUSS_2X2[:, g]) for g in range(4)]
    fields = {"sigma": np.stack([r["sigma"] for r in at]), "N": np.stack([r["N"] for r in at]),
              "M": np.stack([r["M"] for r in at]), "Q": np.stack([r["Qs"] for r in at])}
    out = {}
    for name, v in fields.items():                                      # v (4 points, ne, ...)
        nodal = _average(shell.conn, np.einsum("kg,ge...->ek...", E, v), n_nodes)
        if name == "sigma":
            for j, surf in enumerate(SURFACES):
                out[f"sigma_{surf}"] = nodal[:, j]
        else:
            out[name] = nodal
    for surf in SURFACES:
        s = out[f"sigma_{surf}"]
        out[f"principal_{surf}"] = principal_in_plane(s)
        out[f"von_mises_{surf}"] = von_mises(np.moveaxis(s, -1, 0))
    return out


def beam_nodal_section_forces(beam, state, n_nodes: int) -> dict:
    """Nodal section forces (n_nodes,) of a beam element set: N, Q1, Q2 [N], M1, M2, T [N m]
    (module docstring)."""
    r = np.asarray(beam.r_gauss, dtype=float)
    nodes_r = np.array([-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0])
    deg = r.size - 1
    Vg = np.polynomial.legendre.legvander(r, deg)
    Vn = np.polynomial.legendre.legvander(nodes_r, deg)
    E = Vn @ np.linalg.solve(Vg, np.eye(r.size))                        # (4 nodes, ngp)
    sf = beam.section_forces(state)
    return {k: _average(beam.beams.conn, np.einsum("kg,eg->ek", E, v), n_nodes) for k, v in sf.items()}

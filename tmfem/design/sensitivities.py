"""Exact design sensitivities of the MTC model at its static equilibrium.

Variables p: tendon rest lengths, per group (``"S1"``, ``"V2"``: every tendon of the group
moves together, r = r_0 + G p) or per tendon, and optionally the membrane thickness h, on
which the membrane's internal force, tangent and mass depend linearly (dR/dh = f_mb / h,
dK/dh = K_mb / h, dM/dh = M_mb / h at fixed positions). Responses at the equilibrium R(u, p) = 0:

* the lowest eigenvalues lambda = omega^2 of (K_T - lambda M) phi = 0 (eq. 5.32),
* the largest tendon force and the largest tendon stress,
* the position (hence the displacement) of a labelled node along one axis.

Method: the *direct* method, one linear solve per variable with the tangent of the static
solve, factorised once,

    K_T du/dp = -dR/dp,

where dR/dp is analytic (:func:`tmfem.fem.truss.truss_rest_length_derivatives`). The direct
method is chosen over the adjoint because the variables are few (one per tendon group) while
every eigenvalue needs the derivative of the tangent *along* the state change,
dK = dK_T/du du/dp + dK_T/dp: with du/dp at hand this is one directional derivative per
variable, whereas the adjoint of an eigenvalue would need the gradient of phi^T K_T(u) phi
with respect to u (third derivatives of the strain energy of every element). That
directional derivative is a central difference of the assembled tangent along (du/dp, dp)
with a step that moves the state by 1e-4 of its scale: truncation O(h^2) about 1e-8 relative, while
the rounding of the stiff tendon and bar entries, eps |K| / h, stays below the smallest
eigenvalues' derivatives (a step of 1e-6 already loses five digits of the lowest ones to it).
The mass, linear in the rest lengths, is differenced exactly. For a simple M-normalised mode,

    d lambda = phi^T (dK - lambda dM) phi;

for a cluster of (numerically) repeated eigenvalues with M-orthonormal basis Phi, the
directional derivatives along each variable are the eigenvalues of Phi^T (dK - lambda dM) Phi
(sorted ascending): each eigenvalue of a cluster is only directionally differentiable, their
sum is smooth. The largest tendon force is differentiable where the largest element is unique.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from tmfem.errors import InputError
from tmfem.fem.element import State
from tmfem.fem.truss import truss_axial_force_derivatives, truss_mass, truss_rest_length_derivatives

#: relative gap below which neighbouring eigenvalues form a cluster
CLUSTER_TOL = 1e-6


@dataclass
class Sensitivities:
    """Responses and their derivatives with respect to the variables ``names``.

    Attributes
    ----------
    names : list of str
        The variables (tendon groups or tendon names).
    omega2, d_omega2 : (k,), (k, n_var)
        Lowest eigenvalues [rad^2/s^2] and their (directional, within clusters) derivatives.
    freq_hz, d_freq_hz : (k,), (k, n_var)
        f = sqrt(lambda) / (2 pi) and df = d lambda / (4 pi sqrt(lambda)).
    clusters : list of ndarray
        Index sets of the eigenvalue clusters (length > 1: repeated eigenvalues).
    max_tendon_force, d_max_tendon_force : float, (n_var,)
        Largest tendon element axial force [N] and its derivative.
    max_tendon_stress, d_max_tendon_stress : float, (n_var,)
        Largest tendon stress N / A [Pa] and its derivative.
    position, d_position : float, (n_var,)
        Coordinate of the requested node [m] and its derivative (None without a node).
    du : (n_dofs, n_var)
        Derivatives of the independent positions.
    """

    names: list
    omega2: np.ndarray
    d_omega2: np.ndarray
    freq_hz: np.ndarray
    d_freq_hz: np.ndarray
    clusters: list
    max_tendon_force: float
    d_max_tendon_force: np.ndarray
    max_tendon_stress: float
    d_max_tendon_stress: np.ndarray
    position: float | None
    d_position: np.ndarray | None
    du: np.ndarray


def variable_map(model, variables: str):
    """Names and the map G (n_tendons, n_var) from the variables to the rest lengths."""
    tendons = model.system.tendons
    if variables == "tendons":
        return [t.name for t in tendons], np.eye(len(tendons))
    if variables == "groups":
        names = list(dict.fromkeys(t.group for t in tendons))
        G = np.array([[float(t.group == g) for g in names] for t in tendons])
        return names, G
    raise InputError(f"variables: expected 'groups' or 'tendons', found {variables!r}")


def _clusters(lam: np.ndarray) -> list:
    """Runs of neighbouring eigenvalues within CLUSTER_TOL of each other (relative)."""
    scale = np.maximum(np.abs(lam[1:]), np.abs(lam[:-1])).clip(min=1e-12)
    breaks = np.flatnonzero(np.diff(lam) > CLUSTER_TOL * scale) + 1
    return np.split(np.arange(lam.size), breaks)


def design_sensitivities(model, *, equilibrium=None, variables: str = "groups", k: int = 4,
                              node: str | None = None, axis: int = 2,
                              thickness: bool = False, step: float = 1e-4) -> Sensitivities:
    """Responses of an MTC model at its static equilibrium and their exact derivatives with
    respect to the tendon rest lengths (module docstring: direct method, eigenvalue and
    cluster derivatives).

    Parameters
    ----------
    model : MTCModel
    equilibrium : Equilibrium, optional
        A converged :meth:`MTCModel.equilibrium` at the model's current rest lengths (default:
        solved here from the undeformed membrane).
    variables : {"groups", "tendons"}
        One variable per tendon group (r_t = r_t0 + p_group) or per tendon.
    k : int
        Number of lowest eigenvalues.
    node : str, optional
        Label of a system node (``"H_11"``, ``"A_12"``) whose coordinate ``axis`` is a response.
    thickness : bool
        Add the membrane thickness h as the last variable (``"h_membrane"``).
    step : float
        Relative step of the directional central difference of the tangent.
    """
    if not (isinstance(k, (int, np.integer)) and k >= 1):
        raise InputError(f"k: expected a positive integer, found {k!r}")
    if axis not in (0, 1, 2):
        raise InputError(f"axis: expected 0, 1 or 2, found {axis!r}")
    if model.tendon_law != "cable":
        raise InputError(f"sensitivities: expected a model with tendon_law='cable' (EA fixed as the "
                         f"rest length changes), found {model.tendon_law!r}")
    if model.distributed is not None:
        raise InputError("sensitivities: expected a model on a serial backend (scipy), found a "
                         "distributed one")
    node_at = None if node is None else model.topology.system_node[model.system.node_index(node)]
    eq = model.equilibrium() if equilibrium is None else equilibrium
    names, G = variable_map(model, variables)
    topo, free = model.topology, model.free
    x = eq.state
    xr = model.reduce(x)
    T = topo.T
    tendons = model.tendons
    kt = topo.tendon_elements
    e2t = sp.csr_matrix((np.full(tendons.ne, 1.0 / kt), (np.arange(tendons.ne), topo.tendon_of_element)),
                        shape=(tendons.ne, G.shape[0]))
    dL = e2t @ G                                                       # dL_e / dp  (ne, n_var)
    dR = T.T @ (truss_rest_length_derivatives(x, tendons, dofmap=model.dofmap) @ dL)
    M_mb = K_mb = None
    if thickness:
        h_mb = model.membrane.material.h
        f_mb, K_mb = model.membrane_element.internal(State(x=x))
        M_mb = T.T @ model.membrane_element.mass() @ T / h_mb
        K_mb = T.T @ K_mb @ T / h_mb
        names = names + ["h_membrane"]
        G = np.column_stack([G, np.zeros(G.shape[0])])
        dL = np.column_stack([dL, np.zeros(dL.shape[0])])
        dR = np.column_stack([dR, T.T @ f_mb / h_mb])
    K = eq.tangent if eq.tangent is not None else model.residual(xr)[1]
    solve = model.backend.factorize(sp.csr_matrix(K)[free][:, free])
    du = np.zeros((xr.size, G.shape[1]))
    du[free] = solve(-dR[free]).reshape(-1, G.shape[1])
    dx = np.stack([model.full(du[:, j]) for j in range(du.shape[1])], axis=-1)   # (3, nn, n_var)

    # eigenvalues: two extra modes so that a cluster at the k-th is complete
    n_modes = min(k + 2, int(free.sum()))
    modes = model.modes(k=n_modes, at=eq)
    lam, Phi = modes.omega2, modes.shapes
    clusters = [c for c in _clusters(lam) if c[0] < k]
    r0 = model.rest_lengths.copy()
    L0 = tendons.L.copy()
    scale = step * max(float(np.abs(xr).max()), float(r0.max()))
    dlam = np.zeros((k, G.shape[1]))
    for j in range(G.shape[1]):
        # the step moves the state by `scale` at most, whatever the variable's units
        h = scale / max(1.0, float(np.abs(du[:, j]).max()), float(np.abs(G[:, j]).max()))
        Kpm = []
        try:
            for sgn in (1.0, -1.0):
                model.set_tendon_lengths(r0 + sgn * h * G[:, j])
                Kpm.append(model.residual(xr + sgn * h * du[:, j])[1])
        finally:
            model.set_tendon_lengths(r0)
        dK = (Kpm[0] - Kpm[1]) / (2 * h)
        if thickness and j == G.shape[1] - 1:
            dK, dM = dK + K_mb, M_mb
        else:
            dM = T.T @ truss_mass(dataclasses.replace(tendons, L=L0 + dL[:, j]), model.dofmap,
                                  lumped=model.lumped_tendon_mass) @ T \
                - T.T @ truss_mass(tendons, model.dofmap, lumped=model.lumped_tendon_mass) @ T
        for c in clusters:
            P = Phi[:, c]
            A = P.T @ (dK @ P) - lam[c].mean() * (P.T @ (dM @ P))
            ev = np.linalg.eigvalsh(0.5 * (A + A.T))
            keep = c < k
            dlam[c[keep], j] = ev[keep]
    lam = lam[:k]
    freq = np.sqrt(np.abs(lam)) / (2 * np.pi)
    dfreq = dlam / (4 * np.pi * np.sqrt(np.abs(lam)))[:, None]

    # tendon force and stress: N(l(x), L)
    N, dN_dl, dN_dL, e = truss_axial_force_derivatives(x, tendons)
    c0, c1 = tendons.conn
    dN = dN_dl[:, None] * np.einsum("ie,iej->ej", e, dx[:, c1] - dx[:, c0]) + dN_dL[:, None] * dL
    area = model.tendon_area[topo.tendon_of_element]
    i_f, i_s = int(np.argmax(N)), int(np.argmax(N / area))
    position = d_position = None
    if node_at is not None:
        position, d_position = float(x[axis, node_at]), dx[axis, node_at].copy()
    return Sensitivities(names=names, omega2=lam, d_omega2=dlam, freq_hz=freq, d_freq_hz=dfreq,
                         clusters=clusters, max_tendon_force=float(N[i_f]), d_max_tendon_force=dN[i_f],
                         max_tendon_stress=float(N[i_s] / area[i_s]),
                         d_max_tendon_stress=dN[i_s] / area[i_s],
                         position=position, d_position=d_position, du=du)

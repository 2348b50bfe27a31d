"""Linear plants for control at a deployed configuration (7.3, eqs. 5.17-5.18, 5.62, Fig. 7.1).

* :func:`deployed_plant`: the control-oriented model in the coordinates of the controllers,
  x_z = [q, v, q', v'] with v the relative transverse deflections of K membrane points
  (eqs. 5.17-5.18), linearised about the deployed equilibrium (eq. 5.33 / 5.62): a
  python-control ``StateSpace`` with every state as an output (the measured outputs of
  Fig. 7.1 are q, v, q', v') and the tendon rest lengths as inputs.
* :func:`generalized_plant`: the interconnection of Fig. 7.1 with the weights of 7.4 by
  ``control.interconnect`` on named signals (our reading of the figure: docs/guides/control.md).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tmfem.control.linear.partitioned_plant import GeneralizedPlant
from tmfem.errors import InputError

log = logging.getLogger(__name__)

W_E = 0.5        # W_e = 0.5 I (7.4, item 1)
W_D = 0.001      # W_d1..4 = 0.001 I (7.4, item 2)


def measured_points(system) -> list:
    """The measured membrane points (x_f, y_f) [m] of eq. 5.18 of ``system``: its file's
    ``[control] points`` (eqs. 5.73-5.75 for the deployed presets), else its ``[monitor]
    points``, else :func:`interior_points`."""
    pts = system.problem.control.points
    if pts is not None:
        return list(pts)
    if system.monitor_points.size:
        return [tuple(p) for p in system.monitor_points.T.tolist()]
    return interior_points(system)


def interior_points(system, *, count: int = 3) -> list:
    """``count`` membrane points inside the membrane, away from its edges, corners and the
    patch boundaries of the mesh (centroid to edge midpoints): for the first ``count`` edges
    j, half-way from the centroid c to the point between corner j and the midpoint of edge
    (j, j+1), i.e. c + (p_j + m_j - 2 c) / 4 (x_f, y_f in m)."""
    P = np.asarray(system.membrane_corners, dtype=float)
    c = P.mean(axis=1)
    out = []
    for j in range(min(count, P.shape[1])):
        m = 0.5 * (P[:, j] + P[:, (j + 1) % P.shape[1]])
        x, y = c + (P[:, j] + m - 2 * c) / 4
        out.append((float(x), float(y)))
    return out


#: the greedy choice of :func:`point_coordinates` keeps its points at least this fraction of the
#: membrane's inradius away from its edges (and so from its corners)
EDGE_CLEARANCE = 0.2


def point_coordinates(basis, *, K: int, points) -> list:
    """K membrane points for the coordinates v of eq. 5.18: the given monitored points
    first, then mesh nodes chosen greedily (largest component of the node's row of mode
    deflections orthogonal to the rows already chosen: column-pivoted Gram-Schmidt), so
    that T_v_eta of eq. 5.17 is as well conditioned as the greedy choice allows. The greedy
    choice takes nodes inside the membrane only, at least :data:`EDGE_CLEARANCE` x the
    inradius from every edge (the free edges of the corner-held modes carry their largest
    deflections, but a sensor on an edge is not where the membrane is)."""
    pts = [_on_membrane(basis, p) for p in points][:K]
    mesh = basis.scalar_basis.mesh
    nd = basis.n_delta
    Phi_nodes = basis.shapes[1 + nd:, 2, :].T                   # (n_nodes, K): w of each mode
    chosen = [basis.point_matrix(np.array([[x], [y]]), 2)[0, 1 + nd:] for x, y in pts]
    cand = interior_nodes(mesh.p, basis.mesh.p[:, basis.mesh.corners], clearance=EDGE_CLEARANCE)
    if len(cand) < K - len(pts):
        raise InputError(f"membrane points: expected {K - len(pts)} mesh nodes at least {EDGE_CLEARANCE:g} x the "
                         f"inradius inside the membrane, found {len(cand)} (a finer mesh, or give the points "
                         "in [control] points / coordinate_points)")
    while len(pts) < K:
        Q = np.linalg.qr(np.array(chosen).T)[0] if chosen else np.zeros((basis.K, 0))
        rows = Phi_nodes[cand]
        resid = rows - (rows @ Q) @ Q.T
        j = int(np.argmax(np.linalg.norm(resid, axis=1)))
        pts.append((float(mesh.p[0, cand[j]]), float(mesh.p[1, cand[j]])))
        chosen.append(rows[j])
    return pts


def interior_nodes(nodes, corners, *, clearance: float) -> np.ndarray:
    """Indices of the ``nodes`` (2, n) at least ``clearance`` x r_in from every edge of the
    convex polygon ``corners`` (2, N), r_in its inradius (the smallest distance of the corners'
    centroid to an edge). The distance of a node x to the edge (a, b) is that to the segment,
    |x - a - t (b - a)| with t = clip((x - a).(b - a) / |b - a|^2, 0, 1)."""
    P = np.asarray(corners, dtype=float)
    X = np.asarray(nodes, dtype=float)

    def edge_distance(x):                       # (2, n) -> (n,): distance to the nearest edge
        a = P[:, :, None]
        e = (np.roll(P, -1, axis=1) - P)[:, :, None]
        t = np.clip(np.sum((x[:, None, :] - a) * e, axis=0) / np.sum(e * e, axis=0), 0.0, 1.0)
        return np.min(np.linalg.norm(x[:, None, :] - a - t[None] * e, axis=0), axis=0)

    r_in = float(edge_distance(P.mean(axis=1)[:, None])[0])
    return np.flatnonzero(edge_distance(X) >= clearance * r_in)


def _on_membrane(basis, point, *, max_shift: float = 0.01):
    """The point, or (if it lies just outside the discretised polygon, as the edge points
    of eq. 5.73 do with r_mb = 1.414 m: side 1.9997 m) the nearest point on the segment to
    the membrane centroid that lies inside, moved by at most ``max_shift`` x r_mb. The move
    is the documented rule for points on the edge (docs/guides/control.md), logged at DEBUG level
    only: the presets' edge points take it on every run."""
    x, y = map(float, point)
    pm = basis.scalar_basis.mesh.p
    c = pm.mean(axis=1)
    r = float(np.max(np.linalg.norm(pm - c[:, None], axis=0)))
    for s in np.linspace(0.0, max_shift, 101):
        d = np.array([x, y]) - c
        cand = c + d * (1 - s * r / max(np.linalg.norm(d), 1e-300))
        try:
            basis.point_matrix(cand[:, None], 2)
        except InputError:
            continue
        if s > 0:
            log.debug("membrane point (%g, %g) lies outside the mesh: using (%.4f, %.4f)", x, y, *cand)
        return (float(cand[0]), float(cand[1]))
    raise InputError(f"membrane point ({x}, {y}) m: expected a point on the membrane (within "
                     f"{max_shift * r:.3g} m of it), found it outside")


@dataclass
class DeployedPlant:
    """Linearised COM at a deployed equilibrium in (q, v) coordinates (eqs. 5.18, 5.62).

    ``ss`` has the states ``x_z = [q, v, q', v']`` (names ``theta_11 … wr_1 … *_dot``), the
    inputs ``r_<tendon>`` (rest-length perturbations, m) and one output per state, named as
    the state: the measured signals of Fig. 7.1 before noise.
    """

    ss: object
    q_e: np.ndarray
    u_e: np.ndarray
    z_e: np.ndarray
    points: list
    frequencies_hz: np.ndarray
    model: object
    linearization: object
    #: K and where it comes from (:class:`tmfem.models.com.mode_count.MembraneModeChoice`)
    membrane_modes: object = None

    @property
    def f_max_hz(self) -> float:
        return float(self.frequencies_hz[-1])

    @property
    def n_q(self) -> int:
        return len(self.q_e)

    @property
    def operating_point(self) -> dict:
        return {"q_e": self.q_e, "u_e": self.u_e, "z_e": self.z_e,
                "q_names": list(self.model.system.q_names), "u_names": list(self.ss.input_labels),
                "membrane_points": [("w", x, y) for x, y in self.points]}


def deployed_plant(system, *, membrane_modes: int | None = None, points=None, mesh_n: int = 10,
                   rest_lengths=None, damping: float = 0.0) -> DeployedPlant:
    """Linear plant at the deployed configuration (eqs. 5.17-5.18, 5.33, 5.62).

    Parameters
    ----------
    system : System
        The deployed (final) configuration, e.g. ``load_preset("1-4D")``.
    membrane_modes : int, optional
        K (7.4: 3 for 1-4(D), 5 for 1-6(D), 4 for 2-3); default the file's ``[models.com]
        membrane_modes``, else the automatic choice
        (:func:`tmfem.models.com.mode_count.membrane_mode_choice`).
    points : list of (x_f, y_f), optional
        Membrane points of the coordinates v (eq. 5.18); default :func:`measured_points`
        (eqs. 5.73-5.75 for the presets); completed to K by the file's ``[control]
        coordinate_points``, then by :func:`point_coordinates`.
    rest_lengths : {"system", "design"} or array, optional
        u_e; "system": the file's rest lengths (the printed ones of Tables 7.3, 7.5, 7.7 for
        the presets), "design": those of the equilibrium design (ch. 3); default the file's
        when it gives them, else the design's.
    damping : float
        Modal damping c_m of eq. 5.13 (7.4 states none: default 0).
    """
    from tmfem.models.com.linearize import linearize
    from tmfem.models.com.model import ControlOrientedModel
    from tmfem.models.com.model import membrane_modes_of
    import control
    choice = membrane_modes_of(system, membrane_modes)
    K = choice.K
    if rest_lengths is None:
        rest_lengths = "system" if system.rest_lengths is not None else "design"
    modal = ControlOrientedModel(system, membrane_modes=K, mesh_n=mesh_n, rest_lengths=rest_lengths,
                                 damping=damping, output_points=[])
    pts = list(points if points is not None else measured_points(system))
    pts = point_coordinates(modal.membrane, K=K, points=pts + list(system.problem.control.coordinate_points or ()))
    model = ControlOrientedModel(system, membrane_modes=K, mesh_n=mesh_n, rest_lengths=modal.u0,
                                 damping=damping, output_points=[],
                                 membrane_points=[("w", x, y) for x, y in pts])
    lin = linearize(model)
    n = lin.A.shape[0]
    sys = control.ss(lin.A, lin.B, np.eye(n), np.zeros((n, lin.B.shape[1])),
                     states=list(lin.state_names), inputs=list(lin.input_names),
                     outputs=list(lin.state_names), name="G")
    return DeployedPlant(ss=sys, q_e=lin.z_e[: model.nq].copy(), u_e=lin.u_e.copy(),
                         z_e=lin.z_e.copy(), points=pts, frequencies_hz=lin.frequencies_hz(),
                         model=model, linearization=lin, membrane_modes=choice)


def generalized_plant(plant: DeployedPlant, *, u_m: float, W_e: float = W_E, W_d: float = W_D):
    """The generalised plant of Fig. 7.1 (weights of 7.4) by ``control.interconnect``.

    Reading of Fig. 7.1 (docs/guides/control.md): exogenous w = [q_d, v_d, n_q, n_v, n_q', n_v'],
    measured y = [q_m - q_d, v_m - v_d, q'_m, v'_m] with x_m = x + W_d n (W_d1..4 on the
    four noise blocks), regulated p = [e_d, e_u] with e_d = W_e ([q_d, v_d] - [q, v]) and
    e_u = W_u u, W_u = I / u_m. The controller closes u = K(s) y.

    Returns
    -------
    GeneralizedPlant
        Partitioned eq. 5.62 (D22 = 0); signals w: ``ref_<q or v>``, ``n_<state>``; u: the
        plant's ``r_<tendon>``; p: ``ed_<q or v>``, ``eu_r_<tendon>``; y: ``y_<state>``.
    """
    import control
    if not (np.isfinite(u_m) and u_m > 0):
        raise InputError(f"u_m: expected > 0 m, found {u_m!r}")
    G = plant.ss
    xs = list(G.state_labels)
    nz = len(xs) // 2
    z = xs[:nz]
    us = list(G.input_labels)
    nu = len(us)
    ref = [f"ref_{s}" for s in z]
    noise = [f"n_{s}" for s in xs]
    We = control.ss([], [], [], W_e * np.eye(nz), inputs=[f"e_{s}" for s in z],
                    outputs=[f"ed_{s}" for s in z], name="W_e")
    Wu = control.ss([], [], [], np.eye(nu) / u_m, inputs=us, outputs=[f"eu_{s}" for s in us],
                    name="W_u")
    Wd = control.ss([], [], [], W_d * np.eye(2 * nz), inputs=noise,
                    outputs=[f"dn_{s}" for s in xs], name="W_d")
    # tracking error e = [q_d, v_d] - [q, v]
    blocks = [G, We, Wu, Wd]
    # e = ref - x_z[:nz]
    E = control.ss([], [], [], np.hstack([np.eye(nz), -np.eye(nz)]),
                   inputs=ref + z, outputs=[f"e_{s}" for s in z], name="sum_e")
    # measured: y = x_m - [ref, 0] with x_m = x + W_d n
    Ym = control.ss([], [], [], np.hstack([np.eye(2 * nz), np.eye(2 * nz),
                                           -np.vstack([np.eye(nz), np.zeros((nz, nz))])]),
                    inputs=xs + [f"dn_{s}" for s in xs] + ref,
                    outputs=[f"y_{s}" for s in xs], name="sum_y")
    blocks += [E, Ym]
    inp = ref + noise + us
    out = [f"ed_{s}" for s in z] + [f"eu_{s}" for s in us] + [f"y_{s}" for s in xs]
    P = control.interconnect(blocks, inplist=inp, outlist=out, inputs=inp, outputs=out, name="P")
    return GeneralizedPlant.from_ss(P, nw=len(ref) + len(noise), ny=len(xs))

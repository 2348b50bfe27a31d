"""The finite-element models (MTC, SBC) as the plant of the deployment controllers.

The controllers of chapters 7-8 are designed on the control-oriented model (COM, eq. 5.27)
and read its state z = [q, eta] (bar coordinates and membrane modal coordinates, or the
membrane point coordinates of eqs. 5.17-5.18) with its rates. On a finite-element plant that
state does not exist: it has to be measured. :class:`COMStateEstimator` computes it from the
FE state as sensors would give it:

* q from the rigid placement of each bar closest to its nodes in the kinetic-energy norm
  (:func:`rigid_bar_fit`, ``bars="rigid"``, the default on the SBC plant): the bar's
  rigid-body coordinates, which the bending modes of the SBC's beams (mass-orthogonal to
  them) do not move; or from the bar end nodes (``bars="chord"``, eqs. 3.1-3.2,
  :func:`tmfem.models.mtc.post.q_from_positions`: the MTC plant's truss bars, whose chord is
  their rigid fit; on the SBC plant the chords A_ij-B_ij of the beams, which see their
  bending, docs/guides/fe-plant.md);
* eta by projecting the FE membrane onto the COM's membrane basis (eq. 5.1): the FE membrane
  nodes (the SBC shell's mid-surface nodes) are taken into the floating frame of the current
  corners (eq. 3.3), interpolated at the nodes of the COM basis, the prestressing part sum_k Psi_k Delta_k(q) (Delta
  from the
  corner constraints, eqs. 3.5, 5.14) is subtracted and the rest is projected on the
  relative modes in the mass inner product (:meth:`MembraneBasis.modal_coordinates`) -- a
  full-field measurement of the membrane (photogrammetry), the best case of the "projection
  on the control-oriented model's membrane basis";
* the rates z' as the directional derivative of that map along the FE velocity, by a central
  difference with a displacement step of 1e-5 m (second order: error ~1e-10 relative).

Where the FE membrane moves exactly as the COM's field (eqs. 5.1, 5.3) the estimate is exact
(test); otherwise it is the COM state closest in the kinetic-energy norm, and what it leaves
out (modes above K, tendon vibration) is what the controller does not see.

:class:`FEStatePlant` is an FE plant (any :class:`tmfem.models.fe.plant.FEPlant`: the MTC
model's :class:`~tmfem.models.mtc.dynamics.MTCDynamics` or the SBC model's
:class:`~tmfem.models.sbc.dynamics.SBCDynamics`, the tendon rest lengths as inputs,
M a + C v + f_int(x; u) = 0) whose outputs are that estimate
y = [z, z'], so every controller built for the COM plant (the adaptive PFL, the switch, the
linear controllers) runs on it unchanged; its tendons either take the commanded rest lengths
or, with ``actuation="force"``, the COM's tension at the measured q through tension-servoed
winches (:meth:`FEStatePlant.actuate`, :mod:`tmfem.control.fe_plant.tension_actuation`).
:func:`fe_state_of` places the FE model in the
configuration of a COM state (bars at q, membrane on the COM's field, tendons straight);
:func:`mtc_deployment_plant` and :func:`sbc_deployment_plant` (:func:`deployment_plant` by
name) build the plant of a deployment, started at rest in its own equilibrium of the
packaged design.
"""
from __future__ import annotations

import numpy as np

from tmfem.control.fe_plant.tension_actuation import (ACTUATIONS, fe_element_lengths, fe_tendon_lengths,
                                             rest_length_for_tension, tension_demand)
from tmfem.errors import InputError
from tmfem.fem.membrane import point_matrix
from tmfem.models.fe.outputs import q_from_positions
from tmfem.models.fe.outputs import to_floating
from tmfem.system.coordinates import join_q, q_index
from tmfem.system.geometry import wrap_angle

#: displacement step [m] of the central difference along the FE velocity (module docstring)
RATE_STEP = 1e-5
#: how the estimate measures the bar coordinates q (:class:`COMStateEstimator`)
BAR_MEASURES = ("chord", "rigid")


def default_bar_measure(dyn) -> str:
    """The bar measurement of an FE plant when none is asked for: the rigid fit
    (:func:`rigid_bar_fit`) of a plant with nodes along its bars (``bar_chain_positions``: the
    SBC model's beams, whose chords see their bending modes -- the LPV loop measured through
    them is unstable, docs/guides/fe-plant.md), the chord of one with straight truss bars (the MTC
    model: there the chord is the rigid fit, the two end nodes being the whole bar)."""
    return "rigid" if hasattr(dyn, "bar_chain_positions") else "chord"


def rigid_bar_fit(system, X: np.ndarray, s: np.ndarray) -> np.ndarray:
    """q (eqs. 3.1-3.2) of the rigid bars closest to the chain-node positions X (3, n_bars,
    n_chain) of elastic bars in the kinetic-energy norm of their translations.

    Node i of a bar sits at the fraction s_i of the bar in the reference (A_ij at 0, B_ij at
    1) and carries the lumped mass m_i of a uniform bar (trapezoidal weights of the chain
    spacing). A rigid bar places it at a + s_i l b (unit b); minimising
    sum_i m_i |x_i - a - s_i l b|^2 gives

    * a bar on a fixed base A (stage 1, a = A): b ~ sum_i m_i s_i (x_i - A),
    * a bar of free base: b ~ sum_i m_i (s_i - s_m)(x_i - c), l = |sum_i m_i (s_i - s_m)
      (x_i - c)| / sum_i m_i (s_i - s_m)^2, a = c - s_m l b, with c and s_m the mass-weighted
      means of x_i and s_i,

    and theta = arccos(b_z), psi = atan2(b_y, b_x) (3.2). These are the coordinates of the
    bar's rigid-body modes: the bending modes are mass-orthogonal to them, so a force at an
    interior node (H_1j) moves them at once as it turns a rigid bar, where the chord A-B
    moves only as the bending reaches the ends (docs/guides/fe-plant.md). Straight bars give the
    chord."""
    s = np.asarray(s, dtype=float)
    m = np.zeros_like(s)
    m[:-1] += 0.5 * np.diff(s)
    m[1:] += 0.5 * np.diff(s)
    M, N = system.M, system.N
    a = X[:, :, 0].copy()
    fixed = np.arange(M * N) < N                      # stage-1 bars: A_1j on the base
    b = np.einsum("c,knc->kn", m * s, X - a[:, :, None])
    if not np.all(fixed):
        sm = np.sum(m * s) / np.sum(m)
        c = np.einsum("c,knc->kn", m, X) / np.sum(m)
        bf = np.einsum("c,knc->kn", m * (s - sm), X - c[:, :, None])
        length = np.linalg.norm(bf, axis=0) / np.sum(m * (s - sm) ** 2)
        free = ~fixed
        b[:, free] = bf[:, free]
        a[:, free] = (c - sm * length * bf / np.linalg.norm(bf, axis=0))[:, free]
    A = a.reshape(3, M, N)
    bn = b / np.linalg.norm(b, axis=0)
    theta = np.arccos(np.clip(bn[2], -1.0, 1.0)).reshape(M, N)
    psi = wrap_angle(np.arctan2(bn[1], bn[0])).reshape(M, N)
    return join_q(A, theta, psi)


def _probe(skmesh, p: np.ndarray):
    """Interpolation matrix of ``skmesh``'s nodal field at the reference points p (2, n); the
    boundary nodes of another mesh lie on this mesh's boundary only up to round-off, so where
    a point falls outside, all are pulled toward their centroid by 1e-9 of their distance."""
    try:
        return point_matrix(skmesh, p)
    except InputError:
        c = p.mean(axis=1, keepdims=True)
        return point_matrix(skmesh, c + (1.0 - 1e-9) * (p - c))


class COMStateEstimator:
    """The COM state (z, z') of an FE state (module docstring).

    Parameters
    ----------
    com : ControlOrientedModel
        The controllers' design model, of the same system as the FE model.
    dyn : FEPlant
        The FE plant: ``positions(x)`` gives the node positions of a free-DOF state in the
        placement numbering of its model ``dyn.model`` (membrane, system labels, tendon internals).
    bars : {"chord", "rigid"}, optional
        q from the bar end nodes, or from the rigid fit of the bar's chain nodes
        (:func:`rigid_bar_fit`; a plant with nodes along its bars, ``dyn.bar_chain_positions``:
        the SBC model); default :func:`default_bar_measure` (rigid on the SBC plant, chord on
        the MTC plant).
    """

    def __init__(self, com, dyn, *, bars: str | None = None):
        bars = default_bar_measure(dyn) if bars is None else bars
        if bars not in BAR_MEASURES:
            raise InputError(f"bar measurement: expected one of {BAR_MEASURES}, found {bars!r}")
        if bars == "rigid" and not hasattr(dyn, "bar_chain_positions"):
            raise InputError(f"bar measurement 'rigid': expected an FE plant with nodes along "
                             f"its bars (the SBC model), found the {dyn.name} plant, whose bars "
                             f"are straight trusses (their chord is their rigid fit)")
        self.bars = bars
        fe = dyn.model
        if fe.system is not com.system:
            raise InputError("FE plant: expected the FE model and the control-oriented model of "
                             f"the same System, found {fe.system.name!r} and {com.system.name!r}")
        self.com, self.dyn = com, dyn
        basis = com.membrane
        self._nd = com.layout.n_delta
        self._P0 = basis.shapes[0]
        self._Psi = basis.shapes[1:1 + self._nd]
        # FE nodal field -> values at the COM basis nodes (reference coordinates in O_f)
        self._I = _probe(fe.topology.mesh.to_skfem(), self._P0[:2])
        topo = fe.topology
        self._system_node, self._n_mesh = topo.system_node, topo.n_mesh
        self._corners = topo.mesh.corners
        _, _, psi = q_index(com.system.M, com.system.N)
        self._psi = psi.ravel()
        self.psi_branch = None

    def bar_coordinates(self, x, xf=None) -> np.ndarray:
        """q of the free-DOF FE state x (the rigid fit or the chords, ``bars``); ``xf``: its
        node positions when already computed (``dyn.positions(x)``)."""
        if self.bars == "rigid":
            return rigid_bar_fit(self.com.system, *self.dyn.bar_chain_positions(x))
        xf = self.dyn.positions(x) if xf is None else xf
        return q_from_positions(self.com.system, xf[:, self._system_node])

    def modal(self, x) -> np.ndarray:
        """[q, eta] (modal coordinates) of the free-DOF FE positions x; the azimuths psi on the
        turn of ``psi_branch`` (each within pi of it) when it is set."""
        xf = self.dyn.positions(x)
        q = self.bar_coordinates(x, xf)
        if self.psi_branch is not None:
            # whole turns only: an azimuth already on the branch's turn is returned bit for bit
            q[self._psi] += 2 * np.pi * np.round((self.psi_branch - q[self._psi]) / (2 * np.pi))
        xm = xf[:, :self._n_mesh]
        r = to_floating((self._I @ xm.T).T, xm[:, self._corners])
        delta = self.com.zeta(q)[:self._nd]
        d_rel = r - self._P0 - np.einsum("k,kcn->cn", delta, self._Psi)
        return np.concatenate([q, self.com.membrane.modal_coordinates(d_rel)])

    def state(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """(z, z') in the COM's coordinates (modal, or the point coordinates of eq. 5.18).
        The azimuths psi are counted continuously, as a multi-turn encoder would: each on the
        turn nearest to the previous estimate's (``psi_branch``, which this call updates), so
        that a bar whose azimuth passes +-pi does not jump by 2 pi."""
        x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
        zm = self.modal(x)
        self.psi_branch = zm[self._psi].copy()
        vmax = float(np.max(np.abs(v))) if v.size else 0.0
        if vmax == 0.0:
            zdm = np.zeros_like(zm)
        else:
            h = RATE_STEP / vmax
            dz = self.modal(x + h * v) - self.modal(x - h * v)
            dz[self._psi] = np.remainder(dz[self._psi] + np.pi, 2 * np.pi) - np.pi
            zdm = dz / (2 * h)
        P = self.com.P
        return np.linalg.solve(P, zm), np.linalg.solve(P, zdm)


class FEStatePlant:
    """An FE plant whose outputs are the estimated COM state y = [z, z'] (module docstring).

    Parameters
    ----------
    dyn : FEPlant
    com : ControlOrientedModel
    x0, v0 : ndarray, optional
        Start state (free DOFs); default the plant's own (its equilibrium and perturbation).
    bars : {"chord", "rigid"}, optional
        How the estimate measures q (:class:`COMStateEstimator`; default
        :func:`default_bar_measure`: rigid on the SBC plant, chord on the MTC plant).
    actuation : {"rest-length", "force"}, optional
        What the commanded rest lengths u_c do (:meth:`actuate`): set the FE tendons' rest
        lengths (default, the dissertation's actuators) or be turned into the COM's tendon
        tension at the measured q, which tension-servoed winches realise on the FE tendons
        (:mod:`tmfem.control.fe_plant.tension_actuation`).
    q_start : array, optional
        Bar coordinates of the start (the COM's q of the packaged design): the turn on which
        the estimate counts the azimuths psi from the first sample on
        (:meth:`COMStateEstimator.state`); default the turn (-pi, pi].
    """

    def __init__(self, dyn, com, *, x0=None, v0=None, bars: str | None = None,
                 actuation: str = "rest-length", q_start=None):
        if actuation not in ACTUATIONS:
            raise InputError(f"plant actuation: expected one of {ACTUATIONS}, found {actuation!r}")
        self.actuation, self.com = actuation, com
        self.dyn, self.estimator = dyn, COMStateEstimator(com, dyn, bars=bars)
        if q_start is not None:
            self.estimator.psi_branch = np.asarray(q_start, dtype=float)[self.estimator._psi]
        self.input_names = list(dyn.input_names)
        if self.input_names != list(com.input_names):
            raise InputError(f"FE plant: expected the COM's inputs {com.input_names}, found "
                             f"{self.input_names}")
        self.output_names = list(com.state_names)
        self.predictor = getattr(dyn, "predictor", "acceleration")
        self.u0 = dyn.u0
        self.x0 = dyn.x0 if x0 is None else np.asarray(x0, dtype=float)
        self.v0 = dyn.v0 if v0 is None else np.asarray(v0, dtype=float)
        if self.x0.shape != dyn.x0.shape or self.v0.shape != dyn.v0.shape:
            raise InputError(f"FE plant start state: expected {dyn.x0.shape} free DOFs, found "
                             f"{self.x0.shape} and {self.v0.shape}")

    def actuate(self, x, u) -> np.ndarray:
        """The FE tendons' rest lengths for the commanded rest lengths u at the sampled state x
        (:func:`tmfem.simulation.driver.simulate` holds them over the step): u itself
        (``actuation="rest-length"``), or (``"force"``) those whose FE tendon forces at their
        measured lengths are the COM's tension T_d = max(0, k (|d(q)| - u)) at the measured q
        (:mod:`tmfem.control.fe_plant.tension_actuation`)."""
        if self.actuation == "rest-length":
            return np.asarray(u, dtype=float)
        return rest_length_for_tension(self.dyn.model, fe_element_lengths(self.dyn, x),
                                       self.tension_demand(x, u))

    def tension_demand(self, x, u) -> np.ndarray:
        """T_d [N] of the force actuator: the COM's tendon forces at the q measured from the
        FE state x under the commanded rest lengths u (:func:`tension_demand`)."""
        return tension_demand(self.com, self.estimator.bar_coordinates(x), u)

    def sample(self, x, u) -> None:
        """The FE plant's per-sample hook (:meth:`tmfem.models.fe.plant.FEPlant.sample`) at
        the sampled state x under the model input u (:meth:`actuate`'s)."""
        self.dyn.sample(x, u)

    def residual(self, x, v, a, t, u=None):
        return self.dyn.residual(x, v, a, t, u)

    def jacobians(self, x, v, a, t, u=None):
        return self.dyn.jacobians(x, v, a, t, u)

    def newton_matrix(self, x, v, a, t, cv, ca, u=None):
        return self.dyn.newton_matrix(x, v, a, t, cv, ca, u)

    def factorize(self, S):
        return self.dyn.factorize(S)

    def outputs(self, x, v=None, u=None) -> np.ndarray:
        """y = [z, z'], the COM state estimated from the FE state."""
        z, zd = self.estimator.state(x, np.zeros_like(x) if v is None else v)
        return np.concatenate([z, zd])

    def recover(self, states, inputs, *, stress_every: int = 10) -> dict:
        """What the FE model alone knows over a run, from its recorded states (n, n_free) and
        commanded inputs (n, n_t): the membrane deflections w_k its sensors measure at the
        plant's output points (eqs. 5.36-5.38, :meth:`FEPlant.outputs`), the forces of its
        tension-only tendon elements (``tendon_force``, (n, n_t): the mean of each tendon's
        elements), how often one went slack and which (the COM's tendons
        cannot), its bar compression (the SBC model: the larger of the two segments of a bar
        carrying H_1j) and, every ``stress_every`` samples, its membrane's peak stresses
        (``dyn.membrane_stress``: the MTC membrane's Gauss points, the SBC shell's three
        surfaces). ``slack``: the number of slack tendon elements per sample. The FE rest
        lengths are those :meth:`actuate` set at each sample; with force actuation also the
        tension demand T_d and those rest lengths (``tension_demand``, ``fe_rest_lengths``,
        (n, n_t)), the largest |T - T_d| of the tendons at the samples and the smallest FE
        margin L - r (L the FE tendon length).
        """
        dyn = self.dyn
        nq = len(dyn.model.system.q_names)
        w, T, Te, bar, vm, p1, slack_t, Td, R, L = [], [], [], [], [], [], [], [], [], []
        force = self.actuation == "force"
        for k, (x, uc) in enumerate(zip(states, inputs)):
            w.append(dyn.outputs(x)[nq:])
            u = self.actuate(x, uc)
            if force:
                Td.append(self.tension_demand(x, uc))
                R.append(u)
                L.append(fe_tendon_lengths(dyn, x))
            dyn.model.set_tendon_lengths(u)
            m = dyn.member_forces(x)
            T.append(m["tendon_force"])
            Te.append(m["element_force"])
            bar.append(m["bar_force"])
            slack_t.append(m["tendon_slack"])
            if k % stress_every == 0:
                st = dyn.membrane_stress(x)
                vm.append(st["max_von_mises"])
                p1.append(st["max_sigma_p1"])
        dyn.model.set_tendon_lengths(dyn.u0)
        T, Te, bar = np.array(T), np.array(Te), np.array(bar)
        slack = np.sum(Te <= 0.0, axis=1)
        extra = {}
        if force:
            Td, R = np.array(Td), np.array(R)
            extra = {"tension_demand": Td, "fe_rest_lengths": R,
                     "max_tension_error_N": float(np.max(np.abs(T - Td))),
                     "min_fe_rest_length_margin_m": float(np.min(np.array(L) - R))}
        return {"w": np.array(w), "tendon_force": T, "actuation": self.actuation, **extra,
                "model": dyn.name, "free_dofs": int(dyn.x0.size),
                "max_tendon_stress_Pa": float(np.max(T / dyn.model.tendon_area)),
                "min_tendon_force_N": float(np.min(T)),
                "tendon_slack_samples": int(np.sum(slack > 0)),
                "tendon_slack_elements_max": int(np.max(slack)),
                "peak_bar_compression_N": float(max(0.0, -np.min(bar))),
                "max_von_mises_Pa": float(np.max(vm)), "max_sigma_p1_Pa": float(np.max(p1)),
                "slack_tendons": [t.name for t, s in zip(dyn.model.system.tendons,
                                                         np.any(slack_t, axis=0)) if s],
                "slack": slack}


def com_positions(com, mtc, z) -> np.ndarray:
    """Node positions (3, n_nodes) of the MTC model ``mtc`` (of the COM's system) in the
    configuration of the COM state z: labelled nodes at q (eqs. 3.1-3.2), membrane nodes on
    the COM's field (eqs. 5.1, 5.3, interpolated from the COM basis nodes at the FE reference
    nodes), dependent nodes from their masters, tendon internal nodes on the chords."""
    if mtc.system is not com.system:
        raise InputError("FE start state: expected the FE model and the control-oriented model of "
                         "the same System")
    topo = mtc.topology
    zm = com.P @ np.asarray(z, dtype=float)
    x = np.zeros((3, topo.n_nodes))
    x[:, topo.system_node] = com.system.nodes(zm[:com.nq])
    xm, _ = com.membrane_positions(z)
    x[:, :topo.n_mesh] = (_probe(com.membrane.scalar_basis.mesh, topo.mesh.p) @ xm.T).T
    return mtc.with_straight_tendons(mtc.full(mtc.reduce(x)))


def fe_state_of(com, dyn, z, zd=None, *, step: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Free-DOF state and velocity of the FE plant ``dyn`` in the configuration of the COM
    state (z, z'): :func:`com_positions` on the placement numbering of ``dyn.model``, then
    ``dyn.state_of`` (the SBC model's bars straight, its rotations those of ``dyn``'s
    reference state); velocities by a central difference of that placement along z'
    (``step`` in the coordinates).
    """
    def place(zz):
        return dyn.state_of(com_positions(com, dyn.model, zz))

    z = np.asarray(z, dtype=float)
    x = place(z)
    if zd is None or not np.any(zd):
        return x, np.zeros_like(x)
    zd = np.asarray(zd, dtype=float)
    return x, (place(z + step * zd) - place(z - step * zd)) / (2 * step)


def packaged_state(com, initial) -> np.ndarray:
    """The COM state z (eq. 5.18's coordinates) of the packaged design ``initial``: its bars
    at q, eta = 0."""
    return np.linalg.solve(com.P, np.concatenate([np.asarray(initial.q, dtype=float),
                                                  np.zeros(com.K)]))


def start_rest_lengths(initial, tendon_law: str, nominal) -> np.ndarray:
    """Rest lengths that hold the packaged design ``initial`` (a System with its designed
    rest lengths) in equilibrium under a plant's tendon law: the design's tendon forces
    T = EA (|d| - r) / r (eqs. 3.8-3.9) produced by k = EA / r (``"cable"``: the design's own
    rest lengths) or by the fixed rate k = EA / r_0 of the ``nominal`` rest lengths
    (``"fixed-rate"``: r = |d| - T r_0 / EA)."""
    if initial.rest_lengths is None:
        raise InputError(f"FE plant start: expected designed rest lengths in {initial.name!r}, "
                         "found none")
    r = np.asarray(initial.rest_lengths, dtype=float)
    if tendon_law == "cable":
        return r
    EA = initial.tendon_EA
    L = initial.tendon_lengths(initial.q)
    T = EA * (L - r) / r
    return L - T * np.asarray(nominal, dtype=float) / EA


#: the damping tangent of a damped deployment plant when none is given (docs/guides/fe-plant.md,
#: "Plant damping along the path")
DEPLOYMENT_DAMPING_TANGENT = "current"


def deployment_damping_tangent(damping_tangent, beta: float):
    """The damping tangent of a deployment plant: the given one, else
    :data:`DEPLOYMENT_DAMPING_TANGENT` where there is stiffness-proportional damping (beta >
    0; none without it, :func:`tmfem.models.fe.plant.check_damping_tangent`)."""
    if damping_tangent is None and beta:
        return DEPLOYMENT_DAMPING_TANGENT
    return damping_tangent


def mtc_deployment_plant(com, initial, *, mesh_n: int = 10, tendon_elements: int = 3,
                         tendon_law: str = "cable", beta: float = 0.0,
                         actuation: str = "rest-length",
                         damping_tangent: str | None = None) -> FEStatePlant:
    """The MTC model of the COM's system (its rest lengths, N x mesh_n x mesh_n membrane,
    ``tendon_elements`` trusses per tendon, the tendon law of :class:`MTCModel`) as the plant
    of a deployment, its sensors at the COM's output points.

    The start is the plant's own equilibrium at rest in the packaged configuration: from the
    placement of the COM configuration of ``initial`` (:func:`com_positions`, bars at its q, eta
    = 0) the FE statics are solved under :func:`start_rest_lengths` -- the bars take their
    axial strain, the membrane and tendons their FE shapes -- so that the run starts without
    the transient of an FE state out of equilibrium. ``beta``: stiffness-proportional
    Rayleigh damping C = beta K_0 of the plant (:class:`tmfem.models.fe.plant.FEPlant`);
    ``damping_tangent``: K_0 (``"initial"``) or the tangent at every sample (``"current"``,
    C_n = beta K_T(x_n)), default :data:`DEPLOYMENT_DAMPING_TANGENT`, only with beta > 0;
    ``actuation``: rest-length or tension-servoed tendons (:class:`FEStatePlant`)."""
    from tmfem.models.mtc.dynamics import MTCDynamics
    from tmfem.models.mtc.model import MTCModel
    fe = MTCModel(com.system, mesh_n=mesh_n, tendon_elements=tendon_elements,
                  rest_lengths=com.u0, tendon_law=tendon_law)
    dyn = MTCDynamics(fe, fe.equilibrium().x, output_points=com.output_points, beta=beta,
                      damping_tangent=deployment_damping_tangent(damping_tangent, beta))
    fe.set_tendon_lengths(start_rest_lengths(initial, tendon_law, com.u0))
    st = fe.equilibrium(x0=com_positions(com, fe, packaged_state(com, initial)))
    fe.set_tendon_lengths(com.u0)
    return FEStatePlant(dyn, com, x0=fe.reduce(st.x)[fe.free], actuation=actuation, q_start=initial.q)


def sbc_deployment_plant(com, initial, *, mesh_n: int = 10, tendon_elements: int = 3,
                         bar_elements: int = 1, bars: str = "rigid",
                         beta: float = 0.0, actuation: str = "rest-length",
                         damping_tangent: str | None = None) -> FEStatePlant:
    """The SBC model of the COM's system (MITC4 shell membrane, four-node beam bars -- with
    H_1j a node of the bar for a 1-N(D) system --, tension-only tendons of the cable law
    k = EA / r, its sensors at the COM's output points) as the plant of a deployment.

    The plant's reference state (rotation vectors counted from it, mass at its directors,
    :class:`SBCDynamics`) is its own equilibrium at rest in the packaged configuration, so
    the run starts at u = 0: the COM configuration of ``initial`` (bars at its q, eta = 0) is
    placed on the SBC model's MTC numbering (:func:`com_positions`), solved there
    with the MTC model of rigid bar points (the SBC statics' predictor) under the packaged
    design's rest lengths (:func:`start_rest_lengths`, ``"cable"``), mapped onto the SBC
    unknowns (:meth:`SBCModel.state_from_mtc`: shell directors on the membrane normals, bar
    triads turned with the chords) and Newton's method finishes on the SBC model, whose bars
    then bend under the tendons at H_1j. ``bars``: how the estimate measures q (the rigid fit
    of the beam nodes, default, or the bar chords, which see the bending modes,
    :class:`COMStateEstimator`); ``beta``: stiffness-proportional
    Rayleigh damping C = beta K_0 (K_0 at that equilibrium; docs/guides/fe-plant.md: without it the
    undamped SBC plant's Park integration diverges during the 1-4(D) deployment even under
    the COM run's smooth rest lengths); ``damping_tangent``: K_0 (``"initial"``) or the
    tangent at every sample (``"current"``, C_n = beta K_T(x_n), which does not damp the bars'
    rigid rotation), default :data:`DEPLOYMENT_DAMPING_TANGENT`, only with beta > 0;
    ``actuation``: rest-length or tension-servoed tendons (:class:`FEStatePlant`)."""
    from tmfem.models.sbc.dynamics import SBCDynamics
    from tmfem.models.sbc.model import SBCModel
    sbc = SBCModel(com.system, mesh_n=mesh_n, tendon_elements=tendon_elements,
                   bar_elements=bar_elements, rest_lengths=com.u0)
    sbc.set_tendon_lengths(start_rest_lengths(initial, "cable", com.u0))
    mtc = sbc.predictor()
    pre = mtc.equilibrium(x0=com_positions(com, mtc, packaged_state(com, initial)))
    st = sbc.equilibrium(start=sbc.state_from_mtc(pre.x))
    sbc.set_tendon_lengths(com.u0)
    dyn = SBCDynamics(sbc, st.state, output_points=com.output_points, beta=beta,
                      damping_tangent=deployment_damping_tangent(damping_tangent, beta))
    return FEStatePlant(dyn, com, bars=bars, actuation=actuation, q_start=initial.q)


#: the plants a deployment can run on: the COM it is designed on and the two FE models
PLANTS = ("com", "mtc", "sbc")


def deployment_plant(kind: str, com, initial, *, mesh_n: int = 10,
                     tendon_law: str | None = None, bars: str | None = None, beta: float = 0.0,
                     actuation: str = "rest-length", damping_tangent: str | None = None):
    """The plant ``kind`` of a deployment of the COM's system from the packaged design
    ``initial``: None for ``"com"`` (:func:`tmfem.control.deployment.run.run_deployment` builds the
    COM plant), :func:`mtc_deployment_plant` (``tendon_law`` default ``"cable"``) or
    :func:`sbc_deployment_plant` (the SBC model has the cable law only: ``"fixed-rate"`` is
    refused; ``bars``: its bar measurement, default ``"rigid"``, refused on the other plants);
    ``beta``: the FE plant's Rayleigh damping C = beta K_0 (refused for the COM) and
    ``damping_tangent`` its tangent (:func:`sbc_deployment_plant`; refused for the COM and
    without beta);
    ``actuation``: the FE plant's tendon actuators (:class:`FEStatePlant`; ``"force"`` refused
    for the COM, the design model whose tendons the force actuator imitates)."""
    if kind not in PLANTS:
        raise InputError(f"plant: expected one of {list(PLANTS)}, found {kind!r}")
    if bars is not None and kind != "sbc":
        raise InputError(f"bar measurement {bars!r}: expected the SBC plant (beam bars with "
                         f"nodes along them), found the {kind} plant")
    if beta and kind == "com":
        raise InputError(f"plant damping beta = {beta}: expected an FE plant (mtc, sbc), found "
                         "the COM plant (its damping is the design model's)")
    if damping_tangent is not None and kind == "com":
        raise InputError(f"plant damping tangent {damping_tangent!r}: expected an FE plant (mtc, "
                         "sbc), found the COM plant (it has no FE damping)")
    if actuation not in ACTUATIONS:
        raise InputError(f"plant actuation: expected one of {ACTUATIONS}, found {actuation!r}")
    if actuation != "rest-length" and kind == "com":
        raise InputError(f"plant actuation {actuation!r}: expected an FE plant (mtc, sbc), found "
                         "the COM plant (the design model: its tendon forces are the ones the "
                         "force actuator reproduces on an FE plant)")
    if kind == "com":
        return None
    if kind == "sbc":
        if tendon_law not in (None, "cable"):
            raise InputError(f"SBC plant tendons: the SBC model has the cable law only (EA fixed, "
                             f"k = EA / r); expected 'cable', found {tendon_law!r}")
        return sbc_deployment_plant(com, initial, mesh_n=mesh_n, bars=bars or "rigid", beta=beta,
                                    actuation=actuation, damping_tangent=damping_tangent)
    return mtc_deployment_plant(com, initial, mesh_n=mesh_n, tendon_law=tendon_law or "cable",
                                beta=beta, actuation=actuation, damping_tangent=damping_tangent)

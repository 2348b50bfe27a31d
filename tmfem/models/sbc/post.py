"""Result summaries of the SBC model (6.2, 6.4): landing against the design, member forces,
bar bending moments, frequencies beside Tables 6.6/6.7."""
from __future__ import annotations

import numpy as np

from tmfem.models.mtc.post import q_from_positions
from tmfem.system.coordinates import q_index
from tmfem.system.topology import label


def static_summary(model, result) -> dict:
    """Summary of an SBC equilibrium ``result`` (:class:`SBCStaticResult`) of ``model``:
    iterations, residual history, the largest distance of a labelled node from the design,
    the corner offset Delta (mean corner radius - r_mb), tendon forces and stresses, bar axial
    forces and the largest bar bending moment |M| [N m] at the Gauss points."""
    sysm, st = model.system, result.state
    mt = model.mtc.topology
    X = sysm.nodes()
    x = st.x[:, mt.system_node]
    f = model.member_forces(st)
    sec = model.beam.section_forces(st)
    c = st.x[:, mt.mesh.corners]
    out = {"system": sysm.name, "model": "sbc", "dofs": model.ndof, "mesh_n": mt.mesh.n,
           "tendon_elements": mt.tendon_elements, "bar_elements": model.numbering.bar_elements,
           "attachment": mt.attachment, "membrane_law": model.shell.law.name,
           "rest_lengths_source": model.mtc.rest_lengths_source,
           "rest_lengths": {t.name: float(r) for t, r in zip(sysm.tendons, model.rest_lengths)},
           "iterations": result.iterations, "static_time_s": result.time,
           "residual_history": [float(v) for v in result.residual_history],
           "max_deviation_from_design": float(np.linalg.norm(x - X, axis=0).max()),
           "tendon_force": f["tendon"].tolist(),
           "tendon_stress_max": float(np.max(f["tendon"] / model.mtc.tendon_area)),
           "bar_force": f["bar"].tolist(), "bar_load_max": float(np.max(np.abs(f["bar"]))),
           "bar_moment_max": float(np.max(np.hypot(sec["M1"], sec["M2"]))),
           "monitor": {k: v.tolist() for k, v in result.monitor.items()}}
    if sysm.r_mb is not None:
        r = np.linalg.norm(c - c.mean(axis=1, keepdims=True), axis=0)
        out["Delta_mean"] = float(r.mean() - sysm.r_mb)
    out["top_nodes"] = {label("B", sysm.M, j): x[:, sysm.node_index(label("B", sysm.M, j))].tolist()
                        for j in range(1, sysm.N + 1)}
    out.update(bar_angles(sysm, x))
    out["predictor_iterations"] = result.predictor_iterations
    if sysm.deployable:
        out["bar_bow"] = bar_bow(sysm, x).tolist()
    return out


def bar_angles(system, x: np.ndarray) -> dict:
    """theta_ij, psi_ij [deg] of the bar chords A_ij -> B_ij at labelled positions x (3.2,
    :func:`tmfem.models.mtc.post.q_from_positions`) and at the design."""
    q = q_from_positions(system, x)
    _, ti, pi_ = q_index(system.M, system.N)
    deg = lambda v: np.degrees(v).ravel().tolist()          # noqa: E731
    return {"theta_deg": deg(q[ti]), "theta_design_deg": deg(system.q[ti]),
            "psi_deg": deg(q[pi_]), "psi_design_deg": deg(system.q[pi_])}


def bar_bow(system, x: np.ndarray) -> np.ndarray:
    """Distance [m] of each H_1j from the chord A_1j B_1j of its bar at labelled positions x
    (3, n_labels): the bending deflection at the tendon attachment (1-N(D))."""
    nb = system.N
    A, B, H = x[:, :nb], x[:, nb:2 * nb], x[:, 2 * nb:]
    u = (B - A) / np.linalg.norm(B - A, axis=0)
    d = H - A
    return np.linalg.norm(d - np.sum(d * u, axis=0) * u, axis=0)


def format_static(r: dict) -> str:
    """Text of :func:`static_summary` (and of the modes when present)."""
    lines = [f"SBC model of {r['system']}: mesh n={r['mesh_n']}, {r['tendon_elements']} elements/"
             f"tendon, {r['bar_elements']} beam element(s)/bar, {r['attachment']} attachment, "
             f"{r['membrane_law']} lamina, {r['dofs']} free dofs",
             f"converged in {r['predictor_iterations']} MTC predictor + {r['iterations']} SBC "
             f"iterations ({r['static_time_s']:.2f} s); residual "
             f"{r['residual_history'][0]:.3e} -> {r['residual_history'][-1]:.3e} N",
             f"max distance of a node from the design: {r['max_deviation_from_design'] * 1e3:.3f} mm"
             + (f"; Delta {r['Delta_mean'] * 1e3:.4f} mm" if "Delta_mean" in r else ""),
             "theta [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["theta_deg"], r["theta_design_deg"])),
             "psi   [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["psi_deg"], r["psi_design_deg"])),
             f"max tendon stress {r['tendon_stress_max'] / 1e6:.2f} MPa, max bar load "
             f"{r['bar_load_max']:.3f} N, max bar bending moment {r['bar_moment_max']:.3e} N m"]
    if "bar_bow" in r:
        lines.append("bending deflection of the bars at H_1j [mm]: "
                     + ", ".join(f"{v * 1e3:.3f}" for v in r["bar_bow"]))
    if "freq_hz" in r:
        d = r.get("dissertation")
        lines.append(f"{'mode':>4s} {'SBC [Hz]':>10s}" + (f" {'SBC paper':>10s} {'diff':>8s}   ({d['source']})"
                                                          if d else ""))
        for i, fr in enumerate(r["freq_hz"]):
            if d and i < len(d["SBC"]):
                lines.append(f"{i + 1:4d} {fr:10.4f} {d['SBC'][i]:10.4f} {100 * (fr / d['SBC'][i] - 1):7.2f}%")
            else:
                lines.append(f"{i + 1:4d} {fr:10.4f}")
    return "\n".join(lines)


def modal_summary(model, result, modes) -> dict:
    """:func:`static_summary` plus the frequencies of ``modes`` (eq. 5.32)."""
    out = static_summary(model, result)
    out["freq_hz"] = modes.freq_hz.tolist()
    return out

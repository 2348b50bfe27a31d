"""Result summaries of the SBC model (6.2, 6.4): landing against the design, member forces,
bar bending moments, membrane stress peaks, the checks of the design and Tables 6.3/6.5,
frequencies beside Tables 6.6/6.7."""
from __future__ import annotations

import numpy as np

from tmfem.models.fe.outputs import q_from_positions
from tmfem.models.fe.summary import bar_loads, check_lines, design_checks, printed_lines
from tmfem.system.coordinates import q_index
from tmfem.system.topology import label

#: surfaces of :meth:`MITC4Shell.stresses` (r_3 = -1, 0, 1)
SURFACES = ("bottom", "mid", "top")


def shell_stresses(model, state) -> dict:
    """Principal stresses sigma_p1 >= sigma_p2 and von Mises stress [Pa] of the shell at the
    element centres and at the 2 x 2 Gauss points, on the bottom, middle and top surfaces.

    The shell's stresses are second Piola-Kirchhoff components in the element results frame of
    eq. 4.16 (:meth:`tmfem.fem.mitc4.MITC4Shell.stresses`); principal values and von Mises
    (eqs. 5.29-5.30, in-plane with the transverse shear) do not depend on the in-plane frame,
    so they are those of the floating frame O_f. Returns ``centre`` and ``gauss`` dicts of
    arrays (3 surfaces, ne) and (3 surfaces, ne, 4).
    """
    sh = model.shell
    out = {}
    for key, pts in (("centre", [(0.5, 0.5)]), ("gauss", list(sh._gxi.T))):
        p1, p2, vm = [], [], []
        for xi in pts:
            s = sh.stresses(state, xi=tuple(xi))
            s11, s22, s12 = s["sigma"][..., 0], s["sigma"][..., 1], s["sigma"][..., 2]
            c, r = 0.5 * (s11 + s22), np.hypot(0.5 * (s11 - s22), s12)
            p1.append((c + r).T)
            p2.append((c - r).T)
            vm.append(s["von_mises"].T)
        out[key] = {"sigma_p1": np.stack(p1, -1), "sigma_p2": np.stack(p2, -1),
                    "von_mises": np.stack(vm, -1)}
    out["centre"] = {k: v[..., 0] for k, v in out["centre"].items()}
    return out


def membrane_peaks(model, state) -> dict:
    """Peak membrane stresses [Pa] of an SBC state (Tables 6.3, 6.5): the largest sigma_p1 and
    von Mises over the 2 x 2 Gauss points on each surface and over all three
    (``max_sigma_p1``, ``max_von_mises``), the element-centre maxima on the mid surface (the
    counterpart of the MTC model's element means), the smallest mid-surface sigma_p2 and the
    fractions of mid-surface Gauss points taut (sigma_p2 > 0), wrinkled (sigma_p2 <= 0 <
    sigma_p1) and slack (sigma_p1 <= 0), the tension-field criterion of the MTC model's
    membrane (:mod:`tmfem.fem.tension_field`) applied to the shell's stresses."""
    st = shell_stresses(model, state)
    g, c = st["gauss"], st["centre"]
    out = {f"max_{k}_{s}": float(g[k][i].max()) for k in ("sigma_p1", "von_mises")
           for i, s in enumerate(SURFACES)}
    out["max_sigma_p1"] = max(out[f"max_sigma_p1_{s}"] for s in SURFACES)
    out["max_von_mises"] = max(out[f"max_von_mises_{s}"] for s in SURFACES)
    out["max_sigma_p1_element_centre"] = float(c["sigma_p1"][1].max())
    out["max_von_mises_element_centre"] = float(c["von_mises"][1].max())
    out["min_sigma_p2_mid"] = float(g["sigma_p2"][1].min())
    p1, p2 = g["sigma_p1"][1], g["sigma_p2"][1]
    out["state_fractions"] = {"taut": float(np.mean(p2 > 0)),
                              "wrinkled": float(np.mean((p2 <= 0) & (p1 > 0))),
                              "slack": float(np.mean(p1 <= 0))}
    return out


def static_summary(model, result) -> dict:
    """Summary of an SBC equilibrium ``result`` (:class:`~tmfem.models.base.Equilibrium`) of ``model``:
    iterations (MTC predictor and SBC), residual history, landing against the design (largest
    node distance, theta, psi of the bar chords, the corner offsets Delta), tendon forces and stresses, bar axial forces
    and loads
    (per stage for M >= 2) and the largest bar bending moment |M| [N m] at the Gauss points,
    the membrane stress peaks (:func:`membrane_peaks`), the design checks
    (:func:`tmfem.models.mtc.post.design_checks`), the printed Table 6.3/6.5 values and, for
    1-N(D) systems, the bars' bending deflection at H_1j."""
    sysm, st = model.system, result.state
    mt = model.topology
    X = sysm.nodes()
    x = st.x[:, mt.system_node]
    f = model.member_forces(st)
    sec = model.beam.section_forces(st)
    c = st.x[:, mt.mesh.corners]
    stress = f["tendon"] / model.tendon_area
    slack = f["tendon_element"].reshape(len(sysm.tendons), -1).min(axis=1) <= 0
    peaks = membrane_peaks(model, st)
    out = {"system": sysm.name, "model": "sbc", "dofs": model.ndof, "mesh_n": mt.mesh.n,
           "tendon_elements": mt.tendon_elements, "bar_elements": model.numbering.bar_elements,
           "attachment": mt.attachment, "membrane_law": model.shell.law.name,
           "rest_lengths_source": model.rest_lengths_source,
           "rest_lengths": {t.name: float(r) for t, r in zip(sysm.tendons, model.rest_lengths)},
           "iterations": result.iterations, "static_time_s": result.time,
           "residual_history": [float(v) for v in result.residual_history],
           "max_deviation_from_design": float(np.linalg.norm(x - X, axis=0).max()),
           "tendon_force": f["tendon"].tolist(),
           "tendon_stress_max": float(np.max(stress)),
           "tendon_slack": [t.name for t, s_ in zip(sysm.tendons, slack) if s_],
           "bar_force": f["bar"].tolist(), **bar_loads(sysm, f["bar"]),
           "bar_moment_max": float(np.max(np.hypot(sec["M1"], sec["M2"]))),
           **{f"membrane_{k}": v for k, v in peaks.items()},
           "checks": design_checks(sysm, sigma_p1=peaks["max_sigma_p1"],
                                   von_mises=peaks["max_von_mises"], tendon_stress=stress,
                                   tendon_yield=model.tendon_yield, tendon_slack=slack,
                                   bar_force=f["bar"]),
           "printed": dict(sysm.printed),
           "monitor": {k: v.tolist() for k, v in result.monitor.items()}}
    if sysm.r_mb is not None:
        r = np.linalg.norm(c - c.mean(axis=1, keepdims=True), axis=0)
        out["Delta"] = (r - sysm.r_mb).tolist()
        out["Delta_mean"] = float(r.mean() - sysm.r_mb)
        B = X[:, [sysm.node_index(label("B", sysm.M, j)) for j in range(1, sysm.N + 1)]]
        out["Delta_design_mean"] = float(np.linalg.norm(B - B.mean(axis=1, keepdims=True), axis=0).mean()
                                         - sysm.r_mb)
    out["top_nodes"] = {label("B", sysm.M, j): x[:, sysm.node_index(label("B", sysm.M, j))].tolist()
                        for j in range(1, sysm.N + 1)}
    out.update(bar_angles(sysm, x))
    out["predictor_iterations"] = result.predictor_iterations
    if sysm.deployable:
        out["bar_bow"] = bar_bow(sysm, x).tolist()
    return out


def bar_angles(system, x: np.ndarray) -> dict:
    """theta_ij, psi_ij [deg] of the bar chords A_ij -> B_ij at labelled positions x (3.2,
    :func:`tmfem.models.fe.outputs.q_from_positions`) and at the design."""
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
             + (f"; Delta {r['Delta_mean'] * 1e3:.4f} mm" if "Delta_mean" in r else "")
             + (f" (design {r['Delta_design_mean'] * 1e3:.4f} mm)" if "Delta_design_mean" in r else ""),
             "theta [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["theta_deg"], r["theta_design_deg"])),
             "psi   [deg] (design): " + ", ".join(f"{a:.3f} ({b:.3f})" for a, b in
                                                   zip(r["psi_deg"], r["psi_design_deg"])),
             f"max bar bending moment {r['bar_moment_max']:.3e} N m; membrane peaks at the Gauss "
             f"points [MPa], sigma_p1 bottom/mid/top "
             + "/".join(f"{r[f'membrane_max_sigma_p1_{s}'] / 1e6:.3f}" for s in SURFACES)
             + ", von Mises " + "/".join(f"{r[f'membrane_max_von_mises_{s}'] / 1e6:.3f}" for s in SURFACES)
             + f"; element-centre sigma_p1 {r['membrane_max_sigma_p1_element_centre'] / 1e6:.3f}"]
    lines += printed_lines(r, "SBC")
    if r["tendon_slack"]:
        lines.append(f"SLACK tendons: {r['tendon_slack']}")
    lines += check_lines(r["checks"])
    if "bar_bow" in r:
        lines.append("bending deflection of the bars at H_1j [mm]: "
                     + ", ".join(f"{v * 1e3:.3f}" for v in r["bar_bow"]))
    if 0 < r.get("Delta_mean", 0) < 0.5 * r.get("Delta_design_mean", 0):
        lines.append(f"note: the membrane keeps {100 * r['Delta_mean'] / r['Delta_design_mean']:.0f} % of the "
                     "design's corner displacement Delta (eq. 3.22; the design takes the bars rigid): its "
                     "prestress, stresses and frequencies are below the design's; stiffer bars or a larger "
                     "Delta (`tmfem equilibrium FILE --target-delta MM`) bring them closer")
    if "freq_hz" in r:
        d = r.get("dissertation")
        lines.append(f"{'mode':>4s} {'SBC [Hz]':>10s}" + (f" {'SBC paper':>10s} {'diff':>8s}   ({d['source']})"
                                                          if d else ""))
        for i, fr in enumerate(r["freq_hz"]):
            if d and i < len(d["SBC"]):
                lines.append(f"{i + 1:4d} {fr:10.4f} {d['SBC'][i]:10.4f} {100 * (fr / d['SBC'][i] - 1):7.2f}%")
            else:
                lines.append(f"{i + 1:4d} {fr:10.4f}")
    lines += [f"wrote {r[k]}" for k in ("vtk", "png") if k in r]
    return "\n".join(lines)


def modal_summary(model, result, modes) -> dict:
    """:func:`static_summary` plus the frequencies of ``modes`` (eq. 5.32)."""
    out = static_summary(model, result)
    out["freq_hz"] = modes.freq_hz.tolist()
    return out

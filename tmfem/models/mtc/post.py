"""Post-processing of MTC results: landing vs design, member forces, membrane stresses in the
floating frame, design checks (dissertation 6.2, Tables 6.2-6.7, eqs. 3.22, 5.29-5.31).
"""
from __future__ import annotations

import numpy as np

from tmfem.fem.truss import truss_internal
from tmfem.models.fe.outputs import q_from_positions
from tmfem.models.fe.summary import bar_loads, design_checks
from tmfem.system.topology import label

def member_state(model, x: np.ndarray) -> dict:
    """Bar and tendon forces at positions x (3, n_nodes).

    Tendon force = mean axial force of its k elements (equal in statics: no gravity);
    slack = any element slack; ``element_force`` the axial force of every tendon element.
    """
    tb = truss_internal(x, model.bars, tangent=False)
    tt = truss_internal(x, model.tendons, tangent=False)
    e = model.topology.tendon_of_element
    nt = len(model.system.tendons)
    T = np.bincount(e, weights=tt.N, minlength=nt) / np.bincount(e, minlength=nt)
    slack = np.bincount(e, weights=tt.slack.astype(float), minlength=nt) > 0
    return {"bar_force": tb.N, "tendon_force": T, "tendon_slack": slack,
            "tendon_stress": T / model.tendon_area, "element_force": tt.N}


def membrane_stress_summary(model, x: np.ndarray) -> dict:
    """Membrane stresses (Cauchy, in the floating frame: reference axes rotated with the
    material) and their maxima at the Gauss points (eqs. 5.29-5.30, Tables 6.3, 6.5)."""
    xm = x[:, :model.topology.n_mesh]
    st = model.membrane.stresses(xm)
    p1 = st.principal[0]
    vm = st.von_mises
    wr = model.membrane.wrinkling(xm)
    return {"stresses": st, "membrane_law": model.membrane.law.name,
            "state_fractions": wr["fractions"],
            "max_sigma_p1": float(p1.max()), "max_von_mises": float(vm.max()),
            "min_minor_principal": float((st.principal[1] + st.principal[2]).min()),
            "wrinkled_fraction": float(np.mean(st.principal[1] + st.principal[2] < 0)),
            "max_sigma_p1_element_mean": float(st.principal_elem[0].max()),
            "max_von_mises_element_mean": float(st.von_mises_elem.max())}


def static_summary(model, x: np.ndarray, *, result=None) -> dict:
    """JSON-able summary of an MTC equilibrium: landing vs design, forces, stresses, checks.

    Parameters
    ----------
    model : MTCModel
    x : ndarray (3, n_nodes)
    result : Equilibrium, optional
        Adds the iteration count, residual history and the monitored-node history.
    """
    sysm = model.system
    topo = model.topology
    labels = sysm.node_labels
    X = x[:, topo.system_node]
    Xd = sysm.nodes()
    dev = np.linalg.norm(X - Xd, axis=0)
    q = q_from_positions(sysm, X)
    _, th, ps = sysm.split_q(q)
    _, thd, psd = sysm.split_q()
    M, N = sysm.M, sysm.N
    top = [labels.index(label("B", M, j)) for j in range(1, N + 1)]
    corners = X[:, top]
    centre = corners.mean(axis=1)
    r_mb = sysm.r_mb if sysm.r_mb else float(np.mean(np.linalg.norm(
        sysm.membrane_corners - sysm.membrane_corners.mean(axis=1, keepdims=True), axis=0)))
    delta = np.linalg.norm(corners - centre[:, None], axis=0) - r_mb
    cd = Xd[:, top]
    delta_design = np.linalg.norm(cd - cd.mean(axis=1, keepdims=True), axis=0) - r_mb
    ms = member_state(model, x)
    ss = membrane_stress_summary(model, x)
    loads = bar_loads(sysm, ms["bar_force"])
    checks = design_checks(sysm, sigma_p1=ss["max_sigma_p1"], von_mises=ss["max_von_mises"],
                           tendon_stress=ms["tendon_stress"], tendon_yield=model.tendon_yield,
                           tendon_slack=ms["tendon_slack"], bar_force=ms["bar_force"])

    out = {
        "system": sysm.name, "mesh_n": int(topo.mesh.n), "tendon_elements": topo.tendon_elements,
        "attachment": topo.attachment, "dofs": model.ndof,
        "rest_lengths_source": model.rest_lengths_source,
        "rest_lengths": {t.name: float(r) for t, r in zip(sysm.tendons, model.rest_lengths)},
        "nodes": {lab: {"x": X[:, i].tolist(), "design": Xd[:, i].tolist(),
                        "deviation": float(dev[i])} for i, lab in enumerate(labels)},
        "max_deviation_from_design": float(dev.max()),
        "theta_deg": np.degrees(th).ravel().tolist(), "theta_design_deg": np.degrees(thd).ravel().tolist(),
        "psi_deg": np.degrees(ps).ravel().tolist(), "psi_design_deg": np.degrees(psd).ravel().tolist(),
        "Delta": delta.tolist(), "Delta_design": delta_design.tolist(),
        "bar_force": ms["bar_force"].tolist(), **loads,
        "tendon_force": {t.name: float(f) for t, f in zip(sysm.tendons, ms["tendon_force"])},
        "tendon_stress_max": float(ms["tendon_stress"].max()),
        "tendon_slack": [t.name for t, s in zip(sysm.tendons, ms["tendon_slack"]) if s],
        "membrane_max_sigma_p1": ss["max_sigma_p1"], "membrane_max_von_mises": ss["max_von_mises"],
        "membrane_max_sigma_p1_element_mean": ss["max_sigma_p1_element_mean"],
        "membrane_min_minor_principal": ss["min_minor_principal"],
        "membrane_wrinkled_fraction": ss["wrinkled_fraction"],
        "membrane_law": ss["membrane_law"], "membrane_state_fractions": ss["state_fractions"],
        "membrane_max_von_mises_element_mean": ss["max_von_mises_element_mean"],
        "checks": checks, "printed": dict(sysm.printed),
    }
    if result is not None:
        out["iterations"] = int(result.iterations)
        out["residual_history"] = [float(v) for v in result.residual_history]
        out["static_time_s"] = float(result.time)
        out["monitor"] = {k: v.tolist() for k, v in result.monitor.items()}
    return out

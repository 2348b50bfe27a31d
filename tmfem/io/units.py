"""Units of the keys of the commands' JSON documents (``--json``): every document carries a
``units`` table {key: unit} for the keys it contains (SI; stresses in Pa unless the key says
MPa; angles in rad unless the key ends in ``_deg``), so no number is without its unit."""
from __future__ import annotations

import re
from tmfem.io.run import column_header

# exact keys, then suffix rules; first match wins
_EXACT = {
    "F_Delta": "N", "Delta": "m", "Delta_file": "m", "Delta_deployed": "m", "psi_deg_bands": "deg",
    "Delta_design": "m", "Delta_design_mean": "m", "Delta_mean": "m", "residual": "-",
    "nodes": "m", "tendon_forces": "N", "tendon_force": "N", "tendon_lengths": "m",
    "length": "m", "force": "N", "force_density": "N/m", "force_densities": "N/m",
    "rest_lengths": "m", "rest_length": "m", "design_rest_lengths": "m",
    "design_tendon_forces": "N", "equilibrium_tendon_forces": "N", "stress": "Pa",
    "tendon_stress": "Pa", "tendon_stress_max": "Pa", "bar_loads": "N", "bar_load_max": "N",
    "bar_load_by_stage": "N", "bar_critical": "N", "bar_critical_load": "N", "bar_force": "N",
    "membrane_max_principal": "Pa", "membrane_max_von_mises": "Pa",
    "membrane_max_sigma_p1": "Pa", "membrane_max_sigma_p1_element_mean": "Pa",
    "membrane_max_von_mises_element_mean": "Pa", "membrane_min_minor_principal": "Pa",
    "max_deviation_from_design": "m", "freq_hz": "Hz", "highest_hz": "Hz", "MTC": "Hz",
    "SBC": "Hz", "COM": "Hz", "t_end": "s", "dt": "s", "patch": "m", "r_mb": "m",
    "corner_radial_displacement": "m", "max_tendon_deflection_m": "m", "mesh_n": "-",
    "dofs": "-", "steps": "-", "relative_difference": "-", "relative_difference_to_MTC": "-",
    "energy_drift_J": "J", "initial_kinetic_energy_J": "J", "static_time_s": "s",
    "bar_moment_max": "N m", "top_nodes": "m", "residual_history": "N", "bar_load": "N",
    "tendon_max_stress": "Pa", "h": "m", "membrane_mass": "kg", "q": "rad", "q_range": "rad",
    "prestress_scale": "-", "printed_stress_prestress_scale": "-",
    "printed_bar_load_prestress_scale": "-", "B_q_condition_max": "-",
    "final_tracking_error": "-", "rbf_sigma": "rad", "margin": "-", "tol": "-",
    "min_controllability_margin": "-", "min_observability_margin": "-", "eigenvalue": "1/s",
    "rayleigh": "[1/s, s] (alpha, beta of C = alpha M + beta K_0)",
    "damping": "1/s (modal damping c_m of eq. 5.13)",
    "pfl_gains": "[rad/s, rad/s, s, -] (omega_0, omega_e, tau, d_c of eq. 5.69)",
    "w_bar": "bound of the RBF weights, unit of the learnt uncertainty (eq. 5.70)",
    "symmetric_null": "- (null vector of eq. 3.16 per unit F_Delta)",
    "checks": "value and limit in the SI unit of the checked quantity (Pa, N, m)",
    "closed_form": "S1, delta, delta_3_36, r1_equilibrium, r_mb in m; A, det, ratio -",
    "symmetric": "r, l, z in m; theta_deg, psi_deg, sigma_deg in deg (a [symmetric] table)",
    "final": "per state: rad, rad/s (theta, psi), kg^0.5 m, kg^0.5 m/s (eta_k), m (positions)",
    # LPV synthesis and deployment (docs/guides/lpv.md)
    "gamma": "-", "gamma_feasible": "-", "gamma_not_found": "-", "gamma_lower_bound_proven": "-",
    "gamma_rtol": "-", "lpv_gamma_lower_bound": "-", "pointwise_gamma": "-", "printed_gamma_bound": "-",
    "verification_max_eig": "- (relative)", "verification_max_eig_at": "rad",
    "closed_loop_max_real": "1/s", "closed_loop_max_real_at": "rad", "sampled_max_radius": "-",
    "sampled_max_radius_at": "rad", "lpv_gamma_lower_bound_at": "rad", "omega_r": "rad/s", "xi_r": "-",
    "max_tracking_error": "rad (angles), m (positions)", "largest_scaled_eig": "- (scaled)",
    # the automatic deployment path (docs/guides/deployment.md)
    "min_margin": "-", "min_margin_progress": "-", "resolution": "- (progress s)", "hinf_gamma": "-",
    # stage bases and packaged configurations of `tmfem equilibrium` (docs/guides/system-file.md)
    "r": "m", "z": "m", "l": "m", "height": "m",
    # the COM's membrane-mode count (docs/guides/com.md)
    "membrane_mode_choice": "reference_hz, com_hz in Hz; tolerance and differences relative (-)",
    # the modes of compare paired by shape (docs/guides/sbc.md)
    "mode_pairs": "freq_hz in Hz; mode numbers, MAC, fractions and differences (-)",
}
_SUFFIX = [(r".*_deg$", "deg"), (r".*_hz$", "Hz"), (r".*_MPa$", "MPa"), (r".*_mm$", "mm"),
           (r".*_m$", "m"), (r".*_N$", "N"), (r".*_s$", "s"), (r".*_J$", "J"),
           (r".*_Pa$", "Pa"), (r".*_N_per_m$", "N/m"), (r"f\d+$", "Hz"),
           (r".*_fractions?$", "-"), (r"membrane_m(ax|in)_", "Pa")]


def unit_of(key: str) -> str | None:
    """The unit of a JSON key, or None when the key is not a physical quantity. A dict under
    a key with a unit (e.g. ``rest_lengths``: {tendon: value}) carries that unit; the names of
    states and signals (``theta_11``, ``eta_2_dot``) have the units of the run histories
    (:func:`tmfem.io.run.column_header`)."""
    if key.startswith("design_grid_"):                 # an LPV design's check on its own grid
        key = key[len("design_grid_"):]
    if key in _EXACT:
        return _EXACT[key]
    for pattern, unit in _SUFFIX:
        if re.match(pattern, key):
            return unit
    head = column_header(key)
    return head[len(key) + 2:-1] if head != key else None


def units_of(doc) -> dict:
    """{key: unit} for every key of ``doc`` (nested dicts and lists included) with a unit."""
    out: dict = {}

    def walk(obj):
        if isinstance(obj, dict):
            for k, v in obj.items():
                u = unit_of(str(k))
                if u is not None:
                    out.setdefault(str(k), u)
                walk(v)
        elif isinstance(obj, (list, tuple)):
            for v in obj:
                walk(v)
    walk(doc)
    return dict(sorted(out.items()))


def with_units(doc):
    """``doc`` with its ``units`` table (:func:`units_of`) when it is a dict without one:
    every JSON document tmfem writes (``--json``, ``report.json``, ``design.json``)."""
    if isinstance(doc, dict) and "units" not in doc:
        return {**doc, "units": units_of(doc)}
    return doc

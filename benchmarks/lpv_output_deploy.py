"""LPV state feedback against the observer-based output feedback in the 2-3 deployment of 8.4,
through the library (tmfem.control.deployment.run.run_deployment; docs/guides/lpv.md, output feedback).

Run: .venv/bin/python benchmarks/lpv_output_deploy.py [--gamma 20] [--t-end 20] [--dt 2e-4]
         [--sigma 0 1e-3] [--schedule measured|estimate] [--plot out.png]

Builds the 6 x 3 plant of P_D, K(rho) by EIGOPT at --gamma, the Kalman estimator (W_d = W_n =
0.001), then deploys theta_13 from 77.32 to 63 deg (eq. 5.100: xi_r = 1, omega_r = 0.3,
psi_r = 8.36 deg, stage bases of eq. 5.97 from tmfem.reference.tables.deployment_bases) on
the nonlinear COM (point coordinates of eq. 5.17) with the rest-length limits, once per
controller and noise level. Noise: seeded Gaussian samples of std sigma [rad, m; rad/s, m/s]
per step on every signal the controller reads (state feedback: all 50 states; output feedback:
the 25 positions). Prints one JSON line per run.
"""
import argparse
import json
import time

import numpy as np

from tmfem.control.deployment.run import run_deployment
from tmfem.control.lpv.controller import LPVController
from tmfem.control.lpv.output_feedback import LPVOutputController, design_output_feedback
from tmfem.control.lpv.plant import com_lpv_plant
from tmfem.control.lpv.generalized_plant import interconnection_8_1
from tmfem.control.lpv.synthesis import synthesize_state_feedback
from tmfem.control.deployment.reference_trajectory import DeploymentReference
from tmfem.equilibrium.symmetric_map import configuration_5_97, with_configuration
from tmfem.models.com.model import ControlOrientedModel
from tmfem.reference.tables import deployment_bases
from tmfem.simulation.controllers import MeasurementNoise
from tmfem.system import load_preset


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gamma", type=float, default=20.0)
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--dt", type=float, default=2e-4)
    ap.add_argument("--sigma", type=float, nargs="+", default=[0.0, 1e-3])
    ap.add_argument("--schedule", choices=["measured", "estimate"], default="measured",
                    help="where the output feedback reads rho (the state feedback: measured)")
    ap.add_argument("--plot", default=None)
    a = ap.parse_args()
    s = load_preset("2-3-lpv")
    bases = deployment_bases(s)
    th, ps = np.radians(s.printed["theta_grid_deg"]), np.radians(s.printed["psi_grid_deg"])
    t = time.perf_counter()
    pl = com_lpv_plant(s, theta=th, psi=ps, bases=bases)
    sf = synthesize_state_feedback(interconnection_8_1(pl, tracked=s.q_names), solver="EIGOPT", gamma=a.gamma)
    nz = pl.nx // 2
    of = design_output_feedback(sf, pl, tracked=s.q_names, measured=pl.state_names[:nz])
    print(f"# plant, K(rho) at gamma = {a.gamma:g}, estimator: {time.perf_counter() - t:.0f} s")

    def cfg(theta, psi):
        return with_configuration(s, configuration_5_97(s, theta, psi, **bases(theta, psi)))
    th0, th1, ps0 = np.radians(77.32), np.radians(63.0), np.radians(8.36)
    s0 = cfg(th0, ps0)
    model = ControlOrientedModel(s0, membrane_modes=4, membrane_points=pl.membrane_points)
    ref = DeploymentReference(initial=s0.symmetric, final=cfg(th1, ps0).symmetric, N=s.N,
                              q_names=list(s.q_names), omega_r=0.3, bases=bases)
    rho_index = [s.q_names.index("theta_13"), s.q_names.index("psi_13")]
    nq = len(s.q_names)
    z0 = pl.interpolate("x_e", [th0, ps0])[:nz]
    runs = {}
    for sigma in a.sigma:
        for kind in ("lpv", "lpv-output"):
            if kind == "lpv":
                c = LPVController(sf, pl, state_index=range(2 * nz), q_index=range(nq), rho_index=rho_index,
                                  reference=lambda tk: ref(tk)[0])
            else:
                c = LPVOutputController(of, measured_index=range(nz), rho_index=rho_index,
                                        reference=lambda tk: ref(tk)[0], schedule=a.schedule)
            if sigma > 0:
                c = MeasurementNoise(c, sigma=sigma, index=range(2 * nz if kind == "lpv" else nz), seed=1)
            r = run_deployment(model=model, reference=ref, controller=c, z0=z0, t_end=a.t_end, dt=a.dt,
                               stress_every=max(1, int(round(0.05 / a.dt))))
            e = r.z[:, :nq] - r.q_d
            sm = r.summary()
            out = {"controller": kind, "sigma": sigma, "dt_s": a.dt, "t_end_s": a.t_end, "wall_s": r.wall_time,
                   "theta13_final_deg": float(np.degrees(r.z[-1, rho_index[0]])),
                   "theta13_ref_final_deg": float(np.degrees(r.q_d[-1, rho_index[0]])),
                   "max_theta13_error_deg": float(np.degrees(np.abs(e[:, rho_index[0]]).max())),
                   "rms_theta13_error_deg": float(np.degrees(np.sqrt(np.mean(e[:, rho_index[0]] ** 2)))),
                   "final_max_abs_q_error": float(np.abs(e[-1]).max()),
                   "max_membrane_point_deflection_m": float(np.abs(r.z[:, nq:]).max()),
                   **{k: sm[k] for k in ("min_rest_length_margin_m", "limits_active_s", "peak_bar_compression_N",
                                         "max_tendon_stress_Pa", "max_von_mises_Pa")}}
            print(json.dumps(out), flush=True)
            runs[(kind, sigma)] = r
    if a.plot:
        plot(runs, rho_index[0], nq, a.plot)


def plot(runs, i_theta, nq, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), layout="constrained")
    for (kind, sigma), r in runs.items():
        lab = f"{kind}, sigma = {sigma:g}"
        ls = "-" if kind == "lpv" else "--"
        ax[0].plot(r.t, np.degrees(r.z[:, i_theta]), ls, label=lab)
        ax[1].plot(r.t, np.degrees(r.z[:, i_theta] - r.q_d[:, i_theta]), ls, label=lab)
        ax[2].plot(r.t, 1e3 * np.abs(r.z[:, nq:]).max(axis=1), ls, label=lab)
    r = next(iter(runs.values()))
    ax[0].plot(r.t, np.degrees(r.q_d[:, i_theta]), "k:", label="reference (eq. 5.100)")
    ax[0].set(xlabel="t [s]", ylabel="theta_13 [deg]", title="bar b_13 declination")
    ax[1].set(xlabel="t [s]", ylabel="theta_13 - theta_13,r [deg]", title="tracking error")
    ax[2].set(xlabel="t [s]", ylabel="max_k |wr_k| [mm]", title="membrane point deflections (eq. 5.17)")
    for x in ax:
        x.grid(True, alpha=0.3)
        x.legend(fontsize=8)
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()

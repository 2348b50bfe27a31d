"""Free vibration of the control-oriented model (6.5): the 1-4 system after
theta_12' = 0.01 rad/s and the 2-3 system after theta_11' = 0.01 rad/s, dt = 0.01 s,
Park's method started by the trapezoidal rule; CSV histories and plots of the monitored
bar ends (Figs. 6.21-6.22, 6.25-6.27) and membrane points w_1..w_3 (eqs. 5.36, 5.38).

    .venv/bin/python demos/com_free_vibration.py [--out out/com] [--t-end 20]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from tmfem.errors import TmfemError
from tmfem.models.com.model import default_membrane_modes
from tmfem.models.com.model import ControlOrientedModel
from tmfem.post.plots import plot_free_vibration
from tmfem.simulation.vibration import free_vibration
from tmfem.system import load_preset

CASES = {"1-4": {"theta_12_dot": 0.01}, "2-3": {"theta_11_dot": 0.01}}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/com")
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--prestress-scale", type=float, default=1.0)
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, pert in CASES.items():
        try:
            system = load_preset(name)
            K = default_membrane_modes(system)
            m = ControlOrientedModel(system, membrane_modes=K, prestress_scale=a.prestress_scale)
        except TmfemError as exc:
            print(f"{name}: cannot build the COM: {exc}")
            continue
        res = free_vibration(m, t_end=a.t_end, dt=0.01, perturb=pert, csv_path=out / f"{name}.csv",
                             jacobian="reuse")
        png = plot_free_vibration(res, out / f"{name}.png", title=f"{name} COM, K = {K}, {pert}")
        print(f"{name}: {res.stats['steps']} steps in {res.wall_time:.2f} s; max |w| = "
              + ", ".join(f"{1e3 * v:.3f}" for v in np.max(np.abs(res.w), axis=0)) + " mm; "
              + "; ".join(f"{k} peak-to-peak " + ", ".join(f"{1e3 * v:.2f}" for v in np.ptp(X, axis=0)) + " mm"
                          for k, X in res.nodes.items())
              + f"; {out / (name + '.csv')}, {png}")


if __name__ == "__main__":
    main()

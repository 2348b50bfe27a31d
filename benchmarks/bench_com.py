"""Speed of the control-oriented model: one evaluation of M_hat, F_hat, B_hat,
one linearisation, and a 20 s free vibration (dt = 0.01 s, Park) of the 2-3 and 1-4
systems (presets; 2-3 is the design of Tables 6.5/6.7). Target: the 20 s run of the 2-3 system in < 2 s (ten times
faster than real
time). Prints wall and CPU times and where the time of the run goes.

    .venv/bin/python benchmarks/bench_com.py [--systems 2-3 1-4] [--t-end 20]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from tmfem.errors import TmfemError
from tmfem.models.com.dae import matrices_newton
from tmfem.models.com.linearize import linearize
from tmfem.models.com.model import default_membrane_modes
from tmfem.models.com.model import ControlOrientedModel
from tmfem.simulation.vibration import free_vibration
from tmfem.system import load_preset
from timing import print_breakdown

PERTURB = {"1-4": {"theta_12_dot": 0.01}, "2-3": {"theta_11_dot": 0.01}}


class Timed:
    """Proxy that times the calls the integrator makes to the model."""

    def __init__(self, model):
        self.model = model
        self.t = {"residual": 0.0, "newton_matrix": 0.0, "outputs": 0.0}
        self.n = {k: 0 for k in self.t}

    def __getattr__(self, name):
        return getattr(self.model, name)

    def _timed(self, key, fn, *a, **kw):
        t0 = time.perf_counter()
        r = fn(*a, **kw)
        self.t[key] += time.perf_counter() - t0
        self.n[key] += 1
        return r

    def residual(self, *a, **kw):
        return self._timed("residual", self.model.residual, *a, **kw)

    def newton_matrix(self, *a, **kw):
        return self._timed("newton_matrix", self.model.newton_matrix, *a, **kw)

    def jacobians(self, *a, **kw):
        return self.model.jacobians(*a, **kw)

    def fast_outputs(self, *a, with_lengths: bool = False):
        return self._timed("outputs", self.model.fast_outputs, *a, with_lengths=with_lengths)


def per_call(fn, n):
    t0 = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - t0) / n


def bench(name: str, t_end: float) -> None:
    system = load_preset(name)
    K = default_membrane_modes(system)
    t0 = time.perf_counter()
    model = ControlOrientedModel(system, membrane_modes=K)
    t_build = time.perf_counter() - t0
    print(f"\n== {name}: {model.nz} coordinates (nq = {model.nq}, K = {K}), "
          f"{model.n_t} inputs; build {t_build:.2f} s "
          f"(casadi graph of the fast path: {model.graphs.fast.n_nodes()} nodes)")
    z, zd = model.z0, np.full(model.nz, 1e-3)
    print(f"one M_hat, F_hat, B_hat (fast path, one casadi call): "
          f"{1e6 * per_call(lambda: model.matrices(z, zd), 300):8.1f} us")
    print(f"one M_hat, F_hat, B_hat (Newton zeta + numeric 5.23-5.28): "
          f"{1e6 * per_call(lambda: matrices_newton(model, z, zd), 100):8.1f} us")
    print(f"one Newton matrix K + cv C + ca M (AD, {model.graphs.newton.n_nodes()} nodes): "
          f"{1e3 * per_call(lambda: model.newton_matrix(z, zd, zd, 0.0, 1.0, 1.0), 10):8.2f} ms")
    z_e = model.equilibrium().state
    print(f"one linearisation (eq. 5.33, at the equilibrium): "
          f"{1e3 * per_call(lambda: linearize(model, z_e=z_e), 10):8.2f} ms")
    tm = Timed(model)
    c0, w0 = time.process_time(), time.perf_counter()
    res = free_vibration(tm, t_end=t_end, dt=0.01, perturb=PERTURB.get(name, {}), jacobian="reuse")
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    import os
    load = os.getloadavg()[0]
    print(f"{t_end:g} s free vibration, dt = 0.01 s: wall {wall:.2f} s, CPU {cpu:.2f} s "
          f"({t_end / max(cpu, 1e-9):.1f}x real time on CPU time); target < {t_end / 10:g} s: "
          f"CPU {'met' if cpu < t_end / 10 else 'NOT met'}, wall {'met' if wall < t_end / 10 else 'NOT met'}"
          f" (load average {load:.1f} on {os.cpu_count()} cores: wall > CPU means other processes)")
    print(f"  {res.stats['steps']} steps, {res.stats['newton_iterations']} Newton iterations, "
          f"{res.stats['jacobian_evaluations']} Jacobian evaluations")
    print_breakdown(tm.t, tm.n, wall, "Park loop, LU solves, Python")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--systems", nargs="+", default=["2-3", "1-4"])
    ap.add_argument("--t-end", type=float, default=20.0)
    a = ap.parse_args()
    for name in a.systems:
        try:
            bench(name, a.t_end)
        except TmfemError as exc:
            print(f"\n== {name}: cannot build the COM: {exc}")


if __name__ == "__main__":
    main()

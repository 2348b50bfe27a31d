"""The cost of the design sensitivities against one analysis, and the time of the first
design example on the paper's mesh.

    .venv/bin/python benchmarks/bench_design.py [--mesh 10] [--rounds 3] [--system 1-4]

(1) For the MTC model of ``--system`` on the membrane mesh N x n x n: the time of one static
solve warm-started from the converged state (as in an optimisation, where each design starts
from the last one) plus 6 modes, against one call of ``design_sensitivities`` that returns
every response of ``RESPONSES`` and its gradient for every tendon-group rest length, the
membrane thickness, the bar diameter and the tendon families' diameters; the best of
``--rounds``. Prints both and their ratio.

(2) Example 1 of docs/guides/design.md (1-4: maximise the first frequency by the four rest
lengths with the tendon stress <= yield / 1.5, no wrinkling inside 0.8 of the inradius, the
mass not above the start) on the mesh ``--mesh``: iterations, evaluations, time.
OPENBLAS_NUM_THREADS=1.
"""
from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def gradient_cost(system_name: str, mesh: int, rounds: int) -> dict:
    from tmfem.design import design_sensitivities
    from tmfem.design.variables import group_names
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    system = load_preset(system_name)
    m = MTCModel(system, mesh_n=mesh)
    eq = m.equilibrium()
    names = group_names(system) + ["h_membrane", "d_bar"] + \
        [f"d_{f}" for f in dict.fromkeys(t.family for t in system.tendons)]
    t_an, t_sens = [], []
    for _ in range(rounds):
        t0 = time.perf_counter()
        e = m.equilibrium(x0=eq.state)
        m.modes(k=6, at=e)
        t1 = time.perf_counter()
        design_sensitivities(m, equilibrium=e, variables=names, k=4)
        t2 = time.perf_counter()
        t_an.append(t1 - t0)
        t_sens.append(t2 - t1)
    return {"dofs": m.ndof, "variables": len(names), "analysis_s": min(t_an), "gradient_s": min(t_sens)}


def example_1(mesh: int) -> dict:
    from tmfem.design import optimize
    from tmfem.system import load_preset
    system = load_preset("1-4")
    limit = system.tendon_sections["S"].yield_stress / 1.5
    t0 = time.perf_counter()
    res = optimize(system, objective="max:freq",
                   constraints=[f"tendon_stress<={limit}", "membrane_min_principal>=0", "mass<=start"],
                   variables={t: (1.40, 1.52) for t in system.tendon_names()}, mesh_n=mesh, aperture=0.8)
    return {"time_s": time.perf_counter() - t0, "iterations": len(res.history), "evaluations": res.evaluations,
            "freq_start": res.start_responses["freq"][0], "freq_optimum": res.optimum_responses["freq"][0],
            "success": res.success}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--system", default="1-4")
    a = ap.parse_args()
    g = gradient_cost(a.system, a.mesh, a.rounds)
    print(f"{a.system} MTC mesh {a.mesh}: {g['dofs']} dofs, {g['variables']} variables")
    print(f"  static (warm) + 6 modes   {g['analysis_s']:.3f} s")
    print(f"  all responses' gradients  {g['gradient_s']:.3f} s")
    print(f"  ratio                     {g['gradient_s'] / g['analysis_s']:.2f}")
    e = example_1(a.mesh)
    print(f"example 1 (1-4, mesh {a.mesh}): {e['time_s']:.1f} s, {e['iterations']} iterations, "
          f"{e['evaluations']} evaluations, f_1 {e['freq_start']:.4f} -> {e['freq_optimum']:.4f} Hz, "
          f"success {e['success']}")


if __name__ == "__main__":
    main()

"""Two-bar (von Mises) arch of dissertation 4.5.3 through its limit point by arc length."""
from __future__ import annotations

from tmfem.reference.element_benchmarks import two_bar_arch

NAME = "truss-arch"
HELP = ("two-bar arch of 4.5.3 (a = 2.5 m, b = 0.025 m, EA = 5e7 N) by arc length against the "
        "total-Lagrangian closed form (benchmarks.json von_mises_truss_formulas)")
COLUMNS = {"v": "m", "P": "N", "P_closed_form": "N"}


def run(*, reduced: bool = False) -> dict:
    """Arc-length path and the closed-form load at the same apex displacements."""
    r = two_bar_arch(a=2.5, b=0.025, EA=5e7, n_per_b=20 if reduced else 40)
    rows = [{"v": float(v), "P": float(P), "P_closed_form": float(Pg)}
            for v, P, Pg in zip(r.v, r.P, r.P_green)]
    return {"rows": rows, "steps": r.steps, "P_limit_fe_N": r.P_max_fe,
            "P_limit_closed_form_N": r.limits["P_green"],
            "source": "closed form P = (EA/L0^3)(b - v)(2bv - v^2) (Green strain, SVK)"}


def plot(result: dict, png):
    """Load against apex displacement, FE path and closed form."""
    from tmfem.post.plots import plot_xy
    rows = result["rows"]
    v = [r["v"] * 1e3 for r in rows]
    return plot_xy(png, {"FE (arc length)": (v, [r["P"] for r in rows]),
                         "closed form": (v, [r["P_closed_form"] for r in rows])},
                   xlabel="apex displacement v [mm]", ylabel="load P [N]",
                   title="two-bar arch (4.5.3)")

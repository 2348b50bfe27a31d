"""Why a design-grid certificate of the 2-3 output-feedback loop fails on the 4x finer grid
(docs/lpv.md, "On the 2-3 loop"): for a saved X(rho) of the separation form X = M diag(P, beta Z) M^T
(tmfem.control.lpv.certificate.separation_start; M: eps -> e = x_z - eps),

1. the largest relative LMI eigenvalue on the fine grid with the error part re-weighted,
   beta x each of --betas (design points and the others counted apart);
2. at the worst fine point: the positive eigenvalues and the weight of their top eigenvector on
   x_z, xi, eps (coordinates of the separation form) and on w, p; the interpolation error of the
   estimator's model there;
3. the largest scaled eigenvalue in EIGOPT's coordinates (balanced on X, each LMI divided by its
   largest entry, as refine_certificate's re-solve sees it) at the design points and the
   --points worst fine points.

Run: .venv/bin/python benchmarks/lpv_certificate_diagnose.py --design F.npz --certificate X.npz --cache DIR
         [--betas 1,2,5,10] [--points 4]
(--cache as for benchmarks/lpv_certificate.py, whose plants it uses.) Prints one JSON object.
"""
import argparse
import dataclasses
import json

import numpy as np
from lpv_certificate import plant_on

from tmfem.control.lpv.certificate import closed_loop_lpv, pointwise_lmi_eigs
from tmfem.control.lpv.eigopt import EigOpt
from tmfem.control.lpv.output_feedback import design_output_feedback
from tmfem.control.lpv.coordinates import Coordinates
from tmfem.control.lpv.generalized_plant import lmi_matrix
from tmfem.control.lpv.state_feedback import LPVStateFeedback
from tmfem.system import load_preset


def deg(gp, idx):
    return [round(float(np.degrees(a[i])), 2) for a, i in zip(gp.axes, idx)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--design", required=True)
    ap.add_argument("--certificate", required=True)
    ap.add_argument("--cache", default=None)
    ap.add_argument("--betas", default="1,2,3,5,7,10,15,20")
    ap.add_argument("--points", type=int, default=4)
    a = ap.parse_args()
    s = load_preset("2-3-lpv")
    sf = LPVStateFeedback.load(a.design)
    shape = "x".join(str(ax.size) for ax in sf.axes)
    pl = plant_on(s, sf.axes[0], sf.axes[1], sf.rate_bounds, a.cache, f"plant_{shape}")
    fa = pl.refined(4)
    fine = plant_on(s, fa[0], fa[1], pl.rate_bounds, a.cache, f"fine_{shape}", membrane_points=pl.membrane_points)
    of = design_output_feedback(sf, pl, tracked=s.q_names, measured=pl.state_names[:pl.nx // 2])
    X = LPVStateFeedback.load(a.certificate)
    n, nq = of.nx, of.tracked_rows.size
    N = 2 * n + nq
    M = np.eye(N)
    M[n + nq:, :n] = np.eye(n)
    M[n + nq:, n + nq:] = -np.eye(n)
    Mi = np.linalg.inv(M)
    parts = [Mi @ Xk @ Mi.T for Xk in X.P]                     # diag(P, beta Z) in [x_z, xi, eps]
    out = {"separation_offdiagonal_rel": max(float(np.abs(b[:n + nq, n + nq:]).max() / np.abs(b).max())
                                             for b in parts)}
    gp = closed_loop_lpv(of, fine, W_e=0.5, W_u=0.05)
    on_design = np.zeros(gp.grid_shape, bool)
    on_design[np.ix_(*[np.flatnonzero(np.isin(f, d)) for f, d in zip(gp.axes, X.axes)])] = True
    sweep = []
    for b in (float(v) for v in a.betas.split(",")):
        W = np.diag(np.r_[np.ones(n + nq), np.full(n, np.sqrt(b))])
        Xb = dataclasses.replace(X, P=[M @ W @ p @ W @ M.T for p in parts])
        lmi, minX = pointwise_lmi_eigs(Xb, gp)
        sweep.append({"beta_factor": b, "fine_max_eig": float(lmi.max()),
                      "at_deg": deg(gp, np.unravel_index(int(np.argmax(lmi)), lmi.shape)),
                      "failing": int((lmi >= 0).sum()), "design_points_failing": int((lmi[on_design] >= 0).sum()),
                      "min_X_eig": float(minX.min())})
    out["beta_sweep"] = sweep
    lmi, _ = pointwise_lmi_eigs(X, gp)
    order = [tuple(int(i) for i in np.unravel_index(k, lmi.shape)) for k in np.argsort(lmi, axis=None)[::-1]]
    worst = order[0]
    rho = np.array([ax[i] for ax, i in zip(gp.axes, worst)])
    nw = gp.B1.shape[-1]
    verts = []
    for v in gp.rate_vertices():
        dX = sum((v[k] / X.half_width[k]) * X.P[1 + j] for j, k in enumerate(X.varying))
        Mm = lmi_matrix(A=gp.A[worst], B1=gp.B1[worst], B2=gp.B2[worst], C1=gp.C1[worst], D11=gp.D11[worst],
                        D12=gp.D12[worst], P=X.P_of(rho), Q=np.zeros((0, N)), dP=dX, gamma=X.gamma)
        w, V = np.linalg.eigh((Mm + Mm.T) / 2)
        st = M.T @ V[:N, -1]
        verts.append({"positive_eigs": w[w > 0][::-1].tolist(), "max_abs_entry": float(np.abs(Mm).max()),
                      "weight_x_z": float(st[:n] @ st[:n]), "weight_xi": float(st[n:n + nq] @ st[n:n + nq]),
                      "weight_eps": float(st[n + nq:] @ st[n + nq:]),
                      "weight_w": float(V[N:N + nw, -1] @ V[N:N + nw, -1]),
                      "weight_p": float(V[N + nw:, -1] @ V[N + nw:, -1])})
    A_model = of.model(rho)[0]
    out["worst"] = {"at_deg": deg(gp, worst), "rate_vertices": verts,
                    "model_error_rel": float(np.abs(fine.A[worst] - A_model).max() / np.abs(fine.A[worst]).max())}
    co = Coordinates.of(gp)
    pts = [tuple(int(i) for i in k) for k in np.argwhere(on_design)] + order[:a.points]
    e = EigOpt(gp, T=co.T, c_of=co.c_of, dvs=co.dvs, gamma=X.gamma, points=pts, balance_on=co.coefficients_of(X, gp))
    z = e.start_from(*co.coefficients_of(X, gp))
    Ms = e.matrices(z, X.gamma)
    sc = e.scales(z, X.gamma, Ms)
    top = np.linalg.eigvalsh(Ms[0] / sc[0][..., None, None])[..., -1].max(axis=1)
    out["scaled_eig"] = [{"at_deg": deg(gp, k), "design_point": bool(on_design[k]), "largest_scaled_eig": float(t)}
                         for k, t in zip(pts, top)]
    print(json.dumps(out))


if __name__ == "__main__":
    main()

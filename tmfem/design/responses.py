"""State responses of the MTC model and their derivatives along a change of the positions.

Each function takes the positions x (3, n_nodes) and directions dx (3, n_nodes, n_var) (the
derivatives of x with respect to the variables from the direct sensitivity equation), or the
reduced increments du and the model's kinematics (:mod:`tmfem.design.kinematics`), and
returns the value and its derivative (n_var,) at fixed design; the design's own (partial)
dependence is added by :func:`tmfem.design.sensitivities.design_sensitivities`.

* :func:`ks_max`: the Kreisselmeier-Steinhauser aggregate KS(g) = g_max + w ln sum_i
  exp((g_i - g_max) / w) of many values, a smooth upper bound of their maximum within w ln n;
  the minimum is -KS(-g), a lower bound. It replaces the maximum over the membrane's Gauss
  points, which is not differentiable where the largest point changes.
* :func:`membrane_aggregates`: the von Mises stress (eq. 5.30) and the minor in-plane
  principal stress (eq. 5.29; below zero the membrane wrinkles) at every Gauss point (MTC:
  of the Cauchy stress in the floating frame; SBC: of the shells' mid surface), aggregated
  by KS. Their derivative along dx is a
  Richardson-extrapolated central difference (4 D(h) - D(2h)) / 3 of the explicit stress
  function of the positions (no re-solve), error O(h^4), with a step h that moves a node by
  1e-4 of the model's size: the membrane strains are small (1e-6 to 1e-4) and formed from
  F^T F - I, so a smaller step loses digits to rounding (1e-7: 1e-4 relative), while at 1e-4
  the extrapolated difference agrees with 3e-5 and 3e-4 to 1e-9.
* :func:`smooth_step`: the logistic H_w(s) = 1 / (1 + exp(-s / w)) of width w, a smooth
  Heaviside step (H_w -> 1 for s >> w, 0 for s << -w, H_w(0) = 1/2). The wrinkled area
  A_w = sum_g H_w(-sigma_2,g) dA_g over the membrane's Gauss points (dA_g their reference
  areas) is a smooth measure of the area where the minor principal stress is below zero;
  where sigma_2 is the elastic (SVK) law's, its sign is the tension-field law's criterion
  (:mod:`tmfem.fem.tension_field`: taut iff S_2 > 0, and U S U / J has the signs of S), so
  A_w tends to the tension-field law's wrinkled-and-slack area at the same state as w -> 0,
  with an error bounded by the area of the points with |sigma_2| below a few w. Its
  derivative, sum_g -H_w'(-sigma_2,g) dsigma_2,g dA_g, is differenced as the aggregates are.
* :func:`surface_rms`: the RMS distance of the membrane from its best-fit plane,
  rms = sqrt(lambda_min(C)), C = sum_i w_i (x_i - xbar)(x_i - xbar)^T / sum w (w_i the nodal
  areas of the lumped membrane mass); d lambda_min = n^T dC n with n the plane's normal.
* :func:`corner_deltas`: Delta_j = |B_Mj - c| - r_mb (eq. 3.22's corner displacement; c the
  corners' centroid), dDelta_j = e_j . (dB_Mj - dc).
"""
from __future__ import annotations

import numpy as np
from scipy.special import expit

from tmfem.errors import InputError
from tmfem.system.topology import label


def ks_max(g: np.ndarray, width: float):
    """KS aggregate of the values g (n,) with smoothing width w (module docstring) and its
    weights dKS/dg_i (a softmax, summing to 1)."""
    g = np.asarray(g, dtype=float).ravel()
    gm = float(g.max())
    e = np.exp((g - gm) / width)
    s = float(e.sum())
    return gm + width * np.log(s), e / s


def smooth_step(s: np.ndarray, width: float):
    """The logistic H_w(s) = 1 / (1 + exp(-s / w)) (module docstring) and its derivative
    dH_w/ds = H_w (1 - H_w) / w."""
    H = expit(np.asarray(s, dtype=float) / width)
    return H, H * (1.0 - H) / width


def minor_principal(cauchy: np.ndarray) -> np.ndarray:
    """Minor in-plane principal stress (s_xx + s_yy) / 2 - sqrt(((s_xx - s_yy) / 2)^2 + s_xy^2)."""
    sxx, syy, sxy = cauchy
    return 0.5 * (sxx + syy) - np.sqrt((0.5 * (sxx - syy)) ** 2 + sxy ** 2)


def aperture_mask(model, points: np.ndarray, aperture: float | None) -> np.ndarray:
    """Gauss points (ne, nqp) inside the disc of radius ``aperture`` times the membrane's
    inradius about its centroid (reference coordinates); all of them for None."""
    if aperture is None:
        return np.ones(points.shape[1:], dtype=bool)
    P = model.system.membrane_corners
    c = P.mean(axis=1)
    a, b = P, np.roll(P, -1, axis=1)
    t = b - a
    n = np.stack([t[1], -t[0]]) / np.linalg.norm(t, axis=0)
    inradius = float(np.min(np.abs(np.einsum("ij,ij->j", n, c[:, None] - a))))
    return np.linalg.norm(points - c[:, None, None], axis=0) <= aperture * inradius


def membrane_aggregates(model, kin, du: np.ndarray, *, width: float, aperture: float | None,
                        wrinkle_width: float, moved=None) -> dict:
    """KS aggregates of the von Mises and (with -KS(-g)) the minor principal stress over
    the membrane's Gauss points (the minor one inside the ``aperture``), the wrinkled area
    A_w of the smooth step of width ``wrinkle_width`` over the whole membrane, and their
    derivatives along the reduced increments du (n_red, n_var) (module docstring), A_w's at
    fixed Gauss-point areas dA_g (``kin.areas()``); ``kin``
    moves the model's state (:mod:`tmfem.design.kinematics`). ``moved``: {j: fields(step)},
    the stresses at the state and design moved by +-step along variable j, for a variable
    on which the stresses depend at fixed positions (the membrane radius). Returns
    ``{name: (value, derivative)}``."""
    moved = moved or {}
    vm, mp, points = kin.membrane(kin.point(np.zeros(du.shape[0])))
    inside = aperture_mask(model, points, aperture)
    if not inside.any():
        raise InputError(f"aperture: expected Gauss points within {aperture} of the membrane's inradius, "
                         f"found none on this mesh (enlarge the aperture or refine the mesh)")
    vm_ks, w_vm = ks_max(vm, width)
    mp_ks, w_mp = ks_max(-mp[inside], width)
    areas = kin.areas()
    H, dH = smooth_step(-mp, wrinkle_width)
    w_wr = -(dH * areas).ravel()
    n_var = du.shape[-1]
    d_vm, d_mp, d_wr = np.zeros(n_var), np.zeros(n_var), np.zeros(n_var)
    size = float(np.ptp(kin.x, axis=1).max())
    for j in range(n_var):
        top = float(np.abs(kin.positions(du[:, j])).max())
        if top == 0.0 and j not in moved:
            continue
        # a node moves by 1e-4 of the size (a moved design by at most that: its own step)
        h = 1e-4 * size / (max(top, 1.0) if j in moved else top)
        diffs = []
        for step in (h, 2 * h):
            if j in moved:
                (vp, mpp, _), (vmn, mpn, _) = moved[j](step)
            else:
                vp, mpp, _ = kin.membrane(kin.point(step * du[:, j]))
                vmn, mpn, _ = kin.membrane(kin.point(-step * du[:, j]))
            diffs.append(np.array([w_vm @ (vp - vmn).ravel(), w_mp @ (mpp - mpn)[inside],
                                   w_wr @ (mpp - mpn).ravel()]) / (2 * step))
        d_vm[j], d_mp[j], d_wr[j] = (4 * diffs[0] - diffs[1]) / 3
    return {"membrane_von_mises": (vm_ks, d_vm), "membrane_min_principal": (-mp_ks, d_mp),
            "wrinkled_area": (float(np.sum(H * areas)), d_wr)}


def surface_rms(model, x: np.ndarray, dx: np.ndarray):
    """RMS distance of the membrane nodes from their best-fit plane and its derivative along
    dx (module docstring)."""
    from tmfem.fem.membrane import MembraneTL
    nm = model.topology.n_mesh
    mem = getattr(model, "membrane", None) or MembraneTL(mesh=model.topology.mesh, material=model.system.membrane)
    w = np.asarray(mem.mass().sum(axis=1)).ravel()[0::3]
    w = w / w.sum()
    xm = x[:, :nm]
    r = xm - (xm @ w)[:, None]
    C = (r * w) @ r.T
    lam, vec = np.linalg.eigh(C)
    n = vec[:, 0]
    a = n @ r                                                    # signed distances (nm,)
    rms = float(np.sqrt(max(lam[0], 0.0)))
    dlam = 2.0 * np.einsum("i,i,ij->j", w, a, np.einsum("c,cij->ij", n, dx[:, :nm]))
    return rms, dlam / (2.0 * rms) if rms > 0 else np.zeros(dx.shape[-1])


def corner_deltas(model, x: np.ndarray, dx: np.ndarray):
    """Corner displacements Delta_j (N,) of the membrane corners B_Mj and their derivatives
    (N, n_var) along dx (module docstring)."""
    sysm = model.system
    top = [model.topology.system_node[sysm.node_index(label("B", sysm.M, j))]
           for j in range(1, sysm.N + 1)]
    c = x[:, top]
    dc = dx[:, top]
    rel = c - c.mean(axis=1, keepdims=True)
    dist = np.linalg.norm(rel, axis=0)
    e = rel / dist
    r_mb = sysm.r_mb if sysm.r_mb else float(np.mean(np.linalg.norm(
        sysm.membrane_corners - sysm.membrane_corners.mean(axis=1, keepdims=True), axis=0)))
    ddist = np.einsum("ij,ijv->jv", e, dc - dc.mean(axis=1, keepdims=True))
    return dist - r_mb, ddist

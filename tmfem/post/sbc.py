"""Fields, cells and pictures of the shell-beam-cable model's results (ParaView, PNG).

The SBC model's nodes carry rotations (MITC4 shell nodes two about their directors' V_1, V_2,
beam nodes three): the ParaView files give them as rotation vectors theta [rad] (point data,
the spin of :meth:`tmfem.fem.element.State.advanced`: theta = a_1 V_1 + a_2 V_2 on a shell
node). Bars are drawn as their beam elements' segments (3 per four-node element) with the
axial force N and the bending moment |M| = (M_1^2 + M_2^2)^(1/2) of the element (mean over
its Gauss points), tendons as lines with their axial forces, the membrane as the shell quads
with the stresses at the element centres on the bottom, middle and top surfaces and the
lamina law's state there (taut / wrinkled / slack, docs/guides/wrinkling.md).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from tmfem.io.codes import kind_cell_data
from tmfem.io.fields import DISPLACEMENT_FIELD, MembraneField
from tmfem.io.meshes import block_data, to_meshio
from tmfem.io.paths import check_path
from tmfem.io.writer import write_mesh
from tmfem.models.fe.outputs import to_floating
from tmfem.models.sbc.post import SURFACES, shell_stresses

def rotation_vectors(model, state, d=None) -> np.ndarray:
    """Rotation vectors (3, n_nodes) [rad]: of the nodal rotations R of ``state`` (``d`` None)
    or of the full dof vector ``d`` (an increment or a mode shape: theta = a_1 V_1 + a_2 V_2
    on shell nodes with the current directors, the three components on beam nodes, zero on
    tendon nodes)."""
    dm = model.dofmap
    n = dm.n_nodes
    if d is None:
        return Rotation.from_matrix(state.R).as_rotvec().T
    th = np.zeros((n, 3))
    for n_rot in (2, 3):
        nodes = np.flatnonzero(dm.counts == 3 + n_rot)
        if nodes.size == 0:
            continue
        a = d[dm.rotation_dofs(nodes)]
        if n_rot == 3:
            th[nodes] = a
        else:
            V = np.einsum("nij,njk->nik", state.R[nodes], state.frames[nodes])
            th[nodes] = a[:, 0, None] * V[:, :, 0] + a[:, 1, None] * V[:, :, 1]
    return th.T


def shell_wrinkling(model, state) -> dict:
    """Cell data of the shell lamina law's states (docs/guides/wrinkling.md): ``membrane_state``
    (ne,) int32, 0 taut, 1 wrinkled, 2 slack, of the element centre's two thickness Gauss
    points, and ``wrinkle_direction`` (3, ne), the tension (wrinkle-crest) direction in the
    global axes of the reference surface, zero where the element is not wrinkled
    (:meth:`tmfem.fem.mitc4.MITC4Shell.wrinkling`; the MTC model's
    :func:`tmfem.post.mtc.membrane_field` writes the same two fields)."""
    wr = model.shell.wrinkling(state)
    return {"membrane_state": wr["state"].astype(np.int32), "wrinkle_direction": wr["direction_xyz"]}


def shell_field(model, state) -> MembraneField:
    """The shell membrane of ``state`` as a :class:`MembraneField`: displacement in the floating
    frame (eq. 3.4) and the rotation vectors as point data, element-centre stresses on the three
    surfaces as cell data (``von_mises_top``, ``sigma_p1_mid``, ...; ``von_mises`` and
    ``sigma_p1`` the largest over the surfaces) with the lamina states of
    :func:`shell_wrinkling`."""
    topo = model.topology
    nm = topo.n_mesh
    xm = state.x[:, :nm]
    xf = to_floating(xm, xm[:, topo.mesh.corners])
    ref = np.vstack([topo.mesh.p, np.zeros(nm)])
    c = shell_stresses(model, state)["centre"]
    cd = {f"{k}_{s}": c[k][i] for k in c for i, s in enumerate(SURFACES)}
    cd["von_mises"] = c["von_mises"].max(axis=0)
    cd["sigma_p1"] = c["sigma_p1"].max(axis=0)
    cd.update(shell_wrinkling(model, state))
    return MembraneField(mesh=topo.mesh, x=xm,
                         point_data={DISPLACEMENT_FIELD: xf - ref,
                                     "rotation": rotation_vectors(model, state)[:, :nm]},
                         cell_data=cd)


def sbc_cells(model) -> list:
    """Cells of the whole SBC model: beam segments (lines along each bar's node chain),
    tendon elements (lines) and shell quads."""
    ch = model.numbering.bar_chain
    seg = np.stack([ch[:, :-1].ravel(), ch[:, 1:].ravel()])
    return [("line", seg), ("line", model.tendons.conn), ("quad", model.topology.mesh.t)]


def _cell_data(model, state, cells) -> dict:
    """Per block (beams, tendons, shells): ``kind`` (:func:`tmfem.io.codes.kind_cell_data`),
    axial force [N], bending moment |M| [N m], shell sigma_p1 and von Mises [Pa] per surface,
    the shell states ``membrane_state`` and ``wrinkle_direction`` (:func:`shell_wrinkling`);
    NaN where a quantity does not exist (-1 for the integer state)."""
    sec = model.beam.section_forces(state)
    per = 3                                                  # segments per four-node element
    Nb = np.repeat(sec["N"].mean(axis=1), per)
    Mb = np.repeat(np.hypot(sec["M1"], sec["M2"]).mean(axis=1), per)
    Nt = model.member_forces(state)["tendon_element"]
    c = shell_stresses(model, state)["centre"]
    none = [np.full(conn.shape[1], np.nan) for _, conn in cells]        # beams, tendons, shells
    out = {**kind_cell_data(cells), "axial_force": [Nb, Nt, none[2]],
           "bending_moment": [Mb, none[1], none[2]]}
    for i, s in enumerate(SURFACES):
        for k in ("von_mises", "sigma_p1"):
            out[f"{k}_{s}"] = [none[0], none[1], c[k][i]]
    wr = shell_wrinkling(model, state)
    out["membrane_state"] = [np.full(n.size, -1, dtype=np.int32) for n in none[:2]] \
        + [wr["membrane_state"]]
    out["wrinkle_direction"] = [np.full((3, n.size), np.nan) for n in none[:2]] \
        + [wr["wrinkle_direction"]]
    return out


def write_sbc_state(path, model, state) -> str:
    """Write an SBC state for ParaView (.vtu): all nodes at their positions, the cells of
    :func:`sbc_cells`, point data ``displacement`` [m] (from the reference) and ``rotation``
    [rad], cell data ``kind`` (0 beam, 1 tendon, 2 shell), ``axial_force``, ``bending_moment``,
    the shell stresses (module docstring) and the shell states ``membrane_state``,
    ``wrinkle_direction`` (:func:`shell_wrinkling`)."""
    path = check_path(path, suffixes=(".vtu",))
    cells = sbc_cells(model)
    pdata, cdata = block_data({"displacement": state.x - model.X,
                               "rotation": rotation_vectors(model, state)},
                              _cell_data(model, state, cells), cells, state.x.shape[1])
    return str(write_mesh(path, to_meshio(state.x, cells, point_data=pdata, cell_data=cdata)))


def mode_data(model, state, modes):
    """(shapes (3 n, k) node-interleaved translations, point data ``rotation_mode_k``) of the
    reduced mode shapes of :meth:`SBCModel.modes` for :func:`tmfem.io.writer.write_modes`."""
    S = model.full_shapes(modes.shapes)                            # (3, n, k)
    D = model.constraints.T @ modes.shapes
    rot = {f"rotation_mode_{k + 1}": rotation_vectors(model, state, D[:, k])
           for k in range(D.shape[1])}
    return S.transpose(1, 0, 2).reshape(-1, S.shape[2]), rot


# ---------------------------------------------------------------------------- reports
#: files ``tmfem static`` and ``tmfem modal`` can write for this model (the shell stresses
#: are in the ParaView file; the stress and wrinkling maps are of the MTC membrane)
STATIC_FILES = ("vtk", "png")
MODE_FILES = ("vtk", "png")


def static_summary(model, result) -> dict:
    """JSON-able summary of an SBC equilibrium (:func:`tmfem.models.sbc.post.static_summary`)."""
    from tmfem.models.sbc.post import static_summary as summary
    return summary(model, result)


def write_static_files(model, result, *, vtk=None, png=None) -> dict:
    """The ParaView file of the shells, beams and tendons and the PNG of the equilibrium
    ``result`` that are asked for; returns their paths by kind."""
    out, st = {}, result.state
    if vtk:
        out["vtk"] = write_sbc_state(vtk, model, st)
    if png:
        from tmfem.models.fe.outputs import q_from_positions
        from tmfem.post.render import render_configuration
        q = q_from_positions(model.system, st.x[:, model.topology.system_node])
        out["png"] = str(render_configuration(
            png, model.system, q=q, tendon_forces=model.member_forces(st)["tendon"],
            membrane=shell_field(model, st), membrane_field="von_mises_top",
            title=f"{model.system.name} SBC equilibrium (shell von Mises, top surface)"))
    return out


def format_static(r: dict) -> str:
    """Text of :func:`static_summary` (:func:`tmfem.models.sbc.post.format_static`)."""
    from tmfem.models.sbc.post import format_static as text
    return text(r)


def modal_summary(model, result, modes) -> dict:
    """:func:`static_summary` plus the frequencies of ``modes`` (eq. 5.32)."""
    from tmfem.models.sbc.post import modal_summary as summary
    return summary(model, result, modes)


def write_mode_files(model, result, modes, *, vtk=None, png=None) -> dict:
    """The ParaView file of the mode shapes (translations and rotations) and the PNG of the
    first six that are asked for; returns their paths by kind."""
    from tmfem.post.modes import write_mode_shapes
    shapes, rotations = mode_data(model, result.state, modes)
    return write_mode_shapes(result.state.x, sbc_cells(model), shapes, modes.freq_hz, vtk=vtk,
                             png=png, point_data=rotations,
                             title=f"{model.system.name} SBC modes")


def format_modal(r: dict) -> str:
    """Text of :func:`modal_summary`: the equilibrium and the frequencies."""
    return format_static(r)

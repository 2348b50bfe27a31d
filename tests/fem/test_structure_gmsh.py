"""Frames meshed by gmsh and structures read from gmsh models (tmfem.mesh.frame,
tmfem.fem.structure.from_mesh).

Sources: statics of a symmetric tripod (each leg carries P / (3 sin b), the apex sinks
P L / (3 EA sin^2 b), linear truss closed form); a cantilever strip stiffened by two edge beams
on its mid-plane, tip load P: composite beam theory, w = P L^3 / (3 (E I_plate + E I_beam))
(plus the beam's shear deformation, Cowper's k).
"""
import meshio
import numpy as np
import pytest

from tmfem.fem.beam import BeamSection
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure import Structure
from tmfem.mesh.frame import frame_mesh

gmsh = pytest.importorskip("gmsh")


def _tripod(r=1.0, h=2.0):
    ang = 2 * np.pi * np.arange(3) / 3
    X = np.column_stack([np.vstack([r * np.cos(ang), r * np.sin(ang), np.zeros(3)]), [0.0, 0.0, h]])
    return X, np.array([[0, 1, 2, 0, 1, 2], [3, 3, 3, 1, 2, 0]])


def test_frame_mesh_round_trip_keeps_the_physical_groups(tmp_path):
    X, members = _tripod()
    groups = ["legs"] * 3 + ["ring"] * 3
    m = frame_mesh(X, members, groups=groups, elements_per_member=3, order=3, path=tmp_path / "tripod.msh")
    back = meshio.read(tmp_path / "tripod.msh")
    for mesh in (m, back):
        sets = {k: v for k, v in mesh.cell_sets_dict.items() if not k.startswith("gmsh:")}
        assert sorted(sets) == ["legs", "ring"]
        assert sets["legs"]["line4"].size == 9 and sets["ring"]["line4"].size == 9
    # the joints are points of the mesh at their positions
    for k in range(4):
        assert np.min(np.linalg.norm(back.points - X[:, k], axis=1)) < 1e-12
    s = Structure.from_mesh(back, beams={g: dict(section=BeamSection.circle(d=0.05), E=2e11, nu=0.3)
                                         for g in ("legs", "ring")})
    assert sorted(s.node_sets) == ["legs", "ring"] and s.node_sets["legs"].size == 3 * 9 + 1


def test_tripod_of_bars_from_gmsh_against_statics(tmp_path):
    X, members = _tripod()
    P, EA = 1e3, 1e6
    frame_mesh(X[:, :], members[:, :3], groups=["legs"] * 3, path=tmp_path / "legs.msh")
    s = Structure.from_mesh(tmp_path / "legs.msh", trusses={"legs": dict(EA=EA)})
    top = s.nodes_where(lambda x, y, z: np.isclose(z, 2.0))
    s.fix(s.nodes_where(lambda x, y, z: np.isclose(z, 0.0)))
    s.point_load(top, force=(0, 0, -P))
    st = s.solve_linear()
    L = np.hypot(1.0, 2.0)
    sinb = 2.0 / L
    assert s.displacements(st)[2, top][0] == pytest.approx(-P * L / (3 * EA * sinb**2), rel=1e-10)
    F, _ = s.resultant(st)
    np.testing.assert_allclose(F, [0, 0, P], atol=1e-9 * P)


def test_shell_with_an_edge_beam_from_one_gmsh_model(tmp_path):
    L, b, h, E, P = 2.0, 0.2, 0.01, 2e11, -50.0
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("stiffened")
        gmsh.model.occ.addRectangle(0, 0, 0, L, b)
        gmsh.model.occ.synchronize()
        curves = {}
        for dim, tag in gmsh.model.getEntities(1):
            x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(dim, tag)
            key = "bottom" if y1 < 1e-6 else "top" if y0 > b - 1e-6 else "left" if x1 < 1e-6 else "right"
            curves[key] = tag
            gmsh.model.mesh.setTransfiniteCurve(tag, 25 if key in ("bottom", "top") else 4)
        gmsh.model.mesh.setTransfiniteSurface(1)
        gmsh.model.mesh.setRecombine(2, 1)
        gmsh.model.addPhysicalGroup(2, [1], name="plate")
        gmsh.model.addPhysicalGroup(1, [curves["bottom"], curves["top"]], name="edge_beam")
        gmsh.model.addPhysicalGroup(1, [curves["left"]], name="clamp")
        gmsh.model.addPhysicalGroup(1, [curves["right"]], name="tip")
        gmsh.model.mesh.generate(2)
        gmsh.write(str(tmp_path / "stiffened.msh"))
    finally:
        gmsh.finalize()
    sec = BeamSection.rectangle(a=0.02, b=0.04)            # side b along V2 = the bending plane
    s = Structure.from_mesh(tmp_path / "stiffened.msh", shells={"plate": ShellSection(E=E, nu=0.0, thickness=h)},
                            beams={"edge_beam": dict(section=sec, E=E, nu=0.3, v1=[0, 1, 0])},
                            trusses={}, orient=(0, 0, 1))
    assert {"plate", "edge_beam", "clamp", "tip"} <= set(s.node_sets)
    assert s.node_sets["tip"].size == 4 and s.node_sets["clamp"].size == 4
    s.fix("clamp")
    beam_nodes = np.unique(s.element_sets["edge_beam"].beams.conn)
    roots = beam_nodes[np.isclose(s.X[0, beam_nodes], 0.0)]
    assert roots.size == 2
    s.fix(roots, ["rx", "ry", "rz"])                       # the beams' own clamps (their nodes are pinned)
    s.line_load("tip", (0, 0, P / b))
    st = s.solve_linear()
    EI = E * b * h**3 / 12 + 2 * E * sec.I_s
    w_shear = P * L / (2 * sec.shear_coefficient(0.3) * E / 2.6 * sec.A)   # all the shear in the beams
    w = s.displacements(st)[2, s.node_sets["tip"]].mean()
    assert w == pytest.approx(P * L**3 / (3 * EI) + w_shear, rel=0.005)
    F, _ = s.resultant(st)
    np.testing.assert_allclose(F, [0, 0, -P], atol=1e-8 * abs(P))


def test_bars_and_tendons_of_a_system_meshed_by_gmsh():
    """Every bar and tendon of a preset system becomes a line with its ends at the system's
    nodes, in one physical group per family."""
    from tmfem.mesh.frame import system_frame_mesh
    from tmfem.system.presets import load_preset
    system = load_preset("1-4")
    m = system_frame_mesh(system)
    sets = {k: v["line"] for k, v in m.cell_sets_dict.items() if not k.startswith("gmsh:")}
    families = sorted({f"tendons_{t.family}" for t in system.tendons})
    assert sorted(sets) == sorted(["bars"] + families)
    assert sets["bars"].size == system.bar_connectivity.shape[1]
    assert sum(sets[f].size for f in families) == len(system.tendons)
    X = system.nodes()
    lines = np.concatenate([c.data for c in m.cells if c.type == "line"])
    ends = m.points[lines]                                            # (m, 2, 3)
    want = np.hstack([system.bar_connectivity, system.tendon_connectivity])
    np.testing.assert_allclose(ends[:, 0], X[:, want[0]].T, atol=1e-12)
    np.testing.assert_allclose(ends[:, 1], X[:, want[1]].T, atol=1e-12)

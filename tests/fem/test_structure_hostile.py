"""Hostile input to the Structure API: an empty or non-finite mesh, a section without
thickness, coincident nodes and a structure whose supports leave a rigid-body motion free
are refused with one clear message, never a silent answer."""
import numpy as np
import pytest
import skfem

from tmfem.errors import InputError
from tmfem.fem.mitc4 import ShellSection
from tmfem.fem.structure.model import Structure
from tmfem.solvers.singular import SingularMatrix

SECTION = ShellSection(thickness=0.001, E=70e9, nu=0.3)
SQUARE = (np.array([[0, 1, 1, 0], [0, 0, 1, 1.0]]), np.array([[0], [1], [2], [3]]))


def plate():
    s = Structure.shell(skfem.MeshQuad.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5)),
                        section=SECTION, orient=(0, 0, 1))
    s.point_load(s.nodes_where(lambda x, y, z: x > 1 - 1e-9), force=(0, 0, 1.0))
    return s


def test_unsupported_structure_is_refused_not_solved():
    # source: a free plate has six rigid-body motions, so K is singular; before the check
    # its linear solve returned displacements of ~4e9 m
    with pytest.raises(SingularMatrix, match="expected supports that hold every rigid-body "
                                             "motion"):
        plate().solve_linear()


def test_supported_thin_plate_still_solves():
    # source: Euler-Bernoulli cantilever plate, w = F L^3 / (3 E I) with the line load of
    # 5 nodes (1 N each) on a 1 m wide strip, I = b h^3 / 12: the shell's tip deflection
    # is within 10 % on this 4 x 4 mesh (plate stiffening by nu^2 and the coarse mesh)
    s = plate()
    s.fix(s.nodes_where(lambda x, y, z: x < 1e-9))
    st = s.solve_linear()
    I = 1.0 * 0.001**3 / 12
    w = 5.0 * 1.0**3 / (3 * 70e9 * I)
    tip = s.displacements(st)[2, s.nodes_where(lambda x, y, z: x > 1 - 1e-9)]
    assert np.allclose(tip, w, rtol=0.1)


@pytest.mark.parametrize("mesh, match", [
    ((np.zeros((2, 0)), np.zeros((4, 0), int)), "n >= 1"),
    ((SQUARE[0], np.zeros((4, 0), int)), "n >= 1"),
    ((np.array([[0, 1, np.nan, 0], [0, 0, 1, 1.0]]), SQUARE[1]), "finite node coordinates"),
    ((np.array([[0, 1, 1, 1], [0, 0, 1, 1.0]]), SQUARE[1]), "non-degenerate corners"),
    ((SQUARE[0], np.array([[0], [1], [1], [3]])), "non-degenerate corners"),
    ((SQUARE[0], np.array([[0], [1], [2], [7]])), r"node indices in \[0, 4\)"),
])
def test_bad_meshes_refused(mesh, match):
    with pytest.raises(InputError, match=match):
        Structure.shell(mesh, section=SECTION)


@pytest.mark.parametrize("h", [0.0, -1.0, float("nan")])
def test_section_without_thickness_refused(h):
    with pytest.raises(InputError, match="expected thickness > 0"):
        ShellSection(thickness=h, E=70e9, nu=0.3)


def test_no_nodes_refused():
    with pytest.raises(InputError, match=r"n >= 1, found \(3, 0\)"):
        Structure(points=np.zeros((3, 0)), dofs=3)

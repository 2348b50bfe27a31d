"""Membrane meshes of 6.2: N quadrilaterals of n x n elements (gmsh transfinite)."""
import numpy as np
import pytest

from tmfem.errors import InputError
from tmfem.mesh import polygon_quad_mesh
from tmfem.system import membrane_corners_regular


@pytest.mark.parametrize("N, n, n_el", [(4, 10, 400), (3, 10, 300), (6, 10, 600), (4, 3, 36)])
def test_element_counts_of_section_6_2(N, n, n_el):
    corners = membrane_corners_regular(N, 1.5)
    m = polygon_quad_mesh(corners, n)
    assert m.t.shape == (4, n_el)
    assert m.p.shape[1] == N * n * n + N * n + 1   # nodes of N n x n patches sharing edges
    np.testing.assert_allclose(m.p[:, m.corners], corners, atol=1e-12)
    # total area equals the polygon area, every element positively oriented
    x, y = m.p[0, m.t], m.p[1, m.t]
    a = 0.5 * np.sum(x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y, axis=0)
    assert np.all(a > 0)
    assert a.sum() == pytest.approx(0.5 * N * 1.5**2 * np.sin(2 * np.pi / N), rel=1e-12)


def test_square_quadrant_is_the_bilinear_transfinite_grid():
    m = polygon_quad_mesh(membrane_corners_regular(4, np.sqrt(2)), 4)
    # the square [0,2]^2 splits into four 1x1 quadrants: a uniform grid of spacing 0.25
    np.testing.assert_allclose(np.sort(np.unique(np.round(m.p[0], 9))), np.linspace(0, 2, 9))


def test_non_convex_polygon_is_rejected():
    with pytest.raises(InputError, match="convex"):
        polygon_quad_mesh(np.array([[0, 1, 0.2, 0], [0, 0, 0.2, 1.0]]), 2)



def test_small_meshes_are_kept_and_large_ones_made_anew():
    """A mesh of at most KEPT_ELEMENTS elements is gmsh's once per corners and n; a larger one
    is not kept. Either way each call gets arrays of its own, equal to gmsh's mesh."""
    from tmfem.mesh import polygon
    corners = np.array([[1.0, -0.5, -0.6], [0.1, 0.9, -0.8]])
    for n, kept in [(4, True), (24, False)]:     # 3 n^2 elements: 48 and 1728
        assert (3 * n * n <= polygon.KEPT_ELEMENTS) == kept
        fresh = polygon._gmsh_polygon_mesh(corners.tobytes(), 3, n)
        before = polygon._kept_polygon_mesh.cache_info()
        a, b = polygon_quad_mesh(corners, n), polygon_quad_mesh(corners, n)
        after = polygon._kept_polygon_mesh.cache_info()
        assert (after.misses - before.misses, after.hits - before.hits) == ((1, 1) if kept else (0, 0))
        for m in (a, b):
            np.testing.assert_array_equal(m.p, fresh[0])
            np.testing.assert_array_equal(m.t, fresh[1])
        a.p[0, 0] += 1.0                         # a caller's change reaches no other call
        assert polygon_quad_mesh(corners, n).p[0, 0] == fresh[0][0, 0]

"""The grid generator's grading toward the patch's edges (-ssi_mesh_grade, issue 46: the rigid
footing's singular edge tractions)."""
import numpy as np
import pytest

from petsc_ssi.mesh import surface

pytestmark = pytest.mark.unit


def _lines(mesh):
    xs = np.unique(np.round(mesh.nodes[mesh.cells[:, :4], 0], 12))
    return xs


def test_grade_zero_is_the_uniform_grid_bit_for_bit():
    a = surface.grid(6.0, 6.0, 0.25, (1.0, 1.0))
    b = surface.grid(6.0, 6.0, 0.25, (1.0, 1.0), grade=0.0)
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.cells, b.cells)


@pytest.mark.parametrize("xmin", [None, 0.0])
def test_graded_grid_keeps_the_patch_the_count_and_the_area(xmin):
    """grade = 1 on the full and the quarter grid: the same number of elements, grid lines through
    x = +-1 (the patch's edges) and its 'load' group of the same size, the element areas summing
    to the extent, mid-side nodes half-way, and the elements next to an edge at most half as wide
    as the uniform ones, growing away from it."""
    u = surface.grid(6.0, 6.0, 0.25, (1.0, 1.0), xmin=xmin, ymin=xmin)
    g = surface.grid(6.0, 6.0, 0.25, (1.0, 1.0), xmin=xmin, ymin=xmin, grade=1.0)
    assert len(g.cells) == len(u.cells) and len(g.groups["load"]) == len(u.groups["load"])
    xs = _lines(g)
    assert np.any(np.isclose(xs, 1.0, atol=1e-12)) and np.all(np.diff(xs) > 0)
    X = g.cell_coords()
    w = X[:, 1, 0] - X[:, 0, 0]
    hgt = X[:, 3, 1] - X[:, 0, 1]
    area = np.abs(w * hgt).sum()
    span = 6.0 if xmin is None else 3.0
    assert area == pytest.approx(span * span, rel=1e-12)
    assert np.allclose(X[:, 4], 0.5 * (X[:, 0] + X[:, 1]))                 # mid-side node of the first side
    d = np.diff(xs)
    i = int(np.argmin(np.abs(xs - 1.0)))
    assert d[i - 1] < 0.5 * 0.25 and d[i] < 0.5 * 0.25                       # both sides of the edge x = 1
    assert np.all(np.diff(d[i:i + 4]) > 0) and np.all(np.diff(d[i - 4:i][::-1]) > 0)


def test_grading_needs_a_patch():
    with pytest.raises(ValueError, match="patch"):
        surface.grid(6.0, 6.0, 0.25, None, grade=0.5)

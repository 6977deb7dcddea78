"""nd.plot_deformed draws the body moved by u_h, magnified by a factor its title states."""

import re

import numpy as np
import pytest

import ngdual as nd
from ngdual.plot.deformed import magnification, vertex_displacement


@pytest.fixture(scope="module")
def hertz():
    return nd.solve(nd.load_scene("hertz-cylinder"), 1)


def test_the_magnification_shows_the_largest_displacement_at_5_to_10_percent(hertz):
    points, _, u = vertex_displacement(hertz)
    size = max(np.ptp(points[:, 0]), np.ptp(points[:, 1]))
    fig = nd.plot_deformed(hertz)
    scale = float(re.search(r"magnified (\S+) times", fig.axes[0].get_title()).group(1))
    assert 0.05 <= scale * np.linalg.norm(u, axis=1).max() / size <= 0.106


def test_the_vertex_displacement_carries_the_prescribed_top_displacement(hertz):
    """The top of hertz-cylinder is moved by (0, -0.02): u_h there within 5 % (at order 0
    u_h is constant per triangle: the vertex average is that of the triangles' centroids,
    measured 2 % off on level 1)."""
    points, _, u = vertex_displacement(hertz)
    top = points[:, 1] > points[:, 1].max() - 1e-9
    assert np.allclose(u[top], [0.0, -0.02], atol=1e-3)


def test_a_given_scale_is_drawn_and_stated(hertz):
    fig = nd.plot_deformed(hertz, scale=7.0)
    assert "magnified 7 times" in fig.axes[0].get_title()


def test_magnifications_are_round_numbers():
    for largest in np.geomspace(1e-6, 1e3, 40):
        factor = magnification(largest, 1.0)
        mantissa = factor / 10 ** np.floor(np.log10(factor) + 1e-12)
        assert round(mantissa, 9) in (1.0, 2.0, 3.0, 5.0)
    assert magnification(0.0, 1.0) == 1.0

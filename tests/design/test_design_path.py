"""Paths: segment geometry, curvature, transforms and validation."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.path import Arc, Line, Path, Polyline, Sinusoid, chain_segments
from rotomorph.errors import InvalidDesignError


def test_line_arc_sinusoid_chain_ends_where_geometry_says():
    p = Path.from_segments(
        [Line(10.0), Arc(5.0, np.pi / 2), Sinusoid(1.0, 4.0, 2), Line(2.0)], spacing=0.25
    )
    # line to (10, 0), quarter turn left to (15, 5) heading +y, 8 mm of sine axis, 2 mm line
    np.testing.assert_allclose(p.points[-1], [15.0, 15.0, 0.0], atol=1e-12)
    assert np.all(p.edge_lengths < 0.26)


def test_arc_curvature_and_heading():
    p = Path.from_segments([Arc(5.0, -np.pi)], spacing=0.1)
    np.testing.assert_allclose(p.curvature[1:-1], -1 / 5.0, rtol=1e-3)
    np.testing.assert_allclose(p.points[-1], [0.0, -10.0, 0.0], atol=1e-12)
    assert p.heading[-1] == pytest.approx(-np.pi, abs=0.02)
    assert p.length == pytest.approx(5 * np.pi, rel=1e-3)


def test_sinusoid_amplitude_and_sign_of_curvature():
    p = Path.from_segments([Sinusoid(1.5, 10.0, 1)], spacing=0.05)
    assert p.points[:, 1].max() == pytest.approx(1.5, abs=1e-3)
    # first half swings left and bends right (negative curvature), second half the opposite
    k = p.curvature
    s = p.points[:, 0]
    assert np.all(k[(s > 0.5) & (s < 4.5)] < 0)
    assert np.all(k[(s > 5.5) & (s < 9.5)] > 0)


def test_chain_owner_marks_segments():
    pts, owner = chain_segments([Line(1.0), Line(2.0)], spacing=0.5)
    assert len(pts) == 7
    assert owner.tolist() == [0, 0, 1, 1, 1, 1, 1]


def test_polyline_must_continue_from_current_end():
    Path.from_segments([Line(1.0), Polyline([[1.0, 0, 0], [2.0, 1.0, 0]])])
    with pytest.raises(InvalidDesignError, match=r"segments\[1\]\.points"):
        Path.from_segments([Line(1.0), Polyline([[5.0, 0, 0], [6.0, 1.0, 0]])])


def test_transforms():
    p = Path.line((0, 0, 0), (4, 0, 0), spacing=1.0)
    np.testing.assert_allclose(p.scaled(2).points[-1], [8, 0, 0])
    np.testing.assert_allclose(p.translated((1, 2, 3)).points[0], [1, 2, 3])
    r = p.resampled(0.5)
    assert r.n_vertices == 9 and r.length == pytest.approx(4.0)
    np.testing.assert_allclose(p.reversed().points[0], [4, 0, 0])


@pytest.mark.parametrize(
    ("points", "match"),
    [
        (np.zeros((0, 3)), "empty"),
        ([[0, 0, 0]], "at least 2"),
        ([[0, 0, 0], [1, np.nan, 0]], "finite; vertex 1"),
        ([[0, 0, 0], [1, 0, 0], [1, 0, 0]], "vertices 1 and 2 are repeated"),
    ],
)
def test_invalid_paths_name_the_field(points, match):
    with pytest.raises(InvalidDesignError, match=match) as info:
        Path(np.array(points, dtype=float))
    assert info.value.field == "Path.points"


def test_invalid_segments():
    with pytest.raises(InvalidDesignError, match=r"Line\.length"):
        Line(-1.0)
    with pytest.raises(InvalidDesignError, match=r"Sinusoid\.wavelength"):
        Sinusoid(1.0, 0.0)
    with pytest.raises(InvalidDesignError, match="segments"):
        Path.from_segments([])

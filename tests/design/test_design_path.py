"""Paths: segment geometry, curvature, transforms and validation."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.path import (
    Arc,
    Line,
    Path,
    Polyline,
    Sinusoid,
    chain_segments,
    tangent_headings,
)
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
        ([[0, 0, 0], [1, 0, 0], [1, 0, 0]], r"vertices 1 and 2 \(1, 0, 0\) mm are repeated"),
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


def test_polyline_edges_are_split_at_the_vertex_spacing_keeping_its_corners():
    corner = [[0.0, 0, 0], [1.0, 0, 0], [1.0, 0.25, 0]]
    path = Path.from_segments([Polyline(corner)], spacing=0.1)
    assert len(path.points) == 10 + 3 + 1  # 1 mm in 10 edges, 0.25 mm in 3
    # the given vertices stay vertices (the corner is kept), the pieces are equal
    for p in corner:
        assert np.min(np.linalg.norm(path.points - p, axis=1)) < 1e-12
    lengths = np.linalg.norm(np.diff(path.points, axis=0), axis=1)
    np.testing.assert_allclose(lengths[:10], 0.1, rtol=1e-12)
    np.testing.assert_allclose(lengths[10:], 0.25 / 3, rtol=1e-12)
    as_given = Path.from_segments([Polyline(corner, resample=False)], spacing=0.1)
    np.testing.assert_array_equal(as_given.points, corner)


def test_a_polyline_design_is_resolved_at_its_spacing():
    """A two-point polyline filament is a rod at the filament's spacing (it was one edge, so
    refused as too short to bend, whatever the spacing), and the size estimate counts it."""
    from rotomorph.io.designfile import parse_design

    fil = {"spacing": 0.5, "segments": [{"kind": "polyline", "points": [[0, 0, 0], [10, 0, 0]]}]}
    design = parse_design({"schema_version": 1, "filaments": [fil]})
    (f,) = design.filaments
    assert len(f.to_program().points) == f.node_count() == 21
    given = {**fil, "segments": [{**fil["segments"][0], "resample": False}]}
    with pytest.raises(InvalidDesignError, match="vertices"):
        parse_design({"schema_version": 1, "filaments": [given]})


def test_tangent_headings_are_exact_at_the_ends_of_arcs():
    # a chord's heading lags an arc's tangent by half the chord's turning angle (the mean of
    # two edges at a join by a quarter): the tangent there is the arc's own
    segs = [Line(20.0), Arc(60.0, np.pi / 3), Arc(30.0, -np.radians(40.0)), Line(10.0)]
    pts, owner = chain_segments(segs, start=(20.0, 20.0, 0.0), spacing=1.0)
    psi = tangent_headings(segs, pts, owner)
    joins = np.flatnonzero(np.diff(owner)) + 1
    want = [0.0, np.pi / 3, np.pi / 3 - np.radians(40.0)]
    np.testing.assert_allclose(psi[joins], want, atol=1e-15)
    np.testing.assert_allclose(psi[[0, -1]], [0.0, np.pi / 3 - np.radians(40.0)], atol=1e-15)
    # elsewhere the polygon's vertex heading: the mean of its edges (exact inside an arc)
    polygon = Path(pts).heading
    mean = np.concatenate([[polygon[0]], 0.5 * (polygon[1:] + polygon[:-1]), [polygon[-1]]])
    inner = np.setdiff1d(np.arange(len(pts)), [0, len(pts) - 1, *joins])
    np.testing.assert_array_equal(psi[inner], mean[inner])
    turn = np.pi / 3 / np.count_nonzero(owner[:-1] == 1)  # one chord's turn on the 60 mm arc
    np.testing.assert_allclose(psi[joins[0]] - mean[joins[0]], -turn / 4, rtol=1e-9)
    # ending on an arc (and starting on one, heading 90 deg): half a chord's turn
    segs = [Arc(60.0, np.radians(50.0))]
    pts, owner = chain_segments(segs, heading=np.pi / 2, spacing=1.0)
    psi = tangent_headings(segs, pts, owner, heading=np.pi / 2)
    np.testing.assert_allclose(psi[[0, -1]], np.pi / 2 + np.radians([0.0, 50.0]))
    turn = np.radians(50.0) / (len(pts) - 1)
    np.testing.assert_allclose(psi[-1] - Path(pts).heading[-1], turn / 2, rtol=1e-9)
    assert np.degrees(turn / 2) > 0.45  # the 0.48 deg a 1 mm chord lags on 60 mm


def test_tangent_headings_keep_corners_and_paths_without_arcs():
    # a sinusoid meets the arc at an angle (its end tangent swings off the axis): a corner
    segs = [Sinusoid(1.0, 5.0, 1.0), Arc(20.0, 1.0)]
    pts, owner = chain_segments(segs, spacing=0.5)
    psi = tangent_headings(segs, pts, owner)
    polygon = Path(pts).heading
    join = int(np.flatnonzero(np.diff(owner))[0]) + 1
    assert psi[join] == pytest.approx(0.5 * (polygon[join - 1] + polygon[join]))
    assert psi[-1] == pytest.approx(1.0)  # still the arc's tangent at the path end
    segs = [Line(3.0), Sinusoid(1.0, 5.0, 2.0)]
    pts, owner = chain_segments(segs, spacing=0.3)
    polygon = Path(pts).heading
    mean = np.concatenate([[polygon[0]], 0.5 * (polygon[1:] + polygon[:-1]), [polygon[-1]]])
    np.testing.assert_array_equal(tangent_headings(segs, pts, owner), mean)

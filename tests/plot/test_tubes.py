"""Janus tubes: geometry of the facets, the active side, and both colours in the picture."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import figure_to_rgb
from rotomorph.plot.shapes import scalar_norm
from rotomorph.plot.tubes import (
    ACTIVE_COLOUR,
    PASSIVE_COLOUR,
    TubePanel,
    interface_offset,
    plot_tube_panels,
    tube_mesh,
)


def coil(n=60, turns=2.0, radius=3.0, pitch=2.0):
    t = np.linspace(0, 2 * np.pi * turns, n)
    pts = np.stack([radius * np.cos(t), radius * np.sin(t), pitch * t / (2 * np.pi)], 1)
    edges = np.stack([np.arange(n - 1), np.arange(1, n)], 1)
    mid = 0.5 * (pts[1:] + pts[:-1])
    inward = -np.c_[mid[:, :2], np.zeros(n - 1)]
    return pts, edges, inward / np.linalg.norm(inward, axis=1)[:, None]


@pytest.mark.parametrize("f", [0.5, 0.25, 0.8, 0.05])
def test_interface_offset_cuts_the_area_fraction(f):
    d = interface_offset(f)
    theta = 2 * np.arccos(d)
    assert (theta - np.sin(theta)) / (2 * np.pi) == pytest.approx(f, abs=1e-9)
    assert interface_offset(0.5) == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(InvalidParameterError, match="active_fraction"):
        interface_offset(1.5)


def test_tube_facets_lie_on_the_tube_and_split_by_the_normal():
    pts, edges, inward = coil()
    r = 0.4
    quads, normals, active, seg = tube_mesh(pts, edges, r, inward, facets=16)
    assert quads.shape == (len(edges) * 16, 4, 3) and normals.shape == (len(quads), 3)
    # every corner is one radius from its segment's axis line (mitred rings: up to 1/cos)
    a, b = pts[edges[seg, 0]], pts[edges[seg, 1]]
    t = (b - a) / np.linalg.norm(b - a, axis=1)[:, None]
    for c in range(4):
        d = quads[:, c] - a
        dist = np.linalg.norm(d - np.einsum("ij,ij->i", d, t)[:, None] * t, axis=1)
        assert np.all(dist > 0.95 * r) and np.all(dist < 1.1 * r)
    # a symmetric section: exactly half the facets active, and they face the given normal
    assert active.sum() == len(active) // 2
    facing = np.einsum("ij,ij->i", normals, inward[seg])
    assert np.all(facing[active] > 0) and np.all(facing[~active] < 0)
    # a quarter of the section active: the surface shows the arc beyond the chord that cuts
    # a quarter of the area, θ/2π of the perimeter with θ = 2 arccos(d/R) ≈ 0.367
    _, _, act, _ = tube_mesh(pts, edges, r, inward, facets=64, active_fraction=0.25)
    arc = 2 * np.arccos(interface_offset(0.25)) / (2 * np.pi)
    assert act.mean() == pytest.approx(arc, abs=1 / 64)
    _, _, none, _ = tube_mesh(pts, edges, r, None)
    assert none is None


def test_neighbouring_segments_share_their_end_rings():
    pts, edges, inward = coil()
    k = 12
    quads, _, _, _ = tube_mesh(pts, edges, 0.4, inward, facets=k)
    start = quads[:, 0].reshape(len(edges), k, 3)  # ring at each segment's first node
    end = quads[:, 3].reshape(len(edges), k, 3)  # ... and at its second
    # one ring where two segments meet: no gap and no seam between the tube's pieces
    np.testing.assert_allclose(end[:-1], start[1:], atol=1e-12)
    # where the active side flips, each segment keeps its own ring (the colours stay sharp)
    flipped = inward.copy()
    flipped[30:] *= -1
    quads, _, _, _ = tube_mesh(pts, edges, 0.4, flipped, facets=k)
    start = quads[:, 0].reshape(len(edges), k, 3)
    end = quads[:, 3].reshape(len(edges), k, 3)
    assert not np.allclose(end[29], start[30])
    np.testing.assert_allclose(end[30:-1], start[31:], atol=1e-12)


def test_tube_mesh_rejects_bad_input():
    pts, edges, inward = coil(10)
    with pytest.raises(InvalidParameterError, match="facets"):
        tube_mesh(pts, edges, 0.3, inward, facets=2)
    with pytest.raises(InvalidParameterError, match="radius"):
        tube_mesh(pts, edges, -1.0, inward)
    with pytest.raises(InvalidParameterError, match="normals"):
        tube_mesh(pts, edges, 0.3, inward[:-1])


def _colour_pixels(rgb: np.ndarray, colour: str, tol: float = 0.22) -> int:
    """Pixels whose hue matches ``colour`` (shading scales brightness, not hue)."""
    target = np.array(to_rgb(colour))
    px = rgb.reshape(-1, 3) / 255.0
    bright = px.max(axis=1)
    ok = bright > 0.15
    dirn = px[ok] / np.linalg.norm(px[ok], axis=1)[:, None]
    ref = target / np.linalg.norm(target)
    return int(np.sum(np.linalg.norm(dirn - ref, axis=1) < tol))


def test_tube_view_shows_both_janus_colours():
    pts, edges, inward = coil()
    straight = np.c_[np.linspace(0, 20, 60), np.zeros(60), np.zeros(60)]
    panels = [
        TubePanel(pts, edges, 0.4, inward, title="coil", ghost=straight),
        TubePanel(straight, edges, 0.4, np.tile([0.0, 0.0, 1.0], (59, 1)), title="printed"),
    ]
    fig = plot_tube_panels(panels, suptitle="two panels", dpi=60)
    rgb = figure_to_rgb(fig)
    assert _colour_pixels(rgb, ACTIVE_COLOUR) > 200
    assert _colour_pixels(rgb, PASSIVE_COLOUR) > 200
    # one common scale: every 3-D panel spans the same number of millimetres
    spans = {round(float(np.diff(ax.get_xlim())[0]), 9) for ax in fig.axes if ax.name == "3d"}
    assert len(spans) == 1
    # without interface normals the sides are not invented: no Janus colour at all
    grey = figure_to_rgb(plot_tube_panels([TubePanel(pts, edges, 0.4, None)], dpi=60))
    assert _colour_pixels(grey, ACTIVE_COLOUR) == 0


def test_field_colouring_needs_one_shared_norm():
    pts, edges, _ = coil(20)
    panel = TubePanel(pts, edges, 0.3, values=np.linspace(-1, 1, 19))
    with pytest.raises(InvalidParameterError, match="norm"):
        plot_tube_panels([panel])
    fig = plot_tube_panels([panel], norm=scalar_norm(np.linspace(-1, 1, 5)), label="k", dpi=50)
    assert figure_to_rgb(fig).std() > 5.0


def test_colour_scale_does_not_amplify_round_off():
    noise = np.random.default_rng(0).normal(scale=1e-7, size=50)
    norm = scalar_norm(noise)
    assert norm.vmin <= -1e-3 and norm.vmax >= 1e-3  # round-off sits in the neutral centre
    assert np.all(np.abs(norm(noise) - 0.5) < 1e-3)
    real = np.linspace(-0.2, 0.3, 50)
    assert scalar_norm(real).vmax == pytest.approx(np.percentile(real, 98))


def _content_box(rgb: np.ndarray) -> tuple[int, int, int, int]:
    """Rows and columns of the pixels that are not white: (top, bottom, left, right)."""
    ink = np.argwhere(rgb.min(axis=2) < 235)
    return ink[:, 0].min(), ink[:, 0].max(), ink[:, 1].min(), ink[:, 1].max()


def test_panels_are_framed_to_what_they_show():
    """A long straight filament and a flat lattice fill their figures (before: a 3-D box in a
    square panel, most of it white)."""
    s = np.linspace(0.0, 30.0, 61)
    line = np.c_[s, 0 * s, 0 * s]
    edges = np.stack([np.arange(60), np.arange(1, 61)], 1)
    normals = np.tile([0.0, 0.0, 1.0], (60, 1))
    fig = plot_tube_panels([TubePanel(line, edges, 0.3, normals)], legend=False, dpi=60)
    rgb = figure_to_rgb(fig)
    top, bottom, left, right = _content_box(rgb)
    h, w = rgb.shape[:2]
    assert (right - left) > 0.85 * w and (bottom - top) > 0.7 * h
    assert w > 2.0 * h  # a long thin shape gets a wide, low figure


def test_a_small_shape_beside_a_long_ghost_gets_an_inset():
    pts, edges, inward = coil(n=80, turns=3.0, radius=0.8, pitch=0.9)
    s = np.linspace(0.0, 40.0, len(pts))
    ghost = np.c_[s - 20.0, 0 * s - 3.0, 0 * s - 1.0]
    straight = TubePanel(ghost, edges, 0.3, np.tile([0.0, 0.0, 1.0], (len(edges), 1)))
    small = TubePanel(pts, edges, 0.3, inward, ghost=ghost)
    fig = plot_tube_panels([small, straight], dpi=60)
    assert [ax.get_label() for ax in fig.axes if ax.name == "3d"] == ["panel", "inset", "panel"]
    labels = [t.get_text() for ax in fig.axes if ax.name != "3d" for t in ax.texts]
    (times,) = [t for t in labels if t.startswith("×")]
    assert float(times[1:]) >= 2.0
    # a movie keeps its frame: no insets with a fixed extent
    centres = [np.zeros(3), np.zeros(3)]
    fixed = plot_tube_panels([small, straight], extent=(centres, np.full(3, 21.0)), dpi=40)
    assert len([ax for ax in fixed.axes if ax.name == "3d"]) == 2

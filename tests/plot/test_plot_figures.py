"""Figures and GIFs: files exist, are not trivial, and are not blank."""

from __future__ import annotations

import itertools
import os

import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

from rotomorph.errors import InvalidParameterError
from rotomorph.plot.animate import animate_gif
from rotomorph.plot.figure import crowded_ticks, figure_to_rgb, new_figure, save_figure
from rotomorph.plot.report import plot_measured_vs_predicted, plot_parity
from rotomorph.plot.shapes import plot_lattice_views, plot_network_3d, segment_values


def small_lattice(n: int = 3, spacing: float = 10.0, ghosts: int = 4):
    """Branch nodes 0..n²-1 on a grid, sinusoidal ghost nodes, segments (E, 2)."""
    nodes = [np.array([[spacing * i, spacing * j, 0.0] for i in range(n) for j in range(n)])]
    edges, nxt = [], n * n
    s = np.arange(1, ghosts + 1)
    for i in range(n):
        for j in range(n):
            for di, dj in ((1, 0), (0, 1)):
                if i + di < n and j + dj < n:
                    a, b = n * i + j, n * (i + di) + (j + dj)
                    t = (nodes[0][b] - nodes[0][a]) / spacing
                    normal = np.cross([0, 0, 1.0], t)
                    nodes.append(
                        nodes[0][a]
                        + np.outer(s * spacing / (ghosts + 1), t)
                        + np.outer(2.0 * np.sin(2 * np.pi * s / (ghosts + 1)), normal)
                    )
                    ids = [a, *range(nxt, nxt + ghosts), b]
                    nxt += ghosts
                    edges += list(itertools.pairwise(ids))
    return np.concatenate(nodes), np.array(edges)


def png_pixels(path):
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"), dtype=float)


def helix(n=80):
    t = np.linspace(0, 6 * np.pi, n)
    pts = np.stack([np.cos(t), np.sin(t), 0.2 * t], 1)
    return pts, np.stack([np.arange(n - 1), np.arange(1, n)], 1)


def test_3d_filament_coloured_png_and_svg(tmp_path):
    pts, edges = helix()
    values = np.linspace(-1, 1, len(pts))
    values[:3] = np.nan
    fig = plot_network_3d(pts, edges, values, label="(κ − κ_i)/κ_i", title="helix")
    assert isinstance(fig, Figure)
    png = save_figure(fig, tmp_path / "helix.png")
    svg = save_figure(fig, tmp_path / "helix.svg")
    assert png.stat().st_size > 5_000 and svg.stat().st_size > 5_000
    pix = png_pixels(png)
    assert pix.std() > 5.0
    # colour: some strongly red and some strongly blue pixels (coolwarm ends)
    red = (pix[..., 0] > 150) & (pix[..., 2] < 100)
    blue = (pix[..., 2] > 150) & (pix[..., 0] < 100)
    assert red.sum() > 20 and blue.sum() > 20
    assert sorted(os.listdir(tmp_path)) == ["helix.png", "helix.svg"]


def test_3d_axes_have_equal_scale():
    pts, edges = helix()
    ax = plot_network_3d(pts * [1.0, 1.0, 5.0], edges).axes[0]
    spans = np.array(
        [np.diff(ax.get_xlim())[0], np.diff(ax.get_ylim())[0], np.diff(ax.get_zlim())[0]]
    )
    box = np.array(ax.get_box_aspect())
    np.testing.assert_allclose(box / box[0], spans / spans[0], rtol=1e-6)


def test_lattice_views(tmp_path):
    pos, edges = small_lattice()
    pos[:, 2] = -((pos[:, 0] - 10) ** 2 + (pos[:, 1] - 10) ** 2) / 80.0
    fig = plot_lattice_views(pos, edges, pos[:, 2], label="z (mm)")
    assert len(fig.axes) == 3  # top, side, colour bar
    pix = png_pixels(save_figure(fig, tmp_path / "lattice.png"))
    assert pix.std() > 5.0
    plain = figure_to_rgb(plot_lattice_views(pos, edges))
    assert plain.std() > 5.0


def test_measured_vs_predicted(tmp_path):
    x = np.array([0.06, 0.25, 1.0, 2.0])
    fig = plot_measured_vs_predicted(
        x,
        [0.22, np.nan, 0.5, 0.98],
        [0.01, 0.0, 0.02, 0.02],
        [0.19, 0.6, 0.9, 0.97],
        xlabel="ω* (–)",
        ylabel="L/L0 (–)",
        title="Fig. 2G",
    )
    ax = fig.axes[0]
    assert ax.get_xlabel() == "ω* (–)"
    assert len(ax.get_legend().get_texts()) == 2
    path = save_figure(fig, tmp_path / "report.png", dpi=80)
    assert path.stat().st_size > 3_000 and png_pixels(path).std() > 5.0
    dense = plot_measured_vs_predicted(
        x,
        x,
        None,
        np.sin(np.linspace(0, 2, 50)),
        xlabel="x",
        ylabel="y",
        predicted_x=np.linspace(0, 2, 50),
    )
    assert figure_to_rgb(dense).std() > 5.0


def test_measured_vs_predicted_rejects_mismatch():
    with pytest.raises(InvalidParameterError, match="measured"):
        plot_measured_vs_predicted([1, 2], [1], None, [1, 2], xlabel="x", ylabel="y")
    with pytest.raises(InvalidParameterError, match="spread"):
        plot_measured_vs_predicted([1, 2], [1, 2], [-1, 1], [1, 2], xlabel="x", ylabel="y")


def test_parity_panels_never_mix_scales():
    """One panel per unit; a sign and a row without a unit each get their own, and rows
    without a measurement are left out."""
    rows = [
        {"quantity": "curvature", "unit": "1/mm", "measured": 0.2, "predicted": 0.25},
        {"quantity": "ratio", "unit": "1", "measured": 0.7, "predicted": 0.6, "counted": True},
        {"quantity": "lattice_gaussian_sign", "unit": "1", "measured": 1.0, "predicted": 1.0},
        {"quantity": "area change (%)", "unit": None, "measured": 99.0, "predicted": 88.0},
        {"quantity": "unmeasured", "unit": "mm", "measured": None, "predicted": 1.0},
    ]
    fig = plot_parity(rows, title="t")
    labels = [ax.get_xlabel() for ax in fig.axes]
    assert labels == [
        "measured (1/mm)",
        "measured (–)",
        "measured sign (–)",
        "measured area change (%)",
    ]
    assert figure_to_rgb(fig).std() > 0
    with pytest.raises(InvalidParameterError, match="rows"):
        plot_parity(rows[-1:])


def test_save_figure_rejects_unknown_suffix_and_is_atomic(tmp_path):
    pts, edges = helix(10)
    fig = plot_network_3d(pts, edges)
    with pytest.raises(InvalidParameterError, match="suffix"):
        save_figure(fig, tmp_path / "x.txt")
    assert os.listdir(tmp_path) == []


def _strain_panels():
    """Two 4-inch panels of signed three-decimal strains, as the report's Fig. 4C/F draws them:
    matplotlib's default ticks (every 0.025) run into each other there."""
    fig = new_figure(10.0, 5.0)
    axes = fig.subplots(1, 2)
    axes[0].plot([-0.158, -0.094, 0.0], [0.18, 0.12, 0.0], "ko-")
    axes[1].plot([0.0, 0.039, 0.071], [0.0, 0.0, 0.066], "ko-")
    axes[0].set_ylim(1e-4, 1.0)
    axes[0].set_yscale("log")  # a log axis keeps its own ticks
    fig.subplots_adjust(wspace=0.3)
    return fig, axes


def test_saved_figures_thin_tick_labels_that_run_into_each_other(tmp_path):
    fig, axes = _strain_panels()
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert crowded_ticks(axes[0].xaxis, renderer)  # matplotlib's default: labels touch
    before = [t.get_text() for t in axes[1].xaxis.get_ticklabels()]
    save_figure(fig, tmp_path / "strain.png")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in axes:
        assert not crowded_ticks(ax.xaxis, renderer)
        assert not crowded_ticks(ax.yaxis, renderer)
    lo, hi = axes[0].get_xlim()
    inside = [x for x in axes[0].get_xticks() if lo <= x <= hi]
    assert len(inside) >= 3  # still a scale to read
    # an axis whose labels stood apart is left as it was
    assert [t.get_text() for t in axes[1].xaxis.get_ticklabels()] == before
    assert axes[0].get_yscale() == "log"


def test_segment_values_ignore_nan():
    v = np.array([1.0, np.nan, 3.0, np.nan])
    out = segment_values(v, np.array([[0, 1], [1, 2], [0, 2], [1, 3]]))
    np.testing.assert_array_equal(out[:3], [1.0, 3.0, 2.0])
    assert np.isnan(out[3])


@pytest.mark.parametrize("view", ["3d", "top"])
def test_animate_gif(tmp_path, view):
    pos, edges = small_lattice()
    frames = np.stack([pos * [1 + 0.2 * s, 1 + 0.2 * s, 1.0] + [0, 0, s] for s in range(4)])
    values = np.tile(np.linspace(-1, 1, len(pos)), (4, 1))
    path = animate_gif(
        frames,
        edges,
        tmp_path / "morph.gif",
        values=values,
        view=view,
        labels=[f"x = {s / 3:.2f}" for s in range(4)],
        size=(3, 3),
        dpi=60,
    )
    assert path.stat().st_size > 2_000
    with Image.open(path) as im:
        assert im.n_frames == 4
        firsts = []
        for k in range(4):
            im.seek(k)
            firsts.append(np.asarray(im.convert("RGB"), dtype=float))
    assert all(f.std() > 5.0 for f in firsts)
    assert np.abs(firsts[0] - firsts[3]).mean() > 1.0  # the lattice visibly moves
    assert os.listdir(tmp_path) == ["morph.gif"]


def test_animate_gif_rejects_bad_input(tmp_path):
    pos, edges = small_lattice()
    with pytest.raises(InvalidParameterError, match="view"):
        animate_gif(pos[None], edges, tmp_path / "a.gif", view="front")
    with pytest.raises(InvalidParameterError, match="values"):
        animate_gif(pos[None], edges, tmp_path / "a.gif", values=np.zeros((2, len(pos))))
    assert os.listdir(tmp_path) == []


def test_relative_change_scale_is_set_where_the_filament_was_printed_curved():
    """(κ − κᵢ)/κᵢ blows up near a sinusoid's inflections (κᵢ → 0): those values are clipped
    (an arrow on the colour bar), not allowed to wash out the rest; each sign gets half the
    colours (the ratio is never below −1)."""
    from matplotlib.colors import TwoSlopeNorm

    from rotomorph.plot.shapes import (
        RELATIVE_CHANGE_LABEL,
        colourbar_extend,
        colourbar_ticks,
        relative_change_norm,
    )

    rng = np.random.default_rng(1)
    arcs = rng.uniform(-0.5, 1.5, 400)  # where the print was curved (κᵢ ≈ 1/mm)
    near_inflection = rng.uniform(5.0, 40.0, 60)  # κᵢ ≈ 0.02/mm
    values = np.r_[arcs, near_inflection]
    printed = np.r_[np.full(400, 1.0), np.full(60, 0.02)]
    norm = relative_change_norm(values, printed)
    assert isinstance(norm, TwoSlopeNorm) and norm.vcenter == 0.0
    assert -0.5 <= norm.vmin < -0.4 and 1.4 < norm.vmax <= 1.5  # the arcs' 2nd-98th percentile
    assert colourbar_extend(norm, values) == "both"
    ticks = colourbar_ticks(norm)
    assert ticks is not None and min(ticks) < 0 < max(ticks) and 0.0 in ticks
    # the figure says what κᵢ is
    assert "κᵢ: curvature as printed" in RELATIVE_CHANGE_LABEL
    # a flat printed state (zero up to round-off) stays neutral
    flat = relative_change_norm(np.full(10, 1e-9), np.ones(10))
    assert flat.vmin <= -1e-3 and flat.vmax >= 1e-3

"""Filaments drawn as shaded tubes with their active and passive halves in two colours.

The tubes are :func:`~rotomorph.plot.tube_mesh.tube_mesh`'s facets (re-exported here with
:func:`interface_offset`).

:func:`plot_tube_panels` draws one or more states side by side in 3-D on one common scale (the
same millimetres per pixel in every panel), with Lambert–Phong shading, a faint ghost of the
printed shape, a scale bar instead of axes, one title per panel and a legend outside the
panels. Colours are either the Janus sides or a per-segment field with a colour bar.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from matplotlib.colors import Colormap, Normalize, to_rgb
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.coarsen import coarsen_network
from rotomorph.plot.figure import new_figure
from rotomorph.plot.shapes import colourbar_extend, colourbar_ticks
from rotomorph.plot.tube_mesh import interface_offset, tube_mesh

__all__ = [
    "ACTIVE_COLOUR",
    "PASSIVE_COLOUR",
    "TubePanel",
    "coarse_panel",
    "interface_offset",
    "plot_tube_panels",
    "shade",
    "tube_extent",
    "tube_mesh",
]

#: Colour of the active (LCE) half.
ACTIVE_COLOUR = "#d7301f"
#: Colour of the passive half.
PASSIVE_COLOUR = "#2b6cb0"
#: Colour of segments whose side is unknown (no interface normal stored).
UNKNOWN_COLOUR = "#8c8c8c"
#: An inset (width and height as fractions of its cell) magnifies a small shape at least this
#: much, or is not drawn.
INSET_WIDTH, INSET_HEIGHT, MIN_MAGNIFICATION = 0.45, 0.62, 2.0
#: Above this many facets a picture falls back to coarser tubes (matplotlib draws each one).
MAX_FACETS = 120_000


def _view_vectors(elev: float, azim: float) -> tuple[FloatArray, FloatArray]:
    """Unit vector toward the camera and toward the light (up and to the left of it)."""
    el, az = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    el2, az2 = np.radians(min(elev + 35.0, 85.0)), np.radians(azim + 35.0)
    light = np.array([np.cos(el2) * np.cos(az2), np.cos(el2) * np.sin(az2), np.sin(el2)])
    return eye, light


def shade(base: FloatArray, normals: FloatArray, eye: FloatArray, light: FloatArray) -> FloatArray:
    """Lambert (two-sided, with ambient) and Phong-highlight shading of RGB colours ``(F, 3)``."""
    lam = np.abs(normals @ light)
    half = light + eye
    half /= np.linalg.norm(half)
    spec = np.abs(normals @ half) ** 40
    rgb = base * (0.38 + 0.62 * lam[:, None]) + 0.35 * spec[:, None]
    return np.clip(rgb, 0.0, 1.0)


@dataclass(frozen=True)
class TubePanel:
    """One panel of :func:`plot_tube_panels`.

    Attributes
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    edges
        Segments ``(E, 2)``.
    radius
        Tube radius (mm), scalar or ``(E,)``.
    normals
        Interface normal toward the active half per segment ``(E, 3)``, or ``None``.
    title
        Panel title (short; one or two lines).
    ghost
        Printed node positions ``(N, 3)`` (mm) drawn faintly behind, or ``None``.
    values
        Per-segment scalar ``(E,)`` to colour by instead of the Janus sides, or ``None``.
    active_fraction
        Active area fraction, scalar or ``(E,)``.
    view
        Camera ``(elev, azim)`` (degrees) of this panel; default the figure's.
    """

    positions: FloatArray
    edges: IntArray
    radius: float | FloatArray
    normals: FloatArray | None = None
    title: str = ""
    ghost: FloatArray | None = None
    values: FloatArray | None = None
    active_fraction: float | FloatArray = 0.5
    view: tuple[float, float] | None = None


def coarse_panel(panel: TubePanel, *, max_turn: float = 0.2) -> TubePanel:
    """``panel`` with runs of segments shorter than the tube radius merged into segments of
    about one radius (:func:`~rotomorph.plot.coarsen.coarsen_network`, within ``max_turn``
    rad, in the drawn and the ghost shape): the picture is the same, with fewer facets to draw.

    Normals and active fractions are taken at each merged run's middle segment (never
    averaged across a flip of the active side), radii and values averaged over the run.
    """
    edges = np.asarray(panel.edges, dtype=np.int64).reshape(-1, 2)
    m = len(edges)
    r = np.broadcast_to(np.asarray(panel.radius, dtype=float), (m,))
    pos = np.asarray(panel.positions, dtype=float)
    shapes = pos if panel.ghost is None else np.stack([pos, np.asarray(panel.ghost, dtype=float)])
    c = coarsen_network(shapes, edges, float(r.min()), max_turn=max_turn)
    if len(c.edges) == m:
        return panel
    pick = c.middle

    def at_middle(v: Any) -> Any:
        a = np.asarray(v, dtype=float)
        return a[pick] if a.ndim >= 1 and len(a) == m else v

    return replace(
        panel,
        edges=c.edges,
        radius=c.mean(r) if np.ndim(panel.radius) else panel.radius,
        normals=at_middle(panel.normals) if panel.normals is not None else None,
        values=c.mean(np.asarray(panel.values, dtype=float)) if panel.values is not None else None,
        active_fraction=at_middle(panel.active_fraction),
    )


def tube_extent(panels: Sequence[TubePanel]) -> tuple[list[FloatArray], FloatArray]:
    """Box centre of every panel and one box for all: half-widths ``(3,)`` along x, y, z (mm).

    Each half-width is the largest half-extent along that axis over the panels (ghost and
    tube radius included), at least 15 % of the largest one so flat shapes keep some depth;
    the boxes are drawn with the aspect of these half-widths, so every panel and every axis
    has the same millimetres per pixel.
    """
    centres, half = [], np.zeros(3)
    for p in panels:
        pts = np.asarray(p.positions, dtype=float)
        allp = pts if p.ghost is None else np.vstack([pts, np.asarray(p.ghost, dtype=float)])
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        centres.append(0.5 * (lo + hi))
        half = np.maximum(half, 0.5 * (hi - lo) + 1.5 * float(np.max(p.radius)))
    biggest = float(half.max()) or 1.0
    return centres, np.maximum(half, 0.15 * biggest)


def _nice_length(span: float) -> float:
    """A round scale-bar length near a fifth of ``span`` (mm)."""
    target = max(span / 5.0, 1e-6)
    power = 10.0 ** np.floor(np.log10(target))
    for step in (1.0, 2.0, 5.0, 10.0):
        if step * power >= target:
            return float(step * power)
    return float(10.0 * power)


def _panel_box(ax: Any, centre: FloatArray, half: FloatArray, zoom: float, view: Any) -> None:
    """Limits, aspect, camera (orthographic: a scale bar holds everywhere) of a 3-D panel."""
    ax.set_proj_type("ortho")
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
    ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
    ax.set_box_aspect(tuple(half), zoom=zoom)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()
    ax.patch.set_visible(False)  # a panel's axes may reach into its neighbour's cell


def _bar_origin(
    p: TubePanel, centre: FloatArray, half: FloatArray, framed: bool, length: float
) -> FloatArray:
    """Start of the scale bar (of ``length`` mm): below the front left of what the panel shows
    (framed), clear of it, or of its box (a fixed extent, as in a movie)."""
    if not framed:
        return np.array([centre[0] - 0.95 * half[0], centre[1] - half[1], centre[2] - half[2]])
    pts = _shown_points(p)
    r = 1.5 * float(np.max(p.radius))
    low = pts[:, 2].min() - r - 0.15 * length
    return np.array([pts[:, 0].min(), pts[:, 1].min() - r, low])


def _bar_points(origin: FloatArray, length: float) -> FloatArray:
    """The scale bar's two ends and where its label hangs below it (mm)."""
    o = np.asarray(origin, dtype=float)
    step = np.array([length, 0.0, 0.0])
    return np.array([o, o + step, o + 0.5 * step - np.array([0.0, 0.0, 0.2 * length])])


def _hold_layout(fig: Figure, ax: Any, cell: tuple[float, float, float, float]) -> None:
    """Make ``ax`` count as its cell (figure fractions) when a figure is saved with a tight
    bounding box: the 3-D axes square is larger than the cell it draws in."""
    from matplotlib.transforms import Bbox, TransformedBbox

    box = TransformedBbox(Bbox.from_bounds(*cell), fig.transFigure)
    ax.get_tightbbox = lambda *args, **kwargs: box  # the square's margins are empty


def _shown_points(p: TubePanel, ghost: bool = True) -> FloatArray:
    pts = np.asarray(p.positions, dtype=float)
    if ghost and p.ghost is not None:
        pts = np.vstack([pts, np.asarray(p.ghost, dtype=float)])
    return pts


def _draw_panel(
    ax: Any,
    p: TubePanel,
    k: int,
    base: FloatArray,
    view: tuple[float, float],
    bar: tuple[FloatArray, float],
    ghost: bool = True,
) -> None:
    """The tubes (shaded facets in ``base`` colours), the ghost and the scale bar of ``p``."""
    pos = np.asarray(p.positions, dtype=float)
    edges = np.asarray(p.edges, dtype=np.int64).reshape(-1, 2)
    if ghost and p.ghost is not None:
        g = np.asarray(p.ghost, dtype=float)
        ax.add_collection3d(
            Line3DCollection(g[edges], colors="0.62", linewidths=1.2, alpha=0.7, zorder=1)
        )
    quads, fn, _, _ = tube_mesh(
        pos, edges, p.radius, p.normals, facets=k, active_fraction=p.active_fraction
    )
    rgb = shade(base, fn, *_view_vectors(*view))
    # edges in the face colour hide the hairline seams anti-aliasing leaves between facets
    ax.add_collection3d(
        Poly3DCollection(quads, facecolors=rgb, edgecolors=rgb, linewidths=0.2, zorder=2)
    )
    (x0, y0, z0), length = bar
    ax.plot([x0, x0 + length], [y0, y0], [z0, z0], color="k", lw=2.0, zorder=3)
    ax.text(x0 + length / 2, y0, z0 - 0.06 * length, f"{length:g} mm", ha="center", va="top",
            fontsize=8, zorder=3)  # fmt: skip


def _facet_colours(
    p: TubePanel, k: int, colormap: Colormap | None, norm: Normalize | None
) -> FloatArray:
    pos = np.asarray(p.positions, dtype=float)
    edges = np.asarray(p.edges, dtype=np.int64).reshape(-1, 2)
    if p.values is not None and colormap is not None and norm is not None:
        vals = np.repeat(np.asarray(p.values, dtype=float), k)
        base = np.asarray(colormap(norm(np.ma.masked_invalid(vals))))[:, :3]
        base[~np.isfinite(vals)] = to_rgb(UNKNOWN_COLOUR)
        return base
    if p.normals is None:
        return np.tile(to_rgb(UNKNOWN_COLOUR), (len(edges) * k, 1))
    _, _, active, _ = tube_mesh(
        pos, edges, p.radius, p.normals, facets=k, active_fraction=p.active_fraction
    )
    assert active is not None
    return np.where(active[:, None], to_rgb(ACTIVE_COLOUR), to_rgb(PASSIVE_COLOUR))


def plot_tube_panels(
    panels: Sequence[TubePanel],
    *,
    columns: int | None = None,
    panel_size: float = 3.6,
    panel_height: float | None = None,
    zoom: float = 0.92,
    elev: float = 28.0,
    azim: float = -58.0,
    cmap: str | Colormap = "coolwarm",
    norm: Normalize | None = None,
    label: str = "",
    suptitle: str = "",
    legend: bool = True,
    facets: int = 16,
    dpi: float = 100.0,
    extent: tuple[Sequence[FloatArray], float] | None = None,
    suptitle_colour: str = "k",
    coarsen: bool = True,
    insets: bool | None = None,
) -> Figure:
    """Draw states as shaded Janus tubes, one 3-D panel each, on one common scale.

    Every panel is framed to what it shows: the common scale is the largest at which each
    panel's shape (with its ghost and scale bar) fits its cell, and the cells are as tall as
    the tallest shape needs (:mod:`rotomorph.plot.framing`). A shape much smaller than its cell
    (a coil beside the long ghost of its straight print) gets an inset at its own scale, in the
    corner of the cell it leaves free, with its own scale bar and magnification.

    Parameters
    ----------
    panels
        The states to draw (at least one).
    columns
        Panels per row (default: all in one row up to 4).
    panel_size
        Width of a panel (inches).
    panel_height
        Height of a panel (inches; default: what the shapes need, between 0.3 and 1.5 times
        the width).
    zoom
        Fraction of its cell the largest shape fills.
    elev, azim
        Camera angles (degrees), the same in every panel (a panel's ``view`` overrides).
    cmap, norm, label
        Colour map, limits and colour-bar label for panels with ``values``; ``norm`` is
        required when any panel has values (so that every panel shares it).
    suptitle
        Figure title.
    legend
        Draw the legend (active, passive, printed shape) below the panels.
    facets
        Facets around each segment; reduced automatically for very large networks.
    dpi
        Resolution (dots per inch) of the figure.
    extent
        ``(centres, half)``: each panel's box centre (mm) and the common half-widths (mm), to
        keep the scale and framing fixed over an animation (the whole box is framed, no insets);
        default from the panels (:func:`tube_extent`).
    suptitle_colour
        Colour of ``suptitle`` (e.g. red for a state that is not physical).
    coarsen
        Draw runs of segments shorter than the tube radius as segments about one radius long
        (:func:`coarse_panel`): the same picture, drawn several times faster.
    insets
        Magnified insets of small shapes (default: unless ``extent`` is given).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from rotomorph.plot.framing import (
        free_corner,
        inches_per_mm,
        padded,
        projected_box,
        projected_points,
    )

    if not panels:
        raise InvalidParameterError("panels", "needs at least one panel")
    if any(p.values is not None for p in panels) and norm is None:
        raise InvalidParameterError("norm", "give one colour norm shared by every panel")
    if coarsen:
        panels = [coarse_panel(p) for p in panels]
    framed = extent is None
    insets = framed if insets is None else bool(insets)
    n = len(panels)
    ncol = min(n, 4) if columns is None else max(1, min(int(columns), n))
    nrow = -(-n // ncol)
    total_segments = sum(len(np.asarray(p.edges).reshape(-1, 2)) for p in panels)
    k = int(max(6, min(facets, MAX_FACETS // max(total_segments, 1))))
    k -= k % 2
    views = [(elev, azim) if p.view is None else p.view for p in panels]
    centres, half = tube_extent(panels) if extent is None else extent
    half = np.broadcast_to(np.asarray(half, dtype=float), (3,)).copy()
    bar = _nice_length(2.0 * float(half.max()))
    bars = [_bar_origin(p, centres[i], half, framed, bar) for i, p in enumerate(panels)]

    # --- what each panel shows, where it lands in a unit 3-D axes at zoom 1 ----------------
    def shown(i: int) -> FloatArray:
        b = bars[i]
        ends = _bar_points(b, bar)
        if not framed:  # the whole box: the frame stays put over a movie
            corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * 3)).reshape(3, -1).T * half
            return np.vstack([np.asarray(centres[i]) + corners, ends])
        p = panels[i]
        return np.vstack([padded(_shown_points(p), float(np.max(p.radius))), ends])

    boxes = [projected_box(shown(i), centres[i], half, views[i]) for i in range(n)]
    hubs = [projected_points(np.asarray(centres[i])[None], centres[i], half, views[i])[0]
            for i in range(n)]  # fmt: skip
    own = [
        projected_box(padded(_shown_points(p, ghost=False), float(np.max(p.radius))),
                      centres[i], half, views[i])
        for i, p in enumerate(panels)
    ]  # fmt: skip
    fw = max(b[1] - b[0] for b in boxes)
    fh = max(b[3] - b[2] for b in boxes)

    # --- layout (inches): cells of width W, a title band, the shapes, a scale-bar label ------
    width_panel = float(panel_size)
    chars = max(12, int(width_panel * 72 / (9 * 0.55)))
    wrapped = [
        "\n".join(textwrap.fill(line, chars) for line in p.title.split("\n")) if p.title else ""
        for p in panels
    ]
    lines = max((t.count("\n") + 1 for t in wrapped if t), default=0)
    title_band = 0.08 + 0.16 * lines if lines else 0.05
    label_band = 0.2
    scale = zoom * width_panel / fw  # inches per unit fraction of the measuring axes
    if panel_height is None:
        shapes_h = min(max(scale * fh / zoom, 0.3 * width_panel), 1.5 * width_panel)
    else:
        shapes_h = max(float(panel_height) - title_band - label_band, 0.2 * width_panel)

    def inset_size(h: float) -> tuple[float, float]:
        return INSET_WIDTH * width_panel, INSET_HEIGHT * (h + label_band)

    def magnification(i: int, h: float) -> float:
        """How much larger panel i's own shape would be in an inset of a cell h tall."""
        iw, ih = inset_size(h)
        b = own[i]
        return 0.86 * min(iw / ((b[1] - b[0]) * scale), ih / ((b[3] - b[2]) * scale))

    if insets and panel_height is None and shapes_h < 0.6 * width_panel:
        taller = 0.6 * width_panel  # room for an inset, where one would magnify enough
        if any(magnification(i, taller) >= MIN_MAGNIFICATION for i in range(n)):
            shapes_h = taller
    scale = min(scale, zoom * shapes_h / fh)
    height_panel = title_band + shapes_h + label_band
    has_values = any(p.values is not None for p in panels)
    extra_w = 1.1 if has_values else 0.0
    legend_h = 0.4 if legend else 0.0
    width = ncol * width_panel + extra_w
    title_lines = (
        textwrap.wrap(suptitle, max(20, int(width * 72 / (11 * 0.55)))) if suptitle else []
    )
    suptitle = "\n".join(title_lines)
    title_h = 0.2 + 0.2 * len(title_lines) if title_lines else 0.0
    height = nrow * height_panel + legend_h + title_h
    fig = new_figure(width, height, dpi=dpi)
    colormap = None
    if has_values:
        import matplotlib

        colormap = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap

    def rect(x: float, y: float, w: float, h: float) -> tuple[float, float, float, float]:
        return (x / width, y / height, w / width, h / height)

    for i, p in enumerate(panels):
        col, row = i % ncol, i // ncol
        left = col * width_panel
        top = height - title_h - row * height_panel
        region = (
            left,
            top - title_band - shapes_h - label_band,
            left + width_panel,
            top - title_band,
        )
        # the axes square: the shapes never reach its edge (3-D drawing is clipped to it)
        side = max(width_panel, shapes_h) / zoom
        z = scale / side
        x0, x1, y0, y1 = boxes[i]
        hub = hubs[i]
        # the content's centre in the axes, from the box centre's fixed point of the zoom
        cx = hub[0] + z * (0.5 * (x0 + x1) - hub[0])
        cy = hub[1] + z * (0.5 * (y0 + y1) - hub[1])
        mid_x = 0.5 * (region[0] + region[2])
        mid_y = top - title_band - 0.5 * shapes_h
        ax: Any = fig.add_axes(rect(mid_x - side * cx, mid_y - side * cy, side, side),
                          projection="3d")  # fmt: skip
        _hold_layout(fig, ax, rect(region[0], region[1], width_panel, region[3] - region[1]))
        ax.set_label("panel")
        ax.computed_zorder = False
        _panel_box(ax, centres[i], half, z, views[i])
        _draw_panel(ax, p, k, _facet_colours(p, k, colormap, norm), views[i], (bars[i], bar))
        if wrapped[i]:
            fig.text(mid_x / width, (top - 0.04) / height, wrapped[i], ha="center", va="top",
                     fontsize=9)  # fmt: skip
        if not (insets and framed):
            continue
        # --- an inset at the shape's own scale where it is small in its cell ---------------
        if magnification(i, shapes_h) < MIN_MAGNIFICATION:
            continue
        inset = replace(p, ghost=None)
        (o_centre,), o_half = tube_extent([inset])
        o_bar = _nice_length(2.0 * float(o_half.max()))
        o_origin = _bar_origin(inset, o_centre, o_half, True, o_bar)
        pts = np.vstack([padded(_shown_points(inset), float(np.max(p.radius))),
                         _bar_points(o_origin, o_bar)])  # fmt: skip
        ob = projected_box(pts, o_centre, o_half, views[i])
        o_hub = projected_points(np.asarray(o_centre)[None], o_centre, o_half, views[i])[0]
        iw, ih = inset_size(shapes_h)
        o_scale = 0.86 * min(iw / (ob[1] - ob[0]), ih / (ob[3] - ob[2]))
        times = inches_per_mm(o_scale, 1.0, o_half) / inches_per_mm(scale, 1.0, half)
        # where the main picture leaves room: its drawn points, in inches
        # never over the shape, rather not over the scale bar, the ghost may be covered
        ruler = bars[i] + np.linspace(0.0, 1.0, 30)[:, None] * np.array([bar, 0.0, 0.0])
        ruler = np.vstack([ruler, ruler - np.array([0.0, 0.0, 0.2 * bar])])  # and its label
        body = padded(_shown_points(p, ghost=False), float(np.max(p.radius)))
        ghost_pts = np.zeros((0, 3)) if p.ghost is None else np.asarray(p.ghost, dtype=float)
        marks = np.vstack([body, ruler, ghost_pts])
        weight = np.r_[np.full(len(body), 1e3), np.full(len(ruler), 30.0), np.ones(len(ghost_pts))]
        f = projected_points(marks, centres[i], half, views[i])
        drawn = np.c_[
            mid_x - side * cx + side * (hub[0] + z * (f[:, 0] - hub[0])),
            mid_y - side * cy + side * (hub[1] + z * (f[:, 1] - hub[1])),
        ]
        ix, iy = free_corner(drawn, region, (iw, ih), weight)
        o_side = max(iw, ih) / 0.9
        o_z = o_scale / o_side
        ocx = o_hub[0] + o_z * (0.5 * (ob[0] + ob[1]) - o_hub[0])
        ocy = o_hub[1] + o_z * (0.5 * (ob[2] + ob[3]) - o_hub[1])
        frame = fig.add_axes(rect(ix, iy, iw, ih), label="inset frame")
        frame.set_xticks([])
        frame.set_yticks([])
        for spine in frame.spines.values():
            spine.set_color("0.7")
        frame.text(0.03, 0.97, f"×{times:.2g}", transform=frame.transAxes, ha="left",
                   va="top", fontsize=8, color="0.3")  # fmt: skip
        oax: Any = fig.add_axes(rect(ix + 0.5 * iw - o_side * ocx, iy + 0.5 * ih - o_side * ocy,
                                o_side, o_side), projection="3d")  # fmt: skip
        _hold_layout(fig, oax, rect(ix, iy, iw, ih))
        oax.set_label("inset")
        oax.computed_zorder = False
        _panel_box(oax, o_centre, o_half, o_z, views[i])
        _draw_panel(oax, inset, k, _facet_colours(inset, k, colormap, norm), views[i],
                    (o_origin, o_bar), ghost=False)  # fmt: skip
    if has_values and norm is not None and colormap is not None:
        from matplotlib.cm import ScalarMappable

        bottom = legend_h
        cax = fig.add_axes(rect(ncol * width_panel + 0.12 * extra_w, bottom + 0.15 *
                                (height - title_h - bottom), 0.16 * extra_w,
                                0.7 * (height - title_h - bottom)))  # fmt: skip
        shown_values = [np.asarray(p.values, dtype=float) for p in panels if p.values is not None]
        extend = colourbar_extend(norm, np.concatenate(shown_values))
        fig.colorbar(
            ScalarMappable(norm=norm, cmap=colormap),
            cax=cax,
            label=label,
            extend=extend,
            ticks=colourbar_ticks(norm),
        )
    if legend:
        handles: list[Any] = []
        if any(p.values is None and p.normals is not None for p in panels):
            handles += [
                Patch(color=ACTIVE_COLOUR, label="active half (LCE)"),
                Patch(color=PASSIVE_COLOUR, label="passive half"),
            ]
        if any(p.values is None and p.normals is None for p in panels):
            handles.append(Patch(color=UNKNOWN_COLOUR, label="sides not stored"))
        if any(p.ghost is not None for p in panels):
            from matplotlib.lines import Line2D

            handles.append(Line2D([], [], color="0.62", lw=1.2, label="printed shape"))
        if handles:
            fig.legend(
                handles=handles,
                loc="lower center",
                ncol=len(handles),
                frameon=False,
                fontsize=9,
                bbox_to_anchor=(0.5, 0.0),
            )
    if suptitle:
        fig.suptitle(suptitle, fontsize=11, color=suptitle_colour, y=1.0 - 0.08 / height)
    return fig

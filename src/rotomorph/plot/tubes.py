"""Filaments drawn as shaded tubes with their active and passive halves in two colours.

A segment of a printed Janus filament is a cylinder of radius R split by the interface: the
half on the side of the interface normal n (toward the active ink) is active. :func:`tube_mesh`
turns a network's segments into quadrilateral facets (``facets`` around each segment, mitred at
ordinary nodes, where neighbouring segments share their end rings: no gaps, no seams) and tells,
per facet, whether it lies on the active side. With an active area fraction f ≠ ½ the interface
is a chord at distance d from the axis, :math:`f = (θ - \\sin θ)/2π` with
:math:`θ = 2\\arccos(d/R)`; a facet is active when its outward direction u satisfies
:math:`u·n > d/R`.

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

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.coarsen import coarsen_network
from rotomorph.plot.figure import new_figure

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
#: Above this many facets a picture falls back to coarser tubes (matplotlib draws each one).
MAX_FACETS = 120_000


def interface_offset(active_fraction: float) -> float:
    """Distance d/R of the interface chord from the axis for an active area fraction f.

    Solves :math:`f = (θ - \\sin θ)/2π`, :math:`θ = 2\\arccos(d/R)` by bisection; f = ½ → 0,
    f → 0 → 1, f → 1 → −1.
    """
    f = float(active_fraction)
    if not 0.0 <= f <= 1.0:
        raise InvalidParameterError("active_fraction", f"must lie in [0, 1]; got {f}")
    lo, hi = -1.0, 1.0  # d/R; the segment beyond d shrinks as d grows
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        theta = 2.0 * np.arccos(mid)
        if (theta - np.sin(theta)) / (2.0 * np.pi) > f:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("ij,ij->i", a, b)


def _dot3(a: FloatArray, b: FloatArray) -> FloatArray:
    """Dot product over the last axis, broadcasting."""
    return np.sum(a * b, axis=-1)


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _any_perpendicular(t: FloatArray) -> FloatArray:
    helper = np.where(np.abs(t[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    return _unit(np.cross(t, helper))


def _end_frames(
    pos: FloatArray, edges: IntArray, t: FloatArray, ref: FloatArray, radius: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Plane normal and reference direction of each segment's two end rings ``(E, 2, 3)``.

    At an ordinary node (two segments, no hairpin) both segments' rings lie in the bisector
    plane (a mitre) and, where their reference directions agree (``ref`` within 90°), share
    the mean of the two, so the rings coincide and the tube has no seam; elsewhere each end
    has its segment's own tangent and reference direction. A turn so sharp that the mitre
    would fold the tube onto itself (``radius · tan(θ/2)`` beyond half the shorter segment,
    e.g. a lattice's corner) keeps both segments' own rings as well.
    """
    lengths = np.linalg.norm(pos[edges[:, 1]] - pos[edges[:, 0]], axis=1)
    n = len(pos)
    incident: list[list[int]] = [[] for _ in range(n)]
    for j, (a, b) in enumerate(edges):
        incident[a].append(j)
        incident[b].append(j)
    out = np.repeat(t[:, None, :], 2, axis=1)
    refs = np.repeat(ref[:, None, :], 2, axis=1)
    for node, inc in enumerate(incident):
        if len(inc) != 2:
            continue
        e, f = inc
        # orient both tangents along the walk e -> node -> f
        te = t[e] if edges[e, 1] == node else -t[e]
        tf = t[f] if edges[f, 0] == node else -t[f]
        if float(te @ tf) < -0.5:  # a hairpin: a mitre would be degenerate
            continue
        half_turn = float(np.linalg.norm(np.cross(te, tf))) / (1.0 + float(te @ tf))
        if max(radius[e], radius[f]) * half_turn > 0.5 * min(lengths[e], lengths[f]):
            continue  # the mitred rings would cross inside the bend
        mitre = _unit(te + tf)
        shared = _unit(ref[e] + ref[f]) if float(ref[e] @ ref[f]) > 0.0 else None
        for j in inc:
            end = 0 if edges[j, 0] == node else 1
            out[j, end] = mitre if float(mitre @ t[j]) >= 0 else -mitre
            if shared is not None:
                refs[j, end] = shared
    return out, refs


def tube_mesh(
    positions: FloatArray,
    edges: IntArray,
    radius: float | FloatArray,
    normals: FloatArray | None = None,
    *,
    facets: int = 16,
    active_fraction: float | FloatArray = 0.5,
) -> tuple[FloatArray, FloatArray, BoolArray | None, IntArray]:
    """Quadrilateral facets of tubes around a network's segments.

    Parameters
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    edges
        Segments ``(E, 2)``.
    radius
        Tube radius (mm), scalar or per segment ``(E,)``.
    normals
        Interface normal toward the active half per segment ``(E, 3)`` (unit; need not be
        exactly perpendicular to the segment), or ``None`` when the sides are unknown.
    facets
        Facets around each segment (>= 3; even numbers split a symmetric section exactly).
    active_fraction
        Active area fraction of the section, scalar or per segment.

    Returns
    -------
    quads
        ``(E·facets, 4, 3)`` facet corners (mm).
    face_normals
        ``(E·facets, 3)`` outward unit normals.
    active
        ``(E·facets,)`` True on the active side (``None`` without ``normals``).
    segment
        ``(E·facets,)`` index of each facet's segment.
    """
    pos = np.asarray(positions, dtype=float)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if int(facets) != facets or facets < 3:
        raise InvalidParameterError("facets", f"must be an integer >= 3; got {facets}")
    k = int(facets)
    m = len(e)
    r = np.broadcast_to(np.asarray(radius, dtype=float), (m,))
    if not np.all(np.isfinite(r) & (r > 0)):
        raise InvalidParameterError("radius", "must be finite and > 0 mm")
    a, b = pos[e[:, 0]], pos[e[:, 1]]
    t = _unit(b - a)
    ref = _any_perpendicular(t) if normals is None else np.asarray(normals, dtype=float)
    if ref.shape != (m, 3):
        raise InvalidParameterError("normals", f"must have shape ({m}, 3); got {ref.shape}")
    ends, refs = _end_frames(pos, e, t, ref, r)
    centres = np.stack([a, b], axis=1)  # (E, 2, 3)
    u = refs - np.einsum("eij,eij->ei", ends, refs)[..., None] * ends
    bad = np.linalg.norm(u, axis=-1) < 1e-9  # normal along the tangent: any perpendicular
    if bad.any():
        fallback = np.repeat(_any_perpendicular(t)[:, None, :], 2, axis=1)
        u = np.where(bad[..., None], fallback, u)
    u = _unit(u)
    # the circle of radius r about the segment's own axis (from the end plane's reference
    # direction, itself in the end plane), carried along the axis into the end plane: at a
    # mitre both neighbours' cylinders meet the plane in one ellipse, point for point
    tt = t[:, None, :]
    u = _unit(u - _dot3(u, tt)[..., None] * tt)
    v = np.cross(np.broadcast_to(tt, u.shape), u)
    phi = 2.0 * np.pi * np.arange(k + 1) / k
    c, s = np.cos(phi), np.sin(phi)
    around = r[:, None, None, None] * (
        c[None, None, :, None] * u[:, :, None, :] + s[None, None, :, None] * v[:, :, None, :]
    )  # (E, 2, k+1, 3)
    lift = _dot3(around, ends[:, :, None, :]) / _dot3(tt, ends)[:, :, None]
    rings = centres[:, :, None, :] + around - lift[..., None] * tt[:, :, None, :]
    # an end ring that shares its angular origin with the neighbour beyond it (a mitre) starts
    # up to 45° away from this segment's own reference direction: number both rings from the
    # point nearest to that direction, so facet i lies within half a facet of angle 2π(i+½)/k
    # from it at both ends (no facet twisted by more than a facet; the Janus sides by index)
    own = _unit(ref - _dot(ref, t)[:, None] * t)
    own = np.where((np.linalg.norm(own, axis=1) < 1e-9)[:, None], _any_perpendicular(t), own)
    for end in (0, 1):
        off = np.arctan2(_dot(np.cross(own, u[:, end]), t), _dot(own, u[:, end]))
        shift = np.rint(off * k / (2.0 * np.pi)).astype(np.int64)
        if shift.any():
            index = (np.arange(k)[None, :] - shift[:, None]) % k
            ring = np.take_along_axis(rings[:, end, :k], index[:, :, None], axis=1)
            rings[:, end] = np.concatenate([ring, ring[:, :1]], axis=1)
    quads = quad_corners(rings)
    segment = np.repeat(np.arange(m), k)
    # shading: each facet's outward direction from where it is drawn (its centre seen from the
    # axis, in the segment's cross-section)
    ts = t[segment]
    out = quads.mean(axis=1) - 0.5 * (a + b)[segment]
    face_normals = _unit(out - np.einsum("ij,ij->i", out, ts)[:, None] * ts)
    active = None
    if normals is not None:
        frac = np.broadcast_to(np.asarray(active_fraction, dtype=float), (m,))
        offsets = {f: interface_offset(f) for f in np.unique(frac)}
        d = np.array([offsets[f] for f in frac])
        mid_phi = 2.0 * np.pi * (np.arange(k) + 0.5) / k
        active = np.tile(np.cos(mid_phi), m) > d[segment]
    return quads, face_normals, active, segment


def quad_corners(rings: FloatArray) -> FloatArray:
    """Facet corners ``(E·k, 4, 3)`` from end rings ``(E, 2, k+1, 3)`` (last = first point)."""
    m, k = rings.shape[0], rings.shape[2] - 1
    return np.stack(
        [rings[:, 0, :-1], rings[:, 0, 1:], rings[:, 1, 1:], rings[:, 1, :-1]], axis=2
    ).reshape(m * k, 4, 3)


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
    half = _unit(light + eye)
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


def plot_tube_panels(
    panels: Sequence[TubePanel],
    *,
    columns: int | None = None,
    panel_size: float = 3.6,
    panel_height: float | None = None,
    zoom: float = 0.94,
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
) -> Figure:
    """Draw states as shaded Janus tubes, one 3-D panel each, on one common scale.

    Parameters
    ----------
    panels
        The states to draw (at least one).
    columns
        Panels per row (default: all in one row up to 4).
    panel_size
        Width of a panel (inches).
    panel_height
        Height of a panel (inches; default ``panel_size``): less for flat or long shapes.
    zoom
        Size of the 3-D box in its panel (matplotlib's ``set_box_aspect`` zoom; what reaches
        beyond the panel is cut off).
    elev, azim
        Camera angles (degrees), the same in every panel.
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
        keep the scale fixed over an animation; default from the panels (:func:`tube_extent`).
    suptitle_colour
        Colour of ``suptitle`` (e.g. red for a state that is not physical).
    coarsen
        Draw runs of segments shorter than the tube radius as segments about one radius long
        (:func:`coarse_panel`): the same picture, drawn several times faster.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not panels:
        raise InvalidParameterError("panels", "needs at least one panel")
    if any(p.values is not None for p in panels) and norm is None:
        raise InvalidParameterError("norm", "give one colour norm shared by every panel")
    if coarsen:
        panels = [coarse_panel(p) for p in panels]
    n = len(panels)
    ncol = min(n, 4) if columns is None else max(1, min(int(columns), n))
    nrow = -(-n // ncol)
    total_segments = sum(len(np.asarray(p.edges).reshape(-1, 2)) for p in panels)
    k = int(max(6, min(facets, MAX_FACETS // max(total_segments, 1))))
    k -= k % 2
    has_values = any(p.values is not None for p in panels)
    extra_w = 0.9 if has_values else 0.0
    legend_h = 0.5 if legend else 0.0
    width = ncol * panel_size + extra_w
    # wrap the title to the figure (11 pt characters are about 0.55 em wide)
    title_lines = (
        textwrap.wrap(suptitle, max(20, int(width * 72 / (11 * 0.55)))) if suptitle else []
    )
    suptitle = "\n".join(title_lines)
    title_h = 0.25 + 0.22 * len(title_lines) if title_lines else 0.0
    centres, half = tube_extent(panels) if extent is None else extent
    half = np.broadcast_to(np.asarray(half, dtype=float), (3,))
    height = panel_size if panel_height is None else float(panel_height)
    fig = new_figure(width, nrow * height + legend_h + title_h, dpi=dpi)
    eye, light = _view_vectors(elev, azim)
    colormap = None
    if has_values:
        import matplotlib

        colormap = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    bottom = legend_h / fig.get_figheight()
    top = 1.0 - title_h / fig.get_figheight()
    right = 1.0 - extra_w / fig.get_figwidth()
    gs = fig.add_gridspec(
        nrow, ncol, left=0.0, right=right, bottom=bottom, top=top, wspace=0.0, hspace=0.08
    )
    bar = _nice_length(2.0 * float(half.max()))
    for i, p in enumerate(panels):
        ax = fig.add_subplot(gs[i // ncol, i % ncol], projection="3d")
        ax.computed_zorder = False
        c = centres[i]
        pos = np.asarray(p.positions, dtype=float)
        edges = np.asarray(p.edges, dtype=np.int64).reshape(-1, 2)
        if p.ghost is not None:
            g = np.asarray(p.ghost, dtype=float)
            ghost = Line3DCollection(g[edges], colors="0.62", linewidths=1.2, alpha=0.7, zorder=1)
            ax.add_collection3d(ghost)
        quads, fn, active, seg = tube_mesh(
            pos, edges, p.radius, p.normals, facets=k, active_fraction=p.active_fraction
        )
        if p.values is not None and colormap is not None and norm is not None:
            vals = np.asarray(p.values, dtype=float)[seg]
            base = np.asarray(colormap(norm(np.ma.masked_invalid(vals))))[:, :3]
            base[~np.isfinite(vals)] = to_rgb(UNKNOWN_COLOUR)
        elif active is None:
            base = np.tile(to_rgb(UNKNOWN_COLOUR), (len(quads), 1))
        else:
            base = np.where(active[:, None], to_rgb(ACTIVE_COLOUR), to_rgb(PASSIVE_COLOUR))
        pe, pa = (elev, azim) if p.view is None else p.view
        rgb = shade(base, fn, *(_view_vectors(pe, pa) if p.view is not None else (eye, light)))
        # edges in the face colour hide the hairline seams anti-aliasing leaves between facets
        poly = Poly3DCollection(quads, facecolors=rgb, edgecolors=rgb, linewidths=0.2, zorder=2)
        ax.add_collection3d(poly)
        ax.set_xlim(c[0] - half[0], c[0] + half[0])
        ax.set_ylim(c[1] - half[1], c[1] + half[1])
        ax.set_zlim(c[2] - half[2], c[2] + half[2])
        ax.set_box_aspect(tuple(half), zoom=zoom)
        ax.view_init(elev=pe, azim=pa)
        ax.set_axis_off()
        # scale bar along x at the bottom front of the box
        x0 = c[0] - half[0] * 0.95
        y0, z0 = c[1] - half[1], c[2] - half[2]
        ax.plot([x0, x0 + bar], [y0, y0], [z0, z0], color="k", lw=2.0, zorder=3)
        ax.text(
            x0 + bar / 2,
            y0,
            z0 - 0.06 * float(half.max()),
            f"{bar:g} mm",
            ha="center",
            va="top",
            fontsize=8,
            zorder=3,
        )
        if p.title:  # inside the panel, wrapped to its width: never over a neighbour
            chars = max(12, int(panel_size * 72 / (9 * 0.55)))
            text = "\n".join(textwrap.fill(line, chars) for line in p.title.split("\n"))
            ax.text2D(0.5, 0.99, text, transform=ax.transAxes, ha="center", va="top", fontsize=9)
    if has_values and norm is not None and colormap is not None:
        from matplotlib.cm import ScalarMappable

        cax = fig.add_axes(
            (
                right + 0.15 * extra_w / fig.get_figwidth(),
                bottom + 0.15,
                0.18 * extra_w / fig.get_figwidth(),
                (top - bottom) * 0.7,
            )
        )
        fig.colorbar(ScalarMappable(norm=norm, cmap=colormap), cax=cax, label=label)
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
        fig.suptitle(
            suptitle, fontsize=11, color=suptitle_colour, y=1.0 - 0.08 / fig.get_figheight()
        )
    return fig

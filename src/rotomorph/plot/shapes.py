"""Views of filaments and networks: 3-D with equal aspect, lattice top/side views.

Segments are coloured by a per-vertex scalar (e.g. the relative curvature change
:math:`(κ - κ_i)/κ_i` of paper Fig. 4): each segment takes the mean of its two end values,
ignoring NaN; a segment with no finite value is drawn in grey.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.colors import Colormap, Normalize, TwoSlopeNorm
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import new_figure

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d.axes3d import Axes3D

__all__ = [
    "RELATIVE_CHANGE_LABEL",
    "colourbar_extend",
    "colourbar_ticks",
    "plot_lattice_views",
    "plot_network_3d",
    "relative_change_norm",
    "scalar_colormap",
    "scalar_norm",
    "segment_values",
    "set_equal_3d",
]

_GREY = (0.6, 0.6, 0.6, 1.0)

#: Colour-bar label of the relative curvature change, every symbol defined on the figure.
RELATIVE_CHANGE_LABEL = "(κ − κᵢ)/κᵢ\nκ: curvature, κᵢ: curvature as printed"


def _check(positions: object, edges: object) -> tuple[FloatArray, IntArray]:
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 3 or len(pos) == 0:
        raise InvalidParameterError(
            "positions", f"must have shape (N, 3) in mm with N >= 1; got {pos.shape}"
        )
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        raise InvalidParameterError("edges", "needs at least one segment to draw")
    if e.min() < 0 or e.max() >= len(pos):
        raise InvalidParameterError("edges", f"indices must lie in [0, {len(pos) - 1}]")
    return pos, e


def segment_values(values: FloatArray, edges: IntArray) -> FloatArray:
    """Per-segment mean of per-vertex ``values`` ``(N,)``, ignoring NaN (NaN if both are)."""
    v = np.asarray(values, dtype=float)[np.asarray(edges)]
    finite = np.isfinite(v)
    count = finite.sum(axis=1)
    total = np.where(finite, v, 0.0).sum(axis=1)
    out = np.full(len(v), np.nan)
    out[count > 0] = total[count > 0] / count[count > 0]
    return out


def scalar_colormap(cmap: str | Colormap) -> Colormap:
    """``cmap`` (a name or a colour map) with NaN drawn in grey."""
    base = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    return base.with_extremes(bad=_GREY)


def scalar_norm(
    values: FloatArray,
    vmin: float | None = None,
    vmax: float | None = None,
    *,
    floor: float = 1e-3,
) -> Normalize:
    """Colour limits for ``values``: the given ones, else robust automatic limits.

    Automatic limits span the 2nd to 98th percentile of the finite values (relative curvature
    changes blow up near inflection points, where κ_i → 0, and would wash out the rest), made
    symmetric about 0 when the values take both signs. Values beyond are clipped. Automatic
    limits never come closer to 0 than ``floor`` (in the values' unit): a field that is zero
    up to round-off (e.g. ±1e-7 on the flat printed lattice) is drawn in the colour map's
    centre instead of being stretched into a red–blue pattern of noise.
    """
    finite = values[np.isfinite(values)]
    if vmin is None or vmax is None:
        if len(finite) == 0:
            lo, hi = -1.0, 1.0
        else:
            lo, hi = (float(q) for q in np.percentile(finite, [2.0, 98.0]))
            if lo < 0 < hi:
                lo, hi = -max(-lo, hi), max(-lo, hi)  # symmetric about zero
            if max(abs(lo), abs(hi)) < floor:
                lo, hi = -floor, floor
        vmin = lo if vmin is None else vmin
        vmax = hi if vmax is None else vmax
    if vmax <= vmin:
        vmax = vmin + 1.0
    return Normalize(vmin=vmin, vmax=vmax)


def relative_change_norm(
    values: FloatArray, printed: FloatArray, *, floor: float = 1e-3, share: float = 0.25
) -> Normalize:
    """Colour limits for the relative curvature change (κ − κᵢ)/κᵢ (paper Fig. 4).

    The ratio grows without bound where the printed curvature κᵢ vanishes (a sinusoid's
    inflection points), so the limits are set by the values where the filament was printed
    clearly curved: κᵢ at least ``share`` times its median. They span the 2nd to 98th
    percentile of those values, each sign on its own half of the colour map (the ratio is
    never below −1, while it may reach +5: a symmetric scale would spend half its colours on
    values that do not occur); the rest is clipped (the colour bar's arrows,
    :func:`colourbar_extend`).

    Parameters
    ----------
    values
        Relative curvature changes (per segment or per node), NaN where undefined.
    printed
        κᵢ (1/mm) at the same places.
    floor
        Limits never come closer to 0 than this (a flat printed state is neutral, not noise).
    share
        Fraction of the median κᵢ below which a value does not set the limits.
    """
    v = np.asarray(values, dtype=float)
    k = np.asarray(printed, dtype=float)
    good = np.isfinite(v) & np.isfinite(k)
    if good.any():
        good &= k >= share * float(np.median(k[good]))
    pick = v[good] if good.any() else v[np.isfinite(v)]
    if len(pick) == 0:
        return Normalize(-floor, floor)
    lo, hi = (float(q) for q in np.percentile(pick, [2.0, 98.0]))
    lo, hi = min(lo, -floor), max(hi, floor)
    return TwoSlopeNorm(vcenter=0.0, vmin=lo, vmax=hi)


def colourbar_ticks(norm: Normalize) -> list[float] | None:
    """Round ticks on both halves of a two-slope colour bar (matplotlib's own would leave the
    shorter half bare); ``None`` (matplotlib's choice) for a linear one."""
    if not isinstance(norm, TwoSlopeNorm) or norm.vmin is None or norm.vmax is None:
        return None
    from matplotlib.ticker import MaxNLocator

    locate = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10])
    low = [t for t in locate.tick_values(norm.vmin, 0.0) if norm.vmin <= t < 0.0]
    high = [t for t in locate.tick_values(0.0, norm.vmax) if 0.0 < t <= norm.vmax]
    return [*low, 0.0, *high]


def colourbar_extend(norm: Normalize, values: FloatArray) -> str:
    """``"neither"``, ``"min"``, ``"max"`` or ``"both"``: which ends of a colour bar ``values``
    pass (clipped values get an arrow)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    low = bool(len(v) and norm.vmin is not None and v.min() < norm.vmin)
    high = bool(len(v) and norm.vmax is not None and v.max() > norm.vmax)
    return {(False, False): "neither", (True, False): "min", (False, True): "max"}.get(
        (low, high), "both"
    )


def _style(collection, values, edges, n_nodes, cmap, vmin, vmax, color, norm=None):
    if values is None:
        collection.set_color(color)
        return None
    v = np.asarray(values, dtype=float)
    if v.shape != (n_nodes,):
        raise InvalidParameterError("values", f"must have shape ({n_nodes},); got {v.shape}")
    seg = segment_values(v, edges)
    collection.set_array(np.ma.masked_invalid(seg))
    collection.set_cmap(scalar_colormap(cmap))
    collection.set_norm(scalar_norm(seg, vmin, vmax) if norm is None else norm)
    return collection


def set_equal_3d(ax: Axes3D, positions: FloatArray, *, min_fraction: float = 0.02) -> None:
    """Give a 3-D axes equal scale on x, y, z around ``positions`` (mm), with a tight box.

    Axes with (nearly) no extent get ``min_fraction`` of the largest extent so that flat
    lattices stay visible.
    """
    lo, hi = positions.min(axis=0), positions.max(axis=0)
    span = hi - lo
    biggest = float(span.max()) or 1.0
    span = np.maximum(span, min_fraction * biggest)
    mid = 0.5 * (lo + hi)
    ax.set_xlim(mid[0] - span[0] / 2, mid[0] + span[0] / 2)
    ax.set_ylim(mid[1] - span[1] / 2, mid[1] + span[1] / 2)
    ax.set_zlim(mid[2] - span[2] / 2, mid[2] + span[2] / 2)
    ax.set_box_aspect(tuple(span))


def plot_network_3d(
    positions: FloatArray,
    edges: IntArray,
    values: FloatArray | None = None,
    *,
    cmap: str = "coolwarm",
    vmin: float | None = None,
    vmax: float | None = None,
    label: str = "",
    title: str = "",
    elev: float = 25.0,
    azim: float = -60.0,
    linewidth: float = 1.5,
    color: str = "k",
) -> Figure:
    """3-D view of a filament or network, equal aspect, optionally coloured by a scalar.

    Parameters
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    edges
        Segments ``(E, 2)``; for a filament ``Network.chain(points).edges``.
    values
        Per-vertex scalar ``(N,)`` (e.g. :func:`~rotomorph.analysis.curvature.
        network_relative_curvature_change`); NaN allowed. ``None`` draws in ``color``.
    cmap, vmin, vmax
        Colour map and limits; by default symmetric about 0 for signed data.
    label
        Colour bar label (e.g. ``"(κ − κ_i)/κ_i"``).
    title
        Axes title.
    elev, azim
        Viewing angles (degrees).
    linewidth
        Line width (points).
    color
        Line colour without ``values``.
    """
    pos, e = _check(positions, edges)
    fig = new_figure(6.4, 5.2)
    ax = fig.add_subplot(projection="3d")
    coll = Line3DCollection(pos[e], linewidths=linewidth)
    mappable = _style(coll, values, e, len(pos), cmap, vmin, vmax, color)
    ax.add_collection3d(coll)
    set_equal_3d(ax, pos)
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    if title:
        ax.set_title(title)
    if mappable is not None:
        fig.colorbar(mappable, ax=ax, shrink=0.7, label=label)
    return fig


def plot_lattice_views(
    positions: FloatArray,
    edges: IntArray,
    values: FloatArray | None = None,
    *,
    cmap: str = "coolwarm",
    vmin: float | None = None,
    vmax: float | None = None,
    label: str = "",
    title: str = "",
    linewidth: float = 1.2,
    color: str = "k",
    norm: Normalize | None = None,
) -> Figure:
    """Top (x–y) and side (x–z) views of a lattice at one scale (paper Fig. 4A/D).

    Parameters are those of :func:`plot_network_3d`; ``norm`` (e.g.
    :func:`relative_change_norm`) replaces ``vmin``/``vmax``.
    """
    pos, e = _check(positions, edges)
    # the side view under the top view, both at one scale and sharing x (as a drawing's
    # projections), each as tall as the lattice is along its axis: no empty bands
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    pad = 0.04 * float((hi - lo)[:2].max() or 1.0)
    lo, hi = lo - pad, hi + pad
    span = np.maximum(hi - lo, 0.06 * float((hi - lo).max()))
    mid = 0.5 * (lo + hi)
    lo, hi = mid - 0.5 * span, mid + 0.5 * span
    axes_w = 5.2
    h_top, h_side = axes_w * span[1] / span[0], max(axes_w * span[2] / span[0], 0.45)
    fig = new_figure(axes_w + 2.4, h_top + h_side + 1.5)
    top, side = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [h_top, h_side]})
    mappable = None
    for ax, (i, j), name in ((top, (0, 1), "top"), (side, (0, 2), "side")):
        # an (E, 2, 2) array is a valid segment list; the stubs only accept a Sequence
        coll = LineCollection(pos[e][:, :, [i, j]], linewidths=linewidth)  # type: ignore[arg-type]
        mappable = _style(coll, values, e, len(pos), cmap, vmin, vmax, color, norm)
        ax.add_collection(coll)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[j], hi[j])
        ax.set_aspect("equal", adjustable="box")
        ax.set_ylabel("y (mm)" if name == "top" else "z (mm)")
        ax.set_title(f"{name} view", fontsize=10, loc="left")
    side.set_xlabel("x (mm)")
    fig.set_layout_engine("constrained")
    if title:
        fig.suptitle(title)
    if mappable is not None:
        extend = colourbar_extend(mappable.norm, mappable.get_array())
        fig.colorbar(
            mappable, ax=[top, side], shrink=0.8, label=label, extend=extend,
            ticks=colourbar_ticks(mappable.norm),
        )  # fmt: skip
    return fig

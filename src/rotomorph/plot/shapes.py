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
from matplotlib.colors import Colormap, Normalize
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import new_figure

if TYPE_CHECKING:
    from mpl_toolkits.mplot3d.axes3d import Axes3D

__all__ = [
    "plot_lattice_views",
    "plot_network_3d",
    "scalar_colormap",
    "scalar_norm",
    "segment_values",
    "set_equal_3d",
]

_GREY = (0.6, 0.6, 0.6, 1.0)


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


def _style(collection, values, edges, n_nodes, cmap, vmin, vmax, color):
    if values is None:
        collection.set_color(color)
        return None
    v = np.asarray(values, dtype=float)
    if v.shape != (n_nodes,):
        raise InvalidParameterError("values", f"must have shape ({n_nodes},); got {v.shape}")
    seg = segment_values(v, edges)
    collection.set_array(np.ma.masked_invalid(seg))
    collection.set_cmap(scalar_colormap(cmap))
    collection.set_norm(scalar_norm(seg, vmin, vmax))
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
) -> Figure:
    """Top (x–y) and side (x–z) views of a lattice at equal scale (paper Fig. 4A/D).

    Parameters are those of :func:`plot_network_3d`.
    """
    pos, e = _check(positions, edges)
    fig = new_figure(10.0, 4.6)
    top, side = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.4]})
    mappable = None
    for ax, (i, j), name in ((top, (0, 1), "top"), (side, (0, 2), "side")):
        # an (E, 2, 2) array is a valid segment list; the stubs only accept a Sequence
        coll = LineCollection(pos[e][:, :, [i, j]], linewidths=linewidth)  # type: ignore[arg-type]
        mappable = _style(coll, values, e, len(pos), cmap, vmin, vmax, color)
        ax.add_collection(coll)
        ax.autoscale_view()
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)" if name == "top" else "z (mm)")
        ax.set_title(f"{name} view")
    if title:
        fig.suptitle(title)
    if mappable is not None:
        fig.colorbar(mappable, ax=[top, side], shrink=0.8, label=label)
    return fig

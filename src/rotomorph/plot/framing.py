"""Framing 3-D panels to what they show: where points land in a 3-D axes, before drawing.

matplotlib fits a 3-D axes' box into the axes' square: what a panel shows of a flat lattice or a
long, thin filament is a small band of it, and a coil 5 mm tall in a box sized for a 30 mm
ghost is a speck. :func:`projected_box` measures, once per panel, where given 3-D points land
(as fractions of a square 3-D axes at zoom 1, for a box and a camera); the figure is then laid
out so the content fills its cell at one common scale (:func:`plot_tube_panels
<rotomorph.plot.tubes.plot_tube_panels>`). Those fractions scale with the box zoom about the
axes' centre and with the square's side, so one measurement serves any panel size.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from mpl_toolkits.mplot3d import proj3d

from rotomorph._typing import FloatArray
from rotomorph.plot.figure import new_figure

__all__ = ["free_corner", "inches_per_mm", "padded", "projected_box", "projected_points"]


def padded(points: FloatArray, radius: float) -> FloatArray:
    """``points`` ``(n, 3)`` and their six offsets by ``radius`` along ±x, ±y, ±z (mm): what a
    tube of that radius around them reaches."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(p) > 4000:  # the outline is what matters: every k-th point is enough
        p = p[:: len(p) // 4000 + 1]
    offsets = np.vstack([np.zeros(3), np.eye(3) * radius, -np.eye(3) * radius])
    return (p[None, :, :] + offsets[:, None, :]).reshape(-1, 3)


def projected_points(
    points: FloatArray,
    centre: FloatArray,
    half: FloatArray,
    view: tuple[float, float],
) -> FloatArray:
    """Where ``points`` (mm) land in a square 3-D axes at zoom 1: ``(n, 2)`` fractions of its
    width and height (0..1 inside), for the box ``centre ± half`` (mm) drawn with the aspect of
    ``half`` and the camera ``view = (elev, azim)`` (degrees)."""
    fig = new_figure(1.0, 1.0)
    ax: Any = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    c = np.asarray(centre, dtype=float)
    h = np.asarray(half, dtype=float)
    ax.set_xlim(c[0] - h[0], c[0] + h[0])
    ax.set_ylim(c[1] - h[1], c[1] + h[1])
    ax.set_zlim(c[2] - h[2], c[2] + h[2])
    ax.set_box_aspect(tuple(h), zoom=1.0)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()
    fig.canvas.draw()  # an empty axes: cheap, and it fixes the 2-D transform
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    x, y, _ = proj3d.proj_transform(p[:, 0], p[:, 1], p[:, 2], ax.get_proj())
    disp = ax.transData.transform(np.c_[x, y])
    box = ax.bbox
    return np.c_[(disp[:, 0] - box.x0) / box.width, (disp[:, 1] - box.y0) / box.height]


def projected_box(
    points: FloatArray, centre: FloatArray, half: FloatArray, view: tuple[float, float]
) -> FloatArray:
    """``(x0, x1, y0, y1)``: the bounding box of :func:`projected_points`."""
    f = projected_points(points, centre, half, view)
    return np.array([f[:, 0].min(), f[:, 0].max(), f[:, 1].min(), f[:, 1].max()])


def inches_per_mm(size: float, zoom: float, half: FloatArray) -> float:
    """Relative drawing scale of a 3-D axes of side ``size`` (in), box zoom ``zoom`` and box
    half-widths ``half`` (mm): matplotlib normalises the box by the length of its aspect
    vector, so lengths on screen go as ``size · zoom / |half|`` (the constant cancels in any
    ratio of two panels, e.g. an inset's magnification)."""
    return float(size * zoom / np.linalg.norm(np.asarray(half, dtype=float)))


def free_corner(
    points: FloatArray,
    region: tuple[float, float, float, float],
    size: tuple[float, float],
    weights: FloatArray | None = None,
) -> tuple[float, float]:
    """Lower-left corner of the ``size = (w, h)`` rectangle in one of the four corners of
    ``region = (x0, y0, x1, y1)`` that covers the least of ``points`` ``(n, 2)`` (same units),
    each counted with its weight (default 1); ties go to the upper right, then upper left,
    lower right, lower left."""
    x0, y0, x1, y1 = region
    w, h = size
    corners: Sequence[tuple[float, float]] = (
        (x1 - w, y1 - h),
        (x0, y1 - h),
        (x1 - w, y0),
        (x0, y0),
    )
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    wt = np.ones(len(p)) if weights is None else np.asarray(weights, dtype=float)

    def covered(c: tuple[float, float]) -> float:
        in_x = (p[:, 0] >= c[0]) & (p[:, 0] <= c[0] + w)
        return float(np.sum(wt[in_x & (p[:, 1] >= c[1]) & (p[:, 1] <= c[1] + h)]))

    return min(corners, key=covered)

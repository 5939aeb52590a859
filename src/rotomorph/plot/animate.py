"""Animations of the morphing: one frame per actuation step, written as a GIF through Pillow."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.collections import LineCollection
from mpl_toolkits.mplot3d.art3d import Line3DCollection
from PIL import Image

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path
from rotomorph.plot.figure import figure_to_rgb, new_figure
from rotomorph.plot.shapes import scalar_colormap, scalar_norm, segment_values, set_equal_3d

__all__ = ["animate_gif"]


def animate_gif(
    frames_positions: FloatArray,
    edges: IntArray,
    path: str | os.PathLike[str],
    *,
    values: FloatArray | None = None,
    labels: Sequence[str] | None = None,
    view: str = "3d",
    fps: float = 8.0,
    cmap: str = "coolwarm",
    size: tuple[float, float] = (5.0, 4.0),
    dpi: float = 80.0,
    elev: float = 25.0,
    azim: float = -60.0,
) -> Path:
    """Write a looping GIF of a network morphing through its actuation steps (atomically).

    Parameters
    ----------
    frames_positions
        ``(S, N, 3)`` node positions per step (mm); one frame each.
    edges
        Segments ``(E, 2)``.
    path
        Destination ``.gif``; its folder must exist.
    values
        Optional per-step per-vertex scalars ``(S, N)`` colouring the segments; one colour scale
        for the whole animation.
    labels
        Optional per-frame titles ``(S,)`` (e.g. ``"x = 0.25"``).
    view
        ``"3d"`` (fixed camera), ``"top"`` (x–y) or ``"side"`` (x–z).
    fps
        Frames per second.
    cmap
        Colour map for ``values``.
    size, dpi
        Frame size (inches) and resolution (dots per inch).
    elev, azim
        Camera angles for ``"3d"`` (degrees).

    Returns
    -------
    pathlib.Path
        The GIF's path. The axes limits cover every frame, so motion is not hidden by rescaling.
    """
    frames = np.asarray(frames_positions, dtype=float)
    if frames.ndim != 3 or frames.shape[2] != 3 or len(frames) == 0:
        raise InvalidParameterError(
            "frames_positions", f"must have shape (S, N, 3) in mm, S >= 1; got {frames.shape}"
        )
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0 or e.min() < 0 or e.max() >= frames.shape[1]:
        raise InvalidParameterError("edges", f"need >= 1 segment in [0, {frames.shape[1] - 1}]")
    if view not in ("3d", "top", "side"):
        raise InvalidParameterError("view", f"must be '3d', 'top' or 'side'; got {view!r}")
    if not fps > 0:
        raise InvalidParameterError("fps", f"must be > 0 frames/s; got {fps}")
    seg_values = None
    if values is not None:
        vals = np.asarray(values, dtype=float)
        if vals.shape != frames.shape[:2]:
            raise InvalidParameterError(
                "values", f"must have shape {frames.shape[:2]}; got {vals.shape}"
            )
        seg_values = np.stack([segment_values(v, e) for v in vals])
    if labels is not None and len(labels) != len(frames):
        raise InvalidParameterError("labels", f"needs one label per frame ({len(frames)})")

    fig = new_figure(*size, dpi=dpi)
    allpts = frames.reshape(-1, 3)
    if view == "3d":
        ax = fig.add_subplot(projection="3d")
        coll = Line3DCollection(frames[0][e], linewidths=1.2)
        ax.add_collection3d(coll)
        set_equal_3d(ax, allpts)
        ax.view_init(elev=elev, azim=azim)
        dims = [0, 1, 2]
    else:
        ax = fig.add_subplot()
        dims = [0, 1] if view == "top" else [0, 2]
        coll = LineCollection(frames[0][e][:, :, dims], linewidths=1.2)
        ax.add_collection(coll)
        lo, hi = allpts[:, dims].min(axis=0), allpts[:, dims].max(axis=0)
        pad = 0.05 * float((hi - lo).max() or 1.0)
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal", adjustable="datalim")
    if seg_values is None:
        coll.set_color("k")
    else:
        coll.set_cmap(scalar_colormap(cmap))
        coll.set_norm(scalar_norm(seg_values.ravel()))

    images = []
    for s in range(len(frames)):
        coll.set_segments(frames[s][e][:, :, dims])
        if seg_values is not None:
            coll.set_array(np.ma.masked_invalid(seg_values[s]))
        if labels is not None:
            ax.set_title(labels[s])
        rgb = figure_to_rgb(fig)
        images.append(Image.fromarray(rgb).convert("P", palette=Image.Palette.ADAPTIVE))
    target = Path(path)
    with atomic_path(target) as tmp:
        images[0].save(
            tmp,
            format="GIF",
            save_all=True,
            append_images=images[1:],
            duration=round(1000.0 / fps),
            loop=0,
            disposal=2,
        )
    return target

"""Animations of the morphing: one frame per actuation step.

:func:`write_movie` writes rendered frames as an MP4 through matplotlib's ffmpeg writer (a GIF
through Pillow where no ffmpeg is installed); :func:`animate_gif` draws line networks into a
small GIF.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
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

__all__ = ["animate_gif", "ffmpeg_available", "write_movie"]


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


def ffmpeg_available() -> bool:
    """Whether matplotlib finds an ``ffmpeg`` executable (for MP4)."""
    from matplotlib import animation

    return bool(animation.writers.is_available("ffmpeg"))


def write_movie(
    frames: Sequence[np.ndarray] | Callable[[int], np.ndarray],
    count: int,
    path: str | os.PathLike[str],
    *,
    seconds_per_frame: float = 0.6,
    min_duration: float = 5.0,
    hold_last: int = 2,
) -> Path:
    """Write rendered RGB frames as an MP4 (matplotlib's ffmpeg writer) or, without ffmpeg, a GIF.

    Each frame is shown for ``seconds_per_frame`` (longer when needed to last ``min_duration``
    seconds); the last one ``hold_last`` times longer. The MP4 is H.264 at 25 frames/s
    (frames are repeated, never interpolated: every frame is a computed state).

    Parameters
    ----------
    frames
        ``count`` images ``(H, W, 3)`` uint8, all the same size, or a function returning
        frame ``k`` (rendered on demand, so a long run does not hold every frame in memory).
    count
        Number of frames (>= 1).
    path
        Destination; its suffix is replaced by ``.mp4`` or ``.gif`` (whichever is written).
    seconds_per_frame, min_duration, hold_last
        Timing (s, s, frames).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    from matplotlib import animation

    if count < 1:
        raise InvalidParameterError("frames", "needs at least one frame")
    if not (seconds_per_frame > 0 and min_duration >= 0):
        raise InvalidParameterError("seconds_per_frame", "must be > 0 s")
    get = frames if callable(frames) else (lambda k: frames[k])  # type: ignore[index]
    shown = count + max(0, int(hold_last))
    fps = 1.0 / max(seconds_per_frame, min_duration / shown)
    first = np.asarray(get(0))
    h, w = first.shape[0] - first.shape[0] % 2, first.shape[1] - first.shape[1] % 2
    dpi = 100.0
    fig = new_figure(w / dpi, h / dpi, dpi=dpi)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    image = ax.imshow(first[:h, :w], interpolation="none", aspect="auto")
    target = Path(path)
    if ffmpeg_available():
        target = target.with_suffix(".mp4")
        writer: animation.AbstractMovieWriter = animation.FFMpegWriter(
            fps=fps,  # type: ignore[arg-type]  # ffmpeg takes any rate
            codec="h264",
            extra_args=["-r", "25", "-pix_fmt", "yuv420p"],
        )
    else:  # pragma: no cover - depends on the machine
        target = target.with_suffix(".gif")
        writer = animation.PillowWriter(fps=fps)  # type: ignore[arg-type]
    with atomic_path(target) as tmp, writer.saving(fig, str(tmp), dpi=dpi):
        for k in range(count):
            frame = first if k == 0 else np.asarray(get(k))
            image.set_data(frame[:h, :w])
            repeats = 1 + (max(0, int(hold_last)) if k == count - 1 else 0)
            for _ in range(repeats):
                writer.grab_frame()
    return target

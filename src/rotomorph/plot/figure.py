"""Figure helpers shared by every plot module: headless figures and atomic saving.

Figures are built with :class:`matplotlib.figure.Figure` directly (never ``pyplot``), so no
global state is touched, nothing needs a display, and a figure is freed with its last reference.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path

__all__ = ["figure_to_rgb", "new_figure", "save_figure"]

_FORMATS = {".png", ".svg", ".pdf", ".jpg", ".jpeg", ".eps", ".tif", ".tiff", ".webp"}


def new_figure(width: float = 6.4, height: float = 4.8, *, dpi: float = 100.0) -> Figure:
    """An empty Agg-backed figure of ``width`` × ``height`` inches."""
    fig = Figure(figsize=(width, height), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike[str], *, dpi: float = 150.0) -> Path:
    """Save ``fig`` atomically; the format follows the suffix (``.png``, ``.svg``, ``.pdf`` …).

    Parameters
    ----------
    fig
        The figure.
    path
        Destination; its folder must exist.
    dpi
        Resolution of raster formats (dots per inch).

    Raises
    ------
    InvalidParameterError
        For a suffix matplotlib cannot write.
    """
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in _FORMATS:
        raise InvalidParameterError(
            "path", f"suffix {suffix!r} is not a figure format; use one of {sorted(_FORMATS)}"
        )
    with atomic_path(target) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix[1:], bbox_inches="tight")
    return target


def figure_to_rgb(fig: Figure) -> np.ndarray:
    """Render ``fig`` with Agg and return its pixels ``(H, W, 3)`` as ``uint8``."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()

"""Figure helpers shared by every plot module: headless figures and atomic saving.

Figures are built with :class:`matplotlib.figure.Figure` directly (never ``pyplot``), so no
global state is touched, nothing needs a display, and a figure is freed with its last reference.

Text is never parsed as mathtext: names come from files, and a filament called ``$x^{$`` must
draw as those five characters, not crash the renderer after hours of computation. Every text of
a figure made by :func:`new_figure` is set literal (:func:`literal_text`) each time the figure is
drawn, whoever draws it (``save_figure``, a notebook, ``fig.savefig``); the package's own
labels use Unicode symbols (κ, °C, ω*), never ``$…$``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path

__all__ = ["LiteralFigure", "figure_to_rgb", "literal_text", "new_figure", "save_figure"]


def literal_text(fig: Figure) -> Figure:
    """Turn off mathtext for every text of ``fig`` (titles, labels, legends, annotations):
    ``$`` is a dollar sign. Returns ``fig``."""
    for text in fig.findobj(Text):
        text.set_parse_math(False)
    return fig


class LiteralFigure(Figure):
    """A :class:`~matplotlib.figure.Figure` whose texts are drawn literally, never as mathtext
    (:func:`literal_text` before every draw, by any backend)."""

    def draw(self, renderer: object) -> None:  # type: ignore[override]
        literal_text(self)
        super().draw(renderer)  # type: ignore[arg-type]


_FORMATS = {".png", ".svg", ".pdf", ".jpg", ".jpeg", ".eps", ".tif", ".tiff", ".webp"}


def new_figure(width: float = 6.4, height: float = 4.8, *, dpi: float = 100.0) -> Figure:
    """An empty Agg-backed figure of ``width`` × ``height`` inches (text drawn literally)."""
    fig = LiteralFigure(figsize=(width, height), dpi=dpi)
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
    literal_text(fig)  # also for a figure that is not a LiteralFigure
    with atomic_path(target) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix[1:], bbox_inches="tight")
    return target


def figure_to_rgb(fig: Figure) -> np.ndarray:
    """Render ``fig`` with Agg and return its pixels ``(H, W, 3)`` as ``uint8``."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    literal_text(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()

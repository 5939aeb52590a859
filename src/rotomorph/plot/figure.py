"""Figure helpers shared by every plot module: headless figures and atomic saving.

Figures are built with :class:`matplotlib.figure.Figure` directly (never ``pyplot``), so no
global state is touched, nothing needs a display, and a figure is freed with its last reference.

Text is never parsed as mathtext: names come from files, and a filament called ``$x^{$`` must
draw as those five characters, not crash the renderer after hours of computation. Every text of
a figure made by :func:`new_figure` is set literal (:func:`literal_text`) each time the figure is
drawn, whoever draws it (``save_figure``, a notebook, ``fig.savefig``); the package's own
labels use Unicode symbols (κ, °C, ω*), never ``$…$``.

Tick labels never run into each other: before a figure is saved, :func:`legible_ticks` draws
it once and, on any axis whose neighbouring tick labels touch (long signed decimals such as
``−0.125`` on a narrow panel), asks its locator for fewer ticks until they stand apart.
"""

from __future__ import annotations

import itertools
import os
from pathlib import Path

import numpy as np
from matplotlib.axis import Axis, YAxis
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.ticker import MaxNLocator

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path

__all__ = [
    "LiteralFigure",
    "crowded_ticks",
    "figure_to_rgb",
    "legible_ticks",
    "literal_text",
    "new_figure",
    "save_figure",
]

#: gap (pixels at the figure's dpi) that neighbouring tick labels keep at least
TICK_GAP_PX = 2.0


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


def _tick_axes(fig: Figure) -> list[Axis]:
    """The 2-D x and y axes of ``fig`` whose major ticks come from a linear locator that takes a
    bin count (matplotlib's default; log, category and fixed ticks are left as they are)."""
    out: list[Axis] = []
    for ax in fig.get_axes():
        if getattr(ax, "name", "") == "3d":
            continue
        for axis in (ax.xaxis, ax.yaxis):
            if isinstance(axis.get_major_locator(), MaxNLocator):
                out.append(axis)
    return out


def crowded_ticks(axis: Axis, renderer: object, gap: float = TICK_GAP_PX) -> bool:
    """Whether two neighbouring visible major tick labels of ``axis`` are less than ``gap``
    pixels apart (or overlap), as last drawn with ``renderer``."""
    boxes = [
        t.get_window_extent(renderer)  # type: ignore[arg-type]
        for t in axis.get_ticklabels()
        if t.get_visible() and t.get_text()
    ]
    if len(boxes) < 2:
        return False
    vertical = isinstance(axis, YAxis)
    spans = sorted((b.y0, b.y1) if vertical else (b.x0, b.x1) for b in boxes)
    return any(nxt[0] - cur[1] < gap for cur, nxt in itertools.pairwise(spans))


def legible_ticks(fig: Figure, *, max_rounds: int = 6) -> Figure:
    """Draw ``fig`` and thin the major ticks of every linear 2-D axis whose tick labels touch
    (:func:`crowded_ticks`), one tick fewer per round, until none touch. Returns ``fig``."""
    axes = _tick_axes(fig)
    if not axes:  # only 3-D panels or fixed ticks: nothing to measure, no draw spent
        return fig
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    literal_text(fig)
    bins: dict[Axis, int] = {}  # the bin counts set here, per axis
    for _ in range(max_rounds):
        fig.draw_without_rendering()  # places the ticks; nothing is rasterised
        renderer = canvas.get_renderer()
        crowded = [a for a in axes if crowded_ticks(a, renderer)]
        if not crowded:
            break
        for axis in crowded:
            lo, hi = sorted(axis.get_view_interval())
            locs = np.asarray(axis.get_majorticklocs(), dtype=float)
            shown = int(np.count_nonzero((locs >= lo) & (locs <= hi)))  # intervals + 1
            bins[axis] = max(1, min(shown - 1, bins.get(axis, shown)) - 1)
            locator = axis.get_major_locator()
            assert isinstance(locator, MaxNLocator)  # as _tick_axes chose
            locator.set_params(nbins=bins[axis])
    return fig


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
    legible_ticks(fig)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, dpi=dpi, format=suffix[1:], bbox_inches="tight")
    return target


def figure_to_rgb(fig: Figure) -> np.ndarray:
    """Render ``fig`` with Agg and return its pixels ``(H, W, 3)`` as ``uint8``."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    literal_text(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()

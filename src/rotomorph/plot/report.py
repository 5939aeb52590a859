"""Report figures: measured values with error bars against model predictions."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import new_figure

__all__ = ["plot_measured_vs_predicted"]


def plot_measured_vs_predicted(
    x: FloatArray,
    measured: FloatArray,
    spread: FloatArray | None,
    predicted: FloatArray,
    *,
    xlabel: str,
    ylabel: str,
    measured_label: str = "measured (mean ± s.d.)",
    predicted_label: str = "predicted",
    title: str = "",
    predicted_x: FloatArray | None = None,
    out_of_sample: tuple[FloatArray, FloatArray, FloatArray] | None = None,
) -> Figure:
    """Measured means with error bars and the model's prediction on one axes.

    Parameters
    ----------
    x
        Abscissae of the measurements ``(M,)`` (e.g. ω*, or strain), in the unit of ``xlabel``.
    measured
        Measured means ``(M,)``; NaN marks a missing measurement (not drawn).
    spread
        Error-bar half-widths ``(M,)`` (e.g. one standard deviation), ≥ 0, or ``None``.
    predicted
        Predictions ``(M,)`` at ``x``, or ``(P,)`` at ``predicted_x`` (a dense curve).
    xlabel, ylabel
        Axis labels, with units (e.g. ``"ω* (–)"``, ``"L/L0 (–)"``).
    measured_label, predicted_label
        Legend entries.
    title
        Axes title.
    predicted_x
        Abscissae of ``predicted`` when they differ from ``x``.
    out_of_sample
        Optional ``(x, value, sd)`` of predictions made without these measurements (red
        squares with ± sd bars), drawn next to the measured points.
    """
    xs = np.asarray(x, dtype=float).reshape(-1)
    m = np.asarray(measured, dtype=float).reshape(-1)
    if m.shape != xs.shape:
        raise InvalidParameterError("measured", f"must match x {xs.shape}; got {m.shape}")
    err = None
    if spread is not None:
        err = np.asarray(spread, dtype=float).reshape(-1)
        if err.shape != xs.shape:
            raise InvalidParameterError("spread", f"must match x {xs.shape}; got {err.shape}")
        if np.any(err[np.isfinite(err)] < 0):
            raise InvalidParameterError("spread", "error-bar half-widths must be >= 0")
    px = xs if predicted_x is None else np.asarray(predicted_x, dtype=float).reshape(-1)
    p = np.asarray(predicted, dtype=float).reshape(-1)
    if p.shape != px.shape:
        raise InvalidParameterError(
            "predicted", f"must match {'x' if predicted_x is None else 'predicted_x'} {px.shape}"
        )
    fig = new_figure(5.6, 4.2)
    ax = fig.add_subplot()
    order = np.argsort(px, kind="stable")
    ax.plot(
        px[order],
        p[order],
        "k-",
        marker="s" if predicted_x is None else None,
        ms=4,
        label=predicted_label,
    )
    ok = np.isfinite(m)
    ax.errorbar(
        xs[ok],
        m[ok],
        yerr=None if err is None else err[ok],
        fmt="o",
        color="tab:blue",
        ecolor="tab:blue",
        capsize=3,
        label=measured_label,
    )
    if out_of_sample is not None:
        ox, ov, osd = (np.asarray(a, dtype=float).reshape(-1) for a in out_of_sample)
        if not ox.shape == ov.shape == osd.shape:
            raise InvalidParameterError("out_of_sample", "x, value and sd must have one shape")
        ax.errorbar(
            ox * 1.03 if np.all(ox > 0) else ox,
            ov,
            yerr=osd,
            fmt="s",
            color="tab:red",
            capsize=3,
            ms=5,
            label="predicted without these data (± sd)",
        )
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(frameon=False)
    fig.tight_layout()
    return fig

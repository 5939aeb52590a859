"""Figures of a lab calibration: each table with its fitted curve and band, the residuals, and
how much each parameter the tables determine."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from rotomorph._typing import FloatArray
from rotomorph.plot.figure import new_figure

__all__ = ["Curve", "Points", "fit_figure", "identifiability_figure", "residual_figure"]


@dataclass(frozen=True)
class Curve:
    """A model curve with its ±1 sd calibration band (``sd`` may be zeros)."""

    x: FloatArray
    y: FloatArray
    sd: FloatArray
    label: str


@dataclass(frozen=True)
class Points:
    """Measured points, or predictions, with ± sd bars."""

    x: FloatArray
    y: FloatArray
    sd: FloatArray
    label: str


def fit_figure(
    measured: Sequence[Points],
    curves: Sequence[Curve],
    held_out: Points | None,
    *,
    xlabel: str,
    ylabel: str,
    title: str,
    log_x: bool = False,
) -> Figure:
    """One table: measured means ± sd, the fitted curve(s) with their ±1 sd band, and the
    predictions of the fit without this table (red squares ± sd, beside the points)."""
    fig = new_figure(5.8, 4.2)
    ax = fig.add_subplot()
    colours = ["k", "tab:purple", "tab:green", "tab:orange", "tab:brown"]
    for i, c in enumerate(curves):
        colour = colours[i % len(colours)]
        order = np.argsort(c.x)
        x, y, s = c.x[order], c.y[order], c.sd[order]
        ax.plot(x, y, "-", color=colour, lw=1.2, label=c.label)
        if np.any(s > 0):
            ax.fill_between(x, y - s, y + s, color=colour, alpha=0.15, lw=0)
    markers = ["o", "D", "^", "v", "P"]
    for i, m in enumerate(measured):
        ax.errorbar(
            m.x, m.y, yerr=m.sd, fmt=markers[i % len(markers)], color="tab:blue", ms=5,
            capsize=3, label=m.label,
        )  # fmt: skip
    if held_out is not None and len(held_out.x):
        xs = np.concatenate([*(m.x for m in measured), *(c.x for c in curves)])
        span = float(np.ptp(xs)) if len(xs) else 1.0
        shift = held_out.x * 1.04 if log_x else held_out.x + 0.015 * (span or 1.0)
        ax.errorbar(
            shift, held_out.y, yerr=held_out.sd, fmt="s", color="tab:red", ms=5, capsize=3,
            label=held_out.label,
        )  # fmt: skip
    if log_x:
        from matplotlib.ticker import NullFormatter, ScalarFormatter

        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    return fig


def residual_figure(
    groups: Sequence[str], fitted: Sequence[FloatArray], held_out: Sequence[FloatArray | None]
) -> Figure:
    """Normalised residuals z = (model − measured)/sd of every row: in-sample (the fit to all
    tables, dots) and out-of-sample (the fit without the row's table, squares, z against the
    combined spread); the band −2 ≤ z ≤ 2 shaded."""
    fig = new_figure(6.4, 0.9 + 0.45 * max(len(groups), 1))
    ax = fig.add_subplot()
    ax.axvspan(-2, 2, color="tab:green", alpha=0.08, lw=0)
    ax.axvline(0.0, color="0.5", lw=0.8)
    for i, (z_in, z_out) in enumerate(zip(fitted, held_out, strict=True)):
        jitter = np.linspace(-0.12, 0.12, len(z_in)) if len(z_in) > 1 else np.zeros(1)
        ax.plot(
            z_in,
            i + jitter,
            "o",
            color="tab:blue",
            ms=5,
            label="fit to all tables" if i == 0 else None,
        )
        if z_out is not None:
            ax.plot(
                z_out, i + 0.3 + jitter, "s", color="tab:red", ms=5, mfc="none",
                label="predicted without its table" if i == 0 else None,
            )  # fmt: skip
    ax.set_yticks(range(len(groups)))
    ax.set_yticklabels(groups, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("z = (model − measured) / sd")
    ax.set_title("residuals of every row (|z| <= 2 shaded)", fontsize=10)
    ax.grid(alpha=0.3, axis="x")
    ax.legend(fontsize=7, loc="lower right")
    return fig


def identifiability_figure(
    labels: Sequence[str], before: Sequence[float], after: Sequence[float]
) -> Figure:
    """Posterior over prior width of each parameter, before fitting (at the prior mean) and at
    the optimum: near 1 the tables leave it at its prior."""
    fig = new_figure(6.4, 0.9 + 0.5 * max(len(labels), 1))
    ax = fig.add_subplot()
    y = np.arange(len(labels))
    ax.barh(y - 0.18, before, height=0.34, color="0.7", label="before fitting (prior mean)")
    ax.barh(y + 0.18, after, height=0.34, color="tab:blue", label="at the optimum")
    ax.axvline(0.5, color="tab:green", ls="--", lw=1, label="determined below 0.5")
    ax.axvline(0.9, color="tab:red", ls="--", lw=1, label="at its prior from 0.9")
    ax.set_yticks(y)
    ax.set_yticklabels(labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlim(0.0, 1.05)
    ax.set_xlabel("posterior width / prior width")
    ax.set_title("what the tables determine", fontsize=10)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
    return fig

"""Report figures: measured values with error bars against model predictions."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import new_figure

__all__ = ["plot_measured_vs_predicted", "plot_parity"]


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


def _how(row: dict) -> str:
    if row.get("calibration"):
        return "fit / input"
    if row.get("counted"):
        return "out of sample"
    return "not counted"


def _panel(row: dict) -> str:
    """The panel of a row in :func:`plot_parity`: its unit, ``sign`` for a sign, or its
    quantity where it has no unit."""
    if str(row["quantity"]).replace("_", " ").endswith("sign"):
        return "sign"
    unit = row.get("unit")
    return f"quantity:{row['quantity']}" if unit is None else str(unit)


#: Marker of each kind of row in :func:`plot_parity`.
_KINDS = {"out of sample": ("o", "k"), "not counted": ("s", "none"), "fit / input": ("^", "none")}


def plot_parity(rows: list[dict], *, title: str = "") -> Figure:
    """Predicted against measured for every row with both, one panel per unit.

    Parameters
    ----------
    rows
        Rows as ``rotomorph paper``'s ``summary.json`` writes them: ``quantity``, ``unit``,
        ``measured``, ``spread``, ``predicted``, ``predicted_sd`` and the flags ``calibration``
        and ``counted``. Out-of-sample predictions are filled, fits and inputs triangles,
        rows not counted hollow squares; error bars are the measurement's s.d. (horizontal) and
        the prediction's (vertical); the diagonal is perfect agreement. Rows share a panel
        when they share a unit; a row without a unit has a panel of its own quantity, and signs
        (quantities named ``... sign``) one of their own, so no panel mixes scales.
    title
        Figure title.
    """
    shown = [r for r in rows if r.get("measured") is not None and r.get("predicted") is not None]
    if not shown:
        raise InvalidParameterError("rows", "need at least one row with measured and predicted")
    units = list(dict.fromkeys(_panel(r) for r in shown))
    fig = new_figure(4.3 * len(units) + 1.6, 4.3)
    axes = np.atleast_1d(fig.subplots(1, len(units)))
    quantities = list(dict.fromkeys(r["quantity"] for r in shown))
    colour = {q: f"C{i % 10}" for i, q in enumerate(quantities)}
    for ax, unit in zip(axes, units, strict=True):
        sel = [r for r in shown if _panel(r) == unit]
        for r in sel:
            marker, face = _KINDS[_how(r)]
            c = colour[r["quantity"]]
            ax.errorbar(
                r["measured"],
                r["predicted"],
                xerr=r.get("spread") or None,
                yerr=r.get("predicted_sd") or None,
                fmt=marker,
                ms=6,
                mfc=c if face == "k" else "white",
                mec=c,
                ecolor=c,
                capsize=2,
                lw=1,
            )
        values = [v for r in sel for v in (r["measured"], r["predicted"])]
        lo, hi = min(values), max(values)
        pad = 0.08 * (hi - lo or abs(hi) or 1.0)
        ax.plot([lo - pad, hi + pad], [lo - pad, hi + pad], color="0.6", lw=1, zorder=0)
        ax.set_xlim(lo - pad, hi + pad)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_aspect("equal")
        if unit.startswith("quantity:"):
            name = unit.removeprefix("quantity:")
            ax.set_xlabel(f"measured {name}")
            ax.set_ylabel(f"predicted {name}")
        else:
            suffix = " (–)" if unit in ("1", "", "sign") else f" ({unit})"
            what = " sign" if unit == "sign" else ""
            ax.set_xlabel(f"measured{what}{suffix}")
            ax.set_ylabel(f"predicted{what}{suffix}")
        ax.grid(alpha=0.3)
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], ls="", marker="o", color=colour[q], label=q) for q in quantities]
    handles += [
        Line2D([], [], ls="", marker=m, mfc="0.3" if f == "k" else "white", mec="0.3", label=k)
        for k, (m, f) in _KINDS.items()
        if any(_how(r) == k for r in shown)
    ]
    fig.legend(handles=handles, loc="outside right center", fontsize=8, frameon=False)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.set_layout_engine("constrained")
    return fig

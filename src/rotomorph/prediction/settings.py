r"""Which print settings give a wanted filament shape: ``rotomorph predict --for curvature=0.4``.

The question is answered on the paper report's calibrated curves
(:func:`rotomorph.materials.calibrate.filament_shapes`: a straight filament printed at speed
:math:`v` and rotation number :math:`\omega^*`, heated free to the calibration temperature),
inside the calibrated range (:func:`rotomorph.prediction.band.calibrated_range`): the
measured speeds and :math:`|\omega^*|`; outside it the fitted laws would be extrapolated, and
an answer there would not be a prediction.

Quantities (of the heated filament, per unit of its *current* length where it is a rate):
``curvature`` (1/mm), ``twist`` (the centre line's torsion, 1/mm, > 0 right-handed),
``radius`` and ``pitch`` of the helix (mm, pitch > 0 right-handed) and ``L/L0`` (end-to-end
over printed length).

One quantity leaves one setting free, fixed by the simplest print: ``curvature`` and
``radius`` at :math:`\omega^* = 0` (a Janus filament printed straight bends in a plane, toward
its active half), ``twist``, ``pitch`` and ``L/L0`` at the paper's rotation-series speed
(3 mm/s, where :math:`\omega^*` was calibrated). ``speed=`` or ``rotation_number=`` fixes
another; two quantities fix both settings. Where the simplest line has no solution the whole
calibrated range is searched. A request no setting in the calibrated range meets is refused,
with the range the quantity does reach there.

The answer carries the calibration band of each setting (the setting re-solved along every
posterior direction, secants as in :meth:`rotomorph.materials.inference.Fit.propagate`) and
the printable setting, rounded to what a machine realises (speed 0.01 mm/s, ω* 0.001) with
the quantities it gives and their band.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq, least_squares

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.calibrate import PAPER_RADIUS, filament_shapes
from rotomorph.materials.natural import FilamentModel
from rotomorph.prediction.band import (
    CalibratedRange,
    Estimate,
    calibrated_range,
    calibration_fit,
    nominal_model,
    with_band,
)
from rotomorph.prediction.filament import handedness

__all__ = [
    "QUANTITIES",
    "ROTATION_STEP",
    "SPEED_STEP",
    "SettingsAnswer",
    "parse_request",
    "quantity",
    "settings_for",
]

#: Quantities a request may name, with their units.
QUANTITIES = {"curvature": "1/mm", "twist": "1/mm", "radius": "mm", "pitch": "mm", "L/L0": "1"}
_ALIASES = {"end_to_end_ratio": "L/L0", "l/l0": "L/L0", "torsion": "twist"}
#: What a machine realises: print speed to 0.01 mm/s, rotation number to 0.001.
SPEED_STEP = 0.01
ROTATION_STEP = 1e-3
_SETTINGS = ("speed", "rotation_number")


def parse_request(texts: list[str]) -> dict[str, float]:
    """``["curvature=0.4", "radius=2,pitch=1.5"]`` → ``{"curvature": 0.4, ...}``.

    Raises
    ------
    InvalidParameterError
        Unknown names, values that are not finite numbers, a quantity given twice.
    """
    out: dict[str, float] = {}
    for text in texts:
        for item in text.split(","):
            name, sep, value = item.partition("=")
            key = _ALIASES.get(name.strip().lower(), name.strip())
            if key not in QUANTITIES and key not in _SETTINGS:
                raise InvalidParameterError(
                    "--for",
                    f"{item.strip()!r}: give NAME=VALUE with NAME one of "
                    f"{', '.join([*QUANTITIES, *_SETTINGS])}",
                )
            try:
                number = float(value) if sep else math.nan
            except ValueError:
                number = math.nan
            if not math.isfinite(number):
                raise InvalidParameterError(
                    "--for", f"{item.strip()!r}: the value must be a finite number"
                )
            if key in out:
                raise InvalidParameterError("--for", f"{key} is given twice")
            out[key] = number
    return out


def quantity(
    model: FilamentModel,
    speed: float,
    rotation_number: float,
    *,
    active_fraction: float = 0.5,
    radius: float = PAPER_RADIUS,
) -> dict[str, float]:
    """The heated filament's quantities (module docstring) at one print setting."""
    s = filament_shapes(
        model, np.array([rotation_number]), active_fraction, speed=speed, radius=radius
    )[0]
    return {
        "curvature": s.curvature,
        "twist": s.torsion,
        "radius": s.radius,
        "pitch": s.pitch,
        "L/L0": s.end_to_end_ratio,
    }


@dataclass(frozen=True)
class SettingsAnswer:
    """Print settings that give a requested shape.

    Attributes
    ----------
    request
        The requested quantities.
    speed, rotation_number
        The solution (mm/s, dimensionless) with its calibration band.
    printable
        The solution rounded to what a machine realises (``speed``, ``rotation_number``).
    achieved
        The quantities at the printable setting, with their band.
    free
        Which setting was fixed and how (``"rotation_number = 0 (planar)"``, …).
    active_side
        Where the active half sits.
    handedness
        Of the heated shape at the printable setting.
    range
        The calibrated range searched.
    notes
        Other findings (a mirror solution, a band that leaves the range, …).
    """

    request: dict[str, float]
    speed: Estimate
    rotation_number: Estimate
    printable: dict[str, float]
    achieved: dict[str, Estimate]
    free: str
    active_side: str
    handedness: str
    range: CalibratedRange
    active_fraction: float
    notes: list[str] = field(default_factory=list)

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "request": self.request,
            "speed_mm_s": self.speed.record(),
            "rotation_number": self.rotation_number.record(),
            "printable": self.printable,
            "rounding": {"speed_mm_s": SPEED_STEP, "rotation_number": ROTATION_STEP},
            "achieved_at_printable": {k: v.record() for k, v in self.achieved.items()},
            "fixed": self.free,
            "active_fraction": self.active_fraction,
            "active_side": self.active_side,
            "handedness": self.handedness,
            "calibrated_range": self.range.record(),
            "notes": self.notes,
        }

    def line(self) -> str:
        """One line for a terminal."""
        units = {**QUANTITIES, "L/L0": "", "speed": "mm/s", "rotation_number": ""}
        want = ", ".join(f"{k} = {v:g} {units[k]}".rstrip() for k, v in self.request.items())
        got = ", ".join(f"{k} {self.achieved[k].text()}" for k in self.request if k in QUANTITIES)
        p = self.printable
        text = (
            f"{want}: print at speed {self.speed.text(4)}, rotation number ω* "
            f"{self.rotation_number.text(4)} ({self.free}); printable: speed = "
            f"{p['speed']:.2f} mm/s, rotation_number = {p['rotation_number']:.3f} (speed to "
            f"{SPEED_STEP:g} mm/s, ω* to {ROTATION_STEP:g}), active_fraction = "
            f"{self.active_fraction:g}, {self.active_side}; gives {got}"
            + (f", {self.handedness}" if self.handedness != "planar" else ", planar")
            + f"; calibrated range {self.range.text()}"
        )
        if self.notes:
            text += "; " + "; ".join(self.notes)
        return text


def _residual(model: FilamentModel, wanted: Mapping[str, float], fraction: float) -> Any:
    """``f(v, w)`` → scaled residuals ``(len(wanted),)``, or ``(len(wanted), n)`` for an array
    ``w`` (one call of the closed form for all rotation numbers at one speed)."""
    names = list(wanted)

    def f(v: float, w: Any) -> FloatArray:
        ws = np.atleast_1d(np.asarray(w, dtype=float))
        shapes = filament_shapes(model, ws, fraction, speed=float(v), radius=PAPER_RADIUS)
        q = {
            "curvature": [x.curvature for x in shapes],
            "twist": [x.torsion for x in shapes],
            "radius": [x.radius for x in shapes],
            "pitch": [x.pitch for x in shapes],
            "L/L0": [x.end_to_end_ratio for x in shapes],
        }
        out = np.array([(np.array(q[k]) - wanted[k]) / _scale(k, wanted[k]) for k in names])
        return out[:, 0] if np.ndim(w) == 0 else out

    return f


def _scale(name: str, value: float) -> float:
    return max(abs(value), 1e-3 if name in ("curvature", "twist", "L/L0") else 1e-2)


class _Unreachable(Exception):
    pass


#: One free setting: the lines tried, in order (kind fixed, its value or None for the
#: rotation-series speed, how it is stated).
def _lines(name: str, rng: CalibratedRange) -> list[tuple[str, float, str]]:
    planar = ("rotation_number", 0.0, "rotation number 0: planar")
    series = (
        "speed",
        rng.rotation_speed,
        f"speed {rng.rotation_speed:g} mm/s: the calibrated rotation series",
    )
    return [planar, series] if name in ("curvature", "radius") else [series, planar]


def _solve(
    model: FilamentModel,
    wanted: Mapping[str, float],
    fixed: Mapping[str, float],
    fraction: float,
    rng: CalibratedRange,
    near: tuple[float, float] | None = None,
) -> tuple[float, float, str]:
    """``(speed, rotation number, how)`` meeting ``wanted`` (raises _Unreachable).

    ``near``: a nominal solution; the root is then followed from it along the same line (the
    band) instead of searched for."""
    f = _residual(model, wanted, fraction)
    speeds = rng.speed
    w_hi = rng.rotation_number
    if len(wanted) == 2:
        return (*_box_root(f, speeds, w_hi, near), "both settings from the two quantities")
    if fixed:
        kind, value = next(iter(fixed.items()))
        unit = " mm/s" if kind == "speed" else ""
        lines = [(kind, value, f"{kind.replace('_', ' ')} = {value:g}{unit} as asked")]
    else:
        lines = _lines(next(iter(wanted)), rng)
    for kind, value, how in lines:
        root = _line_root(f, kind, value, speeds, w_hi, near)
        if root is not None:
            return (*root, how)
    if fixed:
        raise _Unreachable()
    # neither simple line: the whole calibrated range, one more quantity free
    return (*_box_root(f, speeds, w_hi, near), "searched the calibrated range")


def _line_root(
    f: Any,
    kind: str,
    value: float,
    speeds: tuple[float, float],
    w_hi: float,
    near: tuple[float, float] | None,
) -> tuple[float, float] | None:
    """The root along a line of fixed speed (scan ω* outward from 0, the root of smallest
    |ω*|) or fixed rotation number (scan the speeds from the slowest); with ``near`` the root
    nearest to it."""
    if kind == "speed":
        at = lambda x: float(f(value, x)[0])  # noqa: E731
        lo, hi = -w_hi, w_hi
        start = None if near is None else near[1]
    else:
        at = lambda x: float(f(x, value)[0])  # noqa: E731
        lo, hi = speeds
        start = None if near is None else near[0]
    if start is not None:
        r = _bracketed(at, start, lo, hi)
    elif kind == "speed":
        best: float | None = None
        for side in (1.0, -1.0):
            xs = side * np.linspace(0.0, w_hi, 81)
            vals = f(value, xs)[0]
            r = _first_root(at, xs, vals)
            if r is not None and (best is None or abs(r) < abs(best)):
                best = r
        r = best
    else:
        xs = np.geomspace(lo, hi, 41)
        vals = np.array([at(x) for x in xs])
        r = _first_root(at, xs, vals)
    if r is None:
        return None
    return (value, r) if kind == "speed" else (r, value)


def _first_root(at: Any, xs: FloatArray, vals: FloatArray) -> float | None:
    """The first root along the scan ``xs`` (values ``vals``), refined by Brent's method."""
    for i in range(len(xs) - 1):
        if vals[i] == 0.0:
            return float(xs[i])
        if np.sign(vals[i]) * np.sign(vals[i + 1]) < 0:
            return float(brentq(at, xs[i], xs[i + 1], xtol=1e-14, rtol=1e-13))
    return float(xs[-1]) if vals[-1] == 0.0 else None


def _bracketed(at: Any, x0: float, lo: float, hi: float) -> float | None:
    """The root nearest ``x0`` within [lo, hi]: a bracket grown geometrically about it."""
    f0 = at(x0)
    if f0 == 0.0:
        return x0
    step = 1e-3 * (hi - lo)
    while step < 2.0 * (hi - lo):
        for x in (x0 - step, x0 + step):
            if lo <= x <= hi:
                fx = at(x)
                if np.sign(fx) * np.sign(f0) <= 0:
                    a, b = sorted((x0, x))
                    return float(brentq(at, a, b, xtol=1e-14, rtol=1e-13))
        step *= 2.0
    for x in (lo, hi):  # the ends of the range
        fx = at(x)
        if np.sign(fx) * np.sign(f0) <= 0:
            a, b = sorted((x0, x))
            return float(brentq(at, a, b, xtol=1e-14, rtol=1e-13))
    return None


def _box_root(
    f: Any, speeds: tuple[float, float], w_hi: float, near: tuple[float, float] | None
) -> tuple[float, float]:
    """A root of one or two residuals over the whole calibrated range (least squares from the
    best grid point, or from ``near``)."""
    if near is None:
        vs = np.geomspace(speeds[0], speeds[1], 23)
        ws = np.linspace(-w_hi, w_hi, 41)
        cost = np.array([np.sum(f(v, ws) ** 2, axis=0) for v in vs])
        i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
        x0 = np.array([vs[i], ws[j]])
    else:
        x0 = np.array(near)
    lo, hi = np.array([speeds[0], -w_hi]), np.array([speeds[1], w_hi])
    sol = least_squares(
        lambda x: f(x[0], x[1]), x0, bounds=(lo, hi), xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    if not np.all(np.abs(sol.fun) < 1e-7):
        raise _Unreachable()
    return float(sol.x[0]), float(sol.x[1])


def _reachable(
    model: FilamentModel,
    name: str,
    fraction: float,
    rng: CalibratedRange,
    fixed: Mapping[str, float],
) -> tuple[float, float]:
    """Smallest and largest ``name`` over the calibrated range (or along a fixed setting)."""
    vs = [fixed["speed"]] if "speed" in fixed else np.geomspace(*rng.speed, 12)
    if "rotation_number" in fixed:
        ws = np.array([fixed["rotation_number"]])
    else:
        ws = np.linspace(-rng.rotation_number, rng.rotation_number, 81)
    f = _residual(model, {name: 0.0}, fraction)
    vals = np.concatenate([f(float(v), ws)[0] * _scale(name, 0.0) for v in vs])
    finite = vals[np.isfinite(vals)]
    return float(finite.min()), float(finite.max())


def settings_for(request: Mapping[str, float], *, active_fraction: float = 0.5) -> SettingsAnswer:
    """Print settings giving the ``request`` (module docstring).

    Parameters
    ----------
    request
        One or two quantities of :data:`QUANTITIES` by name, optionally ``speed`` (mm/s) or
        ``rotation_number`` to fix that setting.
    active_fraction
        0.5 (Janus composite, default) or 1 (pure LCE).

    Raises
    ------
    InvalidParameterError
        Nothing or too much asked, a fixed setting outside the calibrated range, or a request
        no setting in the calibrated range meets (the message gives the reachable range).
    """
    rng = calibrated_range()
    wanted = {k: float(v) for k, v in request.items() if k in QUANTITIES}
    fixed = {k: float(v) for k, v in request.items() if k in _SETTINGS}
    if not wanted:
        raise InvalidParameterError("--for", f"name a quantity: {', '.join(QUANTITIES)}")
    if len(wanted) + len(fixed) > 2:
        raise InvalidParameterError(
            "--for", "two numbers fix a filament's two settings (speed, ω*); give at most two"
        )
    if not any(abs(active_fraction - f) < 1e-9 for f in (0.5, 1.0)):
        raise InvalidParameterError(
            "--active-fraction", "must be 0.5 (Janus) or 1 (pure LCE), the calibrated sections"
        )
    outside = rng.outside(speed=fixed.get("speed"), rotation_number=fixed.get("rotation_number"))
    if outside:
        raise InvalidParameterError("--for", "; ".join(outside))
    model = nominal_model()
    try:
        v, w, how = _solve(model, wanted, fixed, active_fraction, rng)
    except _Unreachable:
        name = next(iter(wanted))
        lo, hi = _reachable(model, name, active_fraction, rng, fixed)
        where = "" if not fixed else " with " + ", ".join(f"{k} = {x:g}" for k, x in fixed.items())
        asked = ", ".join(f"{k} = {x:g}" for k, x in wanted.items())
        raise InvalidParameterError(
            "--for",
            f"{asked}: no print setting in the calibrated range ({rng.text()}){where} gives it; "
            f"{name} reaches {lo:.4g} to {hi:.4g} {QUANTITIES[name]} there"
            + ("" if len(wanted) == 1 else " (over the range, the other quantity free)"),
        ) from None
    notes: list[str] = []
    v_sd, w_sd = _setting_band(wanted, fixed, active_fraction, rng, (v, w, how), notes)
    printable = {
        "speed": round(v / SPEED_STEP) * SPEED_STEP,
        "rotation_number": round(w / ROTATION_STEP) * ROTATION_STEP,
    }
    printable = {k: float(f"{x:.6g}") for k, x in printable.items()}
    pv, pw = printable["speed"], printable["rotation_number"]

    def at_printable(m: FilamentModel) -> FloatArray:
        q = quantity(m, pv, pw, active_fraction=active_fraction)
        return np.array([q[k] for k in QUANTITIES])

    est = with_band(at_printable, list(QUANTITIES.values()))
    achieved = dict(zip(QUANTITIES, est, strict=True))
    if len(wanted) == 1 and abs(w) > 0 and next(iter(wanted)) in ("L/L0", "radius", "curvature"):
        notes.append(f"ω* = {-pw:.3f} gives the mirror image (opposite handedness)")
    return SettingsAnswer(
        request={**wanted, **fixed},
        speed=Estimate(v, v_sd, "mm/s"),
        rotation_number=Estimate(w, w_sd, "1"),
        printable=printable,
        achieved=achieved,
        free=how,
        active_side=(
            "active half on the inner side of the bend (toward the centre of curvature)"
            if active_fraction < 1.0
            else "the whole section active (pure LCE)"
        ),
        handedness=handedness(achieved["twist"].value) if abs(pw) > 0 else "planar",
        range=rng,
        active_fraction=active_fraction,
        notes=notes,
    )


def _setting_band(
    wanted: Mapping[str, float],
    fixed: Mapping[str, float],
    fraction: float,
    rng: CalibratedRange,
    nominal: tuple[float, float, str],
    notes: list[str],
) -> tuple[float | None, float | None]:
    """Calibration sd of the solved settings: the root followed from the nominal one along the
    same line (or over the range for two quantities) one posterior sd along each direction."""
    fit = calibration_fit()
    v0, w0, how = nominal
    if fixed or len(wanted) == 2:
        line = dict(fixed)
    elif how.startswith("rotation number"):
        line = {"rotation_number": w0}
    elif how.startswith("speed"):
        line = {"speed": v0}
    else:
        line = {"speed": v0}  # searched: the band along the nominal speed
    var = np.zeros(2)
    for d in fit.directions().T:
        if not np.any(d):
            continue
        ends = []
        for sign in (1.0, -1.0):
            model = fit.model_at(fit.theta + sign * d)
            try:
                v, w, _ = _solve(model, wanted, line, fraction, rng, near=(v0, w0))
            except _Unreachable:
                notes.append("the setting leaves the calibrated range within the calibration band")
                return None, None
            ends.append(np.array([v, w]))
        var += (0.5 * (ends[0] - ends[1])) ** 2
    sd = np.sqrt(var)
    return float(sd[0]), float(sd[1])

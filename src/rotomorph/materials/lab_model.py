"""The model's predictions of a lab's measured quantities, for calibration from its tables.

An :class:`InkPair` is what a calibration varies: the filament model of one active and one
passive ink, the inks themselves (their T_NI) and the section they were printed with. Each
fitted quantity of :data:`~rotomorph.materials.lab_tables.QUANTITIES` has a predictor here
(:func:`predictor`), evaluated at the temperature of each row (default: the actuation
temperature) exactly as ``rotomorph simulate`` evaluates the chain there:

* ``janus_curvature``: K_J of a Janus straight filament at ω* = 0, print speed x;
* ``pure_lce_length`` / ``composite_length``: L/L0 of the free helix at ω* = x, speed v
  (:func:`rotomorph.materials.calibrate.filament_shapes`);
* ``free_length``: passive ink exp(ε_p (T − T0)/(T1 − T0)); active ink, pure filaments printed
  at v without rotation: exp(x(T) ε∥(v)) (the uniform section's centre-line strain);
* ``youngs_modulus``: E_p(T) (entropic) or E_a(T) (log-linear through the transition) of
  :meth:`~rotomorph.materials.natural.FilamentModel.moduli`.

Strains are Hencky unless the model's measure is engineering.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.calibrate import filament_shapes, janus_curvature
from rotomorph.materials.lab_tables import Measurement
from rotomorph.materials.material import Material
from rotomorph.materials.natural import FilamentModel

__all__ = ["InkPair", "curve", "predictor"]


@dataclass(frozen=True)
class InkPair:
    """What a lab calibration varies (a frozen dataclass: dotted parameters such as
    ``"model.modulus_ratio"`` or ``"active.transition_temperature"``).

    Parameters
    ----------
    model
        Filament model of the pair.
    active, passive
        The two inks (values at the print temperature).
    radius
        Filament radius of the calibration prints (mm).
    active_fraction
        Active share of the Janus section.
    """

    model: FilamentModel
    active: Material
    passive: Material
    radius: float
    active_fraction: float = 0.5

    @property
    def inks(self) -> tuple[Material, Material]:
        """(active, passive)."""
        return self.active, self.passive


def _temperature(pair: InkPair, m: Measurement) -> float:
    return float(m.conditions.get("T", pair.model.actuation_temperature))


def _stretch(model: FilamentModel, strain: FloatArray) -> FloatArray:
    e = np.asarray(strain, dtype=float)
    return np.exp(e) if model.strain_model.measure == "hencky" else 1.0 + e


def _by_temperature(
    rows: Sequence[Measurement], pair: InkPair, each: Callable[[list[int], float], FloatArray]
) -> FloatArray:
    """Predictions row by row, evaluated once per distinct temperature."""
    out = np.empty(len(rows))
    temps = [_temperature(pair, m) for m in rows]
    for t in sorted(set(temps)):
        idx = [i for i, ti in enumerate(temps) if ti == t]
        out[idx] = each(idx, t)
    return out


def curve(
    quantity: str,
    pair: InkPair,
    x: FloatArray,
    *,
    role: str = "",
    speed: float | None = None,
    temperature: float | None = None,
) -> FloatArray:
    """The model's curve of ``quantity`` at control values ``x`` (for figures and bands).

    Parameters
    ----------
    quantity
        A fitted quantity (module docstring).
    pair
        The model.
    x
        Control values (canonical units).
    role
        Ink role of per-ink quantities (``"active"``, ``"passive"``).
    speed
        Print speed v (mm/s) of the quantities that need one.
    temperature
        Temperature (°C) of the quantities measured at one (default: actuation).
    """
    x = np.asarray(x, dtype=float)
    t = pair.model.actuation_temperature if temperature is None else float(temperature)
    model = pair.model
    if quantity == "janus_curvature":
        return janus_curvature(
            model,
            x,
            pair.radius,
            inks=pair.inks,
            active_fraction=pair.active_fraction,
            temperature=t,
        )
    if quantity in ("pure_lce_length", "composite_length"):
        frac = 1.0 if quantity == "pure_lce_length" else pair.active_fraction
        v = 3.0 if speed is None else float(speed)
        shapes = filament_shapes(model, x, frac, v, pair.radius, inks=pair.inks, temperature=t)
        return np.array([s.end_to_end_ratio for s in shapes])
    if quantity == "free_length":
        if role == "passive":
            eps = [model.strains_at(1.0, pair.active, pair.passive, float(ti))[2] for ti in x]
            return _stretch(model, np.array(eps))
        v = 3.0 if speed is None else float(speed)
        eps = [
            float(np.asarray(model.strains_at(v, pair.active, pair.passive, float(ti))[0]))
            for ti in x
        ]
        return _stretch(model, np.array(eps))
    if quantity == "youngs_modulus":
        k = 0 if role == "active" else 1
        return np.array([model.moduli(pair.active, pair.passive, float(ti))[k] for ti in x])
    raise InvalidParameterError("quantity", f"no predictor for {quantity!r}")


def predictor(rows: Sequence[Measurement]) -> Callable[[InkPair], FloatArray]:
    """``pair -> (n,)`` predictions at ``rows`` (one fitted quantity, one ink role)."""
    rows = list(rows)
    if not rows:
        raise InvalidParameterError("rows", "needs at least one measurement")
    quantity = rows[0].quantity
    role = rows[0].ink[0] if rows[0].ink is not None else ""

    def run(pair: InkPair) -> FloatArray:
        def each(idx: list[int], t: float) -> FloatArray:
            sel = [rows[i] for i in idx]
            x = np.array([m.x for m in sel])
            if quantity in ("pure_lce_length", "composite_length"):
                out = np.empty(len(sel))
                for v in sorted({float(m.conditions["v"]) for m in sel}):
                    k = [j for j, m in enumerate(sel) if float(m.conditions["v"]) == v]
                    out[k] = curve(quantity, pair, x[k], speed=v, temperature=t)
                return out
            if quantity == "free_length" and role == "active":
                return np.array(
                    [
                        curve(
                            quantity,
                            pair,
                            np.array([m.x]),
                            role=role,
                            speed=float(m.conditions["v"]),
                        )[0]
                        for m in sel
                    ]
                )
            if quantity in ("free_length", "youngs_modulus"):
                return curve(quantity, pair, x, role=role)
            return curve(quantity, pair, x, temperature=t)

        if quantity in ("free_length", "youngs_modulus"):  # x is the temperature itself
            return each(list(range(len(rows))), pair.model.actuation_temperature)
        return _by_temperature(rows, pair, each)

    return run

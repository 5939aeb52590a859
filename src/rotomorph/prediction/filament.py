"""Quick predictions for the filaments of a design: closed-form shapes with the calibration band.

Each filament is answered by the cheapest exact route that applies:

* ``closed form (section + free helix)`` — a straight filament printed at one speed and one
  rotation number with the calibrated inks, heated to the calibration temperature: the paper
  report's own curves (:func:`rotomorph.materials.calibrate.filament_shapes`), the free helix of
  the section's natural curvature and twist;
* ``closed form (natural field)`` — any other filament whose natural field is uniform (another
  temperature, another ink, a curved path whose field is still uniform): the free helix of
  :meth:`~rotomorph.materials.natural.NaturalField.morphology`;
* ``free shape (zero energy)`` — a filament whose natural field varies (sinusoids with
  active-side flips, graded programs): the exact zero-energy state of the discrete rod
  (:func:`rotomorph.simulate.free_shape.free_equilibrium`) and its end-to-end ratio L/L0.

Every length-like number is of the heated filament: curvature and twist per unit *current*
length (what a photograph of the heated filament measures), radius and pitch in mm, L/L0 the
end-to-end length over the printed one. A positive twist (and pitch) is a right-handed helix.
No contact or gravity is modelled: a shape that would pass through itself is flagged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.materials.calibrate import filament_shapes
from rotomorph.materials.morphology import HelixShape
from rotomorph.materials.natural import DIRECTOR_HELIX_SENSE, FilamentModel, natural_field
from rotomorph.materials.process import strain_to_stretch
from rotomorph.prediction.band import (
    CALIBRATION_TEMPERATURE,
    Estimate,
    calibrated_inks,
    calibrated_materials,
    calibrated_range,
    with_band,
)

__all__ = ["FilamentPrediction", "handedness", "predict_filament"]

HELIX_QUANTITIES = ("curvature", "twist", "radius", "pitch", "L/L0")
_UNITS = {"curvature": "1/mm", "twist": "1/mm", "radius": "mm", "pitch": "mm", "L/L0": "1"}


def handedness(twist: float, tol: float = 1e-9) -> str:
    """``"right-handed"`` (twist > 0), ``"left-handed"`` or ``"planar"`` (1/mm)."""
    if abs(twist) < tol:
        return "planar"
    return "right-handed" if twist > 0 else "left-handed"


@dataclass(frozen=True)
class FilamentPrediction:
    """The quick prediction of one filament.

    Attributes
    ----------
    name
        The filament's name (or ``filaments[i]``).
    method
        Which route answered (module docstring).
    quantities
        ``curvature``, ``twist``, ``radius``, ``pitch``, ``L/L0`` (closed forms) or ``L/L0``
        (free shapes: the end-to-end ratio of this filament), each with its calibration band.
        The closed forms' L/L0 is the report's: the axis advance per length of a long filament
        (0 for a ring); ``settings["turns"]`` counts the turns of this filament's length.
    morphology
        ``ring`` (planar), ``coil``, ``helix``, ``twisted rod``, ``straight`` (closed forms) or
        ``free shape``.
    handedness
        ``right-handed``, ``left-handed`` or ``planar`` (closed forms), else ``""``.
    physical
        ``(verdict, reason)``: ``"yes"``, or ``"no"`` when the shape passes through itself.
    extrapolated
        Why the settings lie outside the calibrated range (empty: inside).
    settings
        The print settings read from the design (speed, rotation number ranges, …).
    """

    name: str
    method: str
    quantities: dict[str, Estimate]
    morphology: str
    handedness: str
    physical: tuple[str, str]
    extrapolated: tuple[str, ...]
    settings: dict[str, Any] = field(default_factory=dict)

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "name": self.name,
            "kind": "filament",
            "method": self.method,
            "quantities": {k: v.record() for k, v in self.quantities.items()},
            "morphology": self.morphology,
            "handedness": self.handedness,
            "physical": {"verdict": self.physical[0], "reason": self.physical[1]},
            "extrapolated": bool(self.extrapolated),
            "extrapolation": list(self.extrapolated),
            "settings": self.settings,
        }

    def line(self) -> str:
        """One line for a terminal."""
        q = self.quantities
        shown = ("curvature", "radius") if self.morphology == "ring" else HELIX_QUANTITIES
        parts = [f"{k} {q[k].text()}" for k in shown if k in q]
        if "turns" in self.settings:
            parts.append(f"{self.settings['turns']:.3g} turns over its heated length")
        hand = self.handedness if self.morphology != "ring" else ""
        shape = self.morphology + (f", {hand}" if hand else "")
        out = f"{self.name}: {shape}: " + ", ".join(parts) + f" [{self.method}]"
        if self.physical[0] == "no":
            out += f"; NOT PHYSICAL: {self.physical[1]}"
        if self.extrapolated:
            out += "; EXTRAPOLATED: " + "; ".join(self.extrapolated)
        return out


def _uniform(x: FloatArray, scale: float = 1.0) -> bool:
    return bool(np.ptp(x) <= 1e-9 * max(scale, float(np.max(np.abs(x)))))


def _closed_form_settings(program: Any, temperature: float) -> tuple[float, float] | None:
    """``(speed, rotation number)`` when the report's closed form applies, else ``None``."""
    if abs(temperature - CALIBRATION_TEMPERATURE) > 1e-9:
        return None
    if (program.active_material, program.passive_material) != calibrated_materials():
        return None
    if np.max(np.abs(program.path.curvature)) > 1e-9:
        return None
    if program.step_flips:
        return None
    w = program.rotation_number
    if not (_uniform(program.speed) and _uniform(w)):
        return None
    return float(program.speed[0]), float(np.mean(w))


def _stretch(model: FilamentModel, w: float, fraction: float, speed: float, radius: float) -> float:
    """Natural stretch of the centre line of a straight filament (closed form)."""
    active, passive = calibrated_inks()
    section = model.section(active, passive, radius, fraction)
    e_par, e_perp, eps_p = model.strains(np.array([speed]), passive)
    eps_c, _, _ = section.natural_strains(DIRECTOR_HELIX_SENSE * w, e_par, e_perp, eps_p)
    return float(strain_to_stretch(eps_c[0], model.strain_model.measure))


def _helix_values(shape: HelixShape) -> list[float]:
    return [shape.curvature, shape.torsion, shape.radius, shape.pitch, shape.end_to_end_ratio]


def helix_points(shape: HelixShape, length: float, spacing: float) -> FloatArray:
    """Points ``(n, 3)`` (mm) of ``length`` mm of the free helix ``shape``, ~``spacing`` apart."""
    n = max(int(np.ceil(length / spacing)), 2) + 1
    s = np.linspace(0.0, length, n)
    k, t = shape.curvature, shape.torsion
    rate = math.hypot(k, t)
    if rate == 0.0:
        return np.stack([s, 0 * s, 0 * s], axis=1)
    phi = s * rate
    return np.stack(
        [shape.radius * np.cos(phi), shape.radius * np.sin(phi), t / rate**2 * phi], axis=1
    )


def _overlap(shape: HelixShape, heated_length: float, radius: float) -> str:
    """Why this length of the free helix passes through itself ("" if it does not): bent
    tighter than the filament's radius, or parts more than two diameters apart along it closer
    than a diameter (the clearance rule of :func:`rotomorph.simulate.free_shape.min_clearance`).
    """
    from rotomorph.simulate.free_shape import min_clearance

    if shape.curvature * radius > 1.0:
        return (
            f"bent to radius {1 / shape.curvature:.3g} mm, tighter than the filament radius "
            f"{radius:g} mm (contact not modelled)"
        )
    diameter = 2.0 * radius
    spacing = max(radius / 4.0, heated_length / 1500.0)
    clearance = min_clearance(
        helix_points(shape, heated_length, spacing), exclude_arc=2.0 * diameter
    )
    if clearance < diameter - 1e-9:
        return (
            f"parts of it come {clearance:.3g} mm close, less than the filament diameter "
            f"{diameter:g} mm (contact not modelled)"
        )
    return ""


def predict_filament(
    program: Any, name: str = "", *, temperature: float = CALIBRATION_TEMPERATURE
) -> FilamentPrediction:
    """Quick prediction of one printed filament heated to ``temperature`` (°C).

    Parameters
    ----------
    program
        The filament's :class:`~rotomorph.design.program.PrintProgram`.
    name
        Label in the outputs.
    temperature
        Heating temperature (°C).
    """
    from rotomorph.prediction.band import nominal_model

    rng = calibrated_range()
    w_all = program.rotation_number
    settings = {
        "speed_mm_s": [float(program.speed.min()), float(program.speed.max())],
        "rotation_number": [float(w_all.min()), float(w_all.max())],
        "radius_mm": float(program.radius),
        "active_fraction": float(program.active_fraction),
        "temperature_C": float(temperature),
    }
    extrapolated = rng.outside(
        speed=program.speed,
        rotation_number=w_all,
        temperature=temperature,
        radius=float(program.radius),
        active_fraction=float(program.active_fraction),
        materials=(program.active_material, program.passive_material),
    )
    printed = float(program.arc_length[-1])
    radius = float(program.radius)
    fraction = float(program.active_fraction)
    closed = _closed_form_settings(program, temperature)
    if closed is not None:
        v, w = closed

        inks = calibrated_inks()

        def helix(model: FilamentModel) -> FloatArray:
            shape = filament_shapes(
                model, np.array([w]), fraction, speed=v, radius=radius, inks=inks
            )[0]
            return np.array(_helix_values(shape))

        est = with_band(helix, [_UNITS[k] for k in HELIX_QUANTITIES])
        model = nominal_model()
        shape = filament_shapes(model, np.array([w]), fraction, speed=v, radius=radius, inks=inks)[
            0
        ]
        length = printed * _stretch(model, w, fraction, v, radius)
        return _helix_prediction(
            name, "closed form (section + free helix)", est, shape, length, radius, extrapolated,
            settings,
        )  # fmt: skip
    model = nominal_model()
    nat = natural_field(program, None, temperature, model=model)
    try:
        shape = nat.morphology()
    except Exception:  # a varying field: the exact free shape instead
        return _free_prediction(program, name, temperature, extrapolated, settings)

    def field_helix(m: FilamentModel) -> FloatArray:
        return np.array(
            _helix_values(natural_field(program, None, temperature, model=m).morphology())
        )

    est = with_band(field_helix, [_UNITS[k] for k in HELIX_QUANTITIES])
    stretch = float(np.mean(strain_to_stretch(nat.axial_strain, nat.measure)))
    return _helix_prediction(
        name, "closed form (natural field)", est, shape, printed * stretch, radius, extrapolated,
        settings,
    )  # fmt: skip


def _helix_prediction(
    name: str,
    method: str,
    est: list[Estimate],
    shape: HelixShape,
    heated_length: float,
    radius: float,
    extrapolated: list[str],
    settings: dict[str, Any],
) -> FilamentPrediction:
    overlap = _overlap(shape, heated_length, radius)
    physical = (
        ("no", f"the free shape passes through itself: {overlap}")
        if overlap
        else (
            "yes",
            "free filament: zero-energy state (no loads, contact or gravity)",
        )
    )
    turns = heated_length * math.hypot(shape.curvature, shape.torsion) / (2.0 * math.pi)
    settings = {**settings, "heated_length_mm": heated_length, "turns": turns}
    planar_ring = shape.curvature > 0 and handedness(shape.torsion) == "planar"
    return FilamentPrediction(
        name=name,
        method=method,
        quantities=dict(zip(HELIX_QUANTITIES, est, strict=True)),
        morphology="ring" if planar_ring else str(shape.label),
        handedness=handedness(shape.torsion) if shape.curvature > 0 else "",
        physical=physical,
        extrapolated=tuple(extrapolated),
        settings=settings,
    )


def _free_prediction(
    program: Any,
    name: str,
    temperature: float,
    extrapolated: list[str],
    settings: dict[str, Any],
) -> FilamentPrediction:
    from rotomorph.prediction.band import nominal_model
    from rotomorph.simulate.free_shape import min_clearance
    from rotomorph.simulate.validation import end_to_end, free_shape

    def values(model: FilamentModel) -> FloatArray:
        return np.array([end_to_end(free_shape(program, model, temperature), program.points)])

    (ratio,) = with_band(values, ["1"])
    pts = free_shape(program, nominal_model(), temperature)
    diameter = 2.0 * float(program.radius)
    clearance = min_clearance(pts, exclude_arc=2.0 * diameter)
    physical = (
        ("no", f"the free shape passes through itself (clearance {clearance:.3g} mm < diameter "
         f"{diameter:g} mm; contact not modelled)")
        if clearance < diameter
        else ("yes", "free filament: zero-energy state (no loads, contact or gravity)")
    )  # fmt: skip
    return FilamentPrediction(
        name=name,
        method="free shape (zero energy)",
        quantities={"L/L0": ratio},
        morphology="free shape",
        handedness="",
        physical=physical,
        extrapolated=tuple(extrapolated),
        settings=settings,
    )

"""The report's filament rows with their bands in parts (:mod:`rotomorph.simulate.bands`).

* **Closed-form rows** (Janus curvature, L/L0 of rotated filaments): straight filaments of the
  paper's radius, fully actuated, exactly as the calibration sees them. None of the nuisance
  inputs enters (no cell, no flip, no weight; the calibration and these rows use the full
  actuation, so T_NI does not enter either): ``sd_nuisance = 0``.
* **Sinusoids** (Fig. 3C/D): one lattice edge repeated, at the nuisance priors' centres
  (:func:`~rotomorph.simulate.nuisance.nominal_sample`: wavelength = cell size, amplitude a
  quarter of it, flips of the active side over the flip length) heated to 175 °C with the
  sample's T_NI; the nuisance band from a Latin hypercube of :data:`SINUSOID_SAMPLES` samples.
  A finite flip converges only as O(h) in the flip zones, so the rows with flips are computed
  at :data:`FLIP_SPACINGS` and each sample at :data:`SAMPLE_SPACINGS` with Richardson's
  order-1 extrapolation (its residual error is far below the spread over the priors); a
  sample whose free shape passes through itself is solved with self-contact, at
  :data:`SAMPLE_CONTACT_SPACING` for the calibration secants and the coarser
  :data:`NUISANCE_CONTACT_SPACING` for the nuisance samples.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.materials.calibrated_range import calibrated_range
from rotomorph.materials.inference import Fit
from rotomorph.materials.material import Material, get_material
from rotomorph.materials.measurements import load_table
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.rod.model import Model
from rotomorph.simulate.bands import Band, finish_row
from rotomorph.simulate.convergence import at_two_resolutions
from rotomorph.simulate.free_shape import free_equilibrium, min_clearance
from rotomorph.simulate.nuisance import NuisanceSample, latin_hypercube, nominal_sample

__all__ = [
    "FLIP_SPACINGS",
    "SAMPLE_SPACINGS",
    "SINUSOID_SAMPLES",
    "closed_form_band",
    "sinusoid_program",
    "sinusoid_ratio",
    "sinusoid_rows",
]

#: Latin-hypercube samples of the nuisance priors per sinusoid row.
SINUSOID_SAMPLES = 12
#: Node spacings (mm) of a counted sinusoid with finite flips (O(h) in the flip zones).
FLIP_SPACINGS = (0.0125, 0.00625)
#: Node spacings (mm) of step flips (the flip is placed to within half a segment).
STEP_SPACINGS = (0.1, 0.05)
#: Node spacings (mm) of each nuisance and calibration sample (order-1 extrapolated).
SAMPLE_SPACINGS = (0.025, 0.0125)
#: Node spacings (mm) of a counted sinusoid that touches itself (rod solver with self-contact;
#: about 7 and 19 s of CPU each).
CONTACT_SPACINGS = (0.025, 0.0125)
#: Node spacing (mm) of a calibration sample that touches itself (its error, about 1 % of the
#: ratio, is far below the spread over the priors).
SAMPLE_CONTACT_SPACING = 0.025
#: Node spacing (mm) of a nuisance sample that touches itself: coarser, to keep the report's
#: CPU in bounds (a few per cent of the ratio, still far below the spread over the priors, and
#: the same for every sample).
NUISANCE_CONTACT_SPACING = 0.05
#: Heating steps of a self-contact solve.
CONTACT_STEPS = 8
#: Periods of every sinusoid (the end-to-end ratio of a long periodic filament hardly depends
#: on it; the design file prints 4).
PERIODS = 4
SPEED = 3.0
TEMPERATURE = 175.0


def with_transition(transition: float) -> dict[str, Material]:
    """Materials overrides: the active ink with T_NI = ``transition`` (°C)."""
    lce = get_material("lce")
    return {"lce": dataclasses.replace(lce, transition_temperature=float(transition))}


@lru_cache(maxsize=64)
def sinusoid_program(side: str, sample: NuisanceSample, spacing: float) -> Any:
    """The printed sinusoid of ``sample``'s geometry with the active half ``side``."""
    from rotomorph.io.designfile import Filament

    segment = {
        "kind": "sinusoid",
        "amplitude": sample.amplitude,
        "wavelength": sample.cell_size,
        "periods": PERIODS,
    }
    return Filament(
        name="expanding" if side == "outer" else "contracting",
        speed=SPEED,
        active_side=side,  # type: ignore[arg-type]
        flip_length=sample.flip_length,
        spacing=spacing,
        segments=[segment],  # type: ignore[list-item]
    ).to_program()


@lru_cache(maxsize=256)
def _shape(side: str, model: FilamentModel, sample: NuisanceSample, spacing: float) -> FloatArray:
    prog = sinusoid_program(side, sample, spacing)
    field = natural_field(prog, with_transition(sample.transition), TEMPERATURE, model=model)
    x = free_equilibrium(Model.from_field(prog.points, field))
    x.setflags(write=False)
    return x


def sinusoid_ratio(
    side: str, model: FilamentModel, sample: NuisanceSample, spacing: float
) -> float:
    """End-to-end ratio of the heated sinusoid (zero-energy free shape) at node spacing h."""
    x = _shape(side, model, sample, spacing)
    p = sinusoid_program(side, sample, spacing).points
    return float(np.linalg.norm(x[-1] - x[0]) / np.linalg.norm(p[-1] - p[0]))


def self_clearance(
    side: str, model: FilamentModel, sample: NuisanceSample, spacing: float
) -> float:
    """Smallest distance (mm) between non-neighbouring parts of the free heated shape, on a
    0.05 mm subsample; below the filament diameter the free shape passes through itself."""
    shape = _shape(side, model, sample, spacing)
    radius = float(sinusoid_program(side, sample, spacing).radius)
    stride = max(1, round(0.05 / spacing))
    return min_clearance(shape[::stride], exclude_arc=4.0 * radius)


def contact_shape(
    side: str, model: FilamentModel, sample: NuisanceSample, spacing: float
) -> tuple[float, FloatArray]:
    """End-to-end ratio and final vertices ``(N, 3)`` (mm) of the heated sinusoid with
    self-contact (the rod solver over a :data:`CONTACT_STEPS`-step ramp, filaments touching
    instead of passing through; cached on disk)."""
    from rotomorph.contact import Contact
    from rotomorph.simulate.cache import disk_cached
    from rotomorph.simulate.filament import simulate_filament

    prog = sinusoid_program(side, sample, spacing)

    def run() -> tuple[float, FloatArray]:
        sim = simulate_filament(
            prog,
            steps=CONTACT_STEPS,
            temperature=TEMPERATURE,
            materials=with_transition(sample.transition),
            model=model,
            contact=Contact(radius=float(prog.radius)),
        )
        return float(sim.final_ratio), np.asarray(sim.positions[-1], dtype=float)

    key = repr((side, model, sample.key(), spacing, CONTACT_STEPS))
    return disk_cached("sinusoid_contact", key, run)


def contact_ratio(side: str, model: FilamentModel, sample: NuisanceSample, spacing: float) -> float:
    """End-to-end ratio of :func:`contact_shape`."""
    return contact_shape(side, model, sample, spacing)[0]


def heated_shape(side: str, model: FilamentModel, sample: NuisanceSample) -> FloatArray:
    """The heated sinusoid the counted row measures (``(N, 3)``, mm): the free shape at the
    finer spacing, or the self-contact solve where the free shape passes through itself."""
    spacings = FLIP_SPACINGS if sample.flip_length > 0 else STEP_SPACINGS
    radius = float(sinusoid_program(side, sample, spacings[1]).radius)
    if self_clearance(side, model, sample, spacings[1]) < 2.0 * radius:
        return contact_shape(side, model, sample, CONTACT_SPACINGS[1])[1]
    return np.asarray(_shape(side, model, sample, spacings[1]))


def _sample_ratio(
    side: str, model: FilamentModel, sample: NuisanceSample, contact_spacing: float
) -> float:
    """One sample's ratio: the free shape, order-1 Richardson-extrapolated from
    :data:`SAMPLE_SPACINGS` (step flips: the finer value, already converged); where the free
    shape passes through itself, the self-contact solve at ``contact_spacing`` (mm)."""
    h, h2 = SAMPLE_SPACINGS
    radius = float(sinusoid_program(side, sample, h2).radius)
    if self_clearance(side, model, sample, h2) < 2.0 * radius:
        return contact_ratio(side, model, sample, contact_spacing)
    fine = sinusoid_ratio(side, model, sample, h2)
    if sample.flip_length == 0.0:
        return fine
    return 2.0 * fine - sinusoid_ratio(side, model, sample, h)


def closed_form_band(row: dict[str, Any], sd_prior: float | None) -> dict[str, Any]:
    """A closed-form row with its band: calibration (and its prior part), no nuisance, the
    section mesh's discretisation error. Inside the calibrated range by construction."""
    band = Band(
        calibration=row["predicted_sd"],
        calibration_prior=sd_prior,
        nuisance=0.0,
        numerical=row["discretisation_error"] or 0.0,
    )
    return finish_row(row, band, extrapolated=[])


def sinusoid_rows(
    full: Fit, model: FilamentModel, *, samples: int = SINUSOID_SAMPLES
) -> list[dict[str, Any]]:
    """The two counted sinusoid rows at the nuisance priors' centres, with their bands.

    ``full`` is the calibration on all filament groups, ``model`` its model on the report's
    section mesh.
    """
    from rotomorph.simulate.validation import at_resolution, row

    table = load_table("sinusoid_end_to_end")
    nominal = nominal_sample()
    spacings = FLIP_SPACINGS if nominal.flip_length > 0 else STEP_SPACINGS
    lhs = latin_hypercube(samples, seed=0)
    rows = []
    for i, side in enumerate(("outer", "inner")):
        radius = float(sinusoid_program(side, nominal, spacings[1]).radius)
        clearance = self_clearance(side, model, nominal, spacings[1])
        touching = clearance < 2.0 * radius
        if touching:  # the free shape passes through itself: resolve the self-contact
            spacings_used = CONTACT_SPACINGS
            res = at_two_resolutions(
                lambda h, s=side: contact_ratio(s, model, nominal, h),  # type: ignore[misc]
                CONTACT_SPACINGS[0],
            )
        else:
            spacings_used = spacings
            res = at_two_resolutions(
                lambda h, s=side: sinusoid_ratio(s, model, nominal, h),  # type: ignore[misc]
                spacings[0],
            )

        def ratio(m: FilamentModel, s: str = side) -> FloatArray:
            return np.array([_sample_ratio(s, at_resolution(m), nominal, SAMPLE_CONTACT_SPACING)])

        # one-sided secants where each evaluation is a contact solve
        _, sd_cal, sd_prior = full.propagate_parts(ratio, central=not touching)
        values = np.array([_sample_ratio(side, model, s, NUISANCE_CONTACT_SPACING) for s in lhs])
        how = (
            f"its free shape passes through itself (clearance {clearance:.2f} mm < the "
            f"{2 * radius:g} mm diameter), so it is solved with self-contact (rod solver, "
            f"{CONTACT_STEPS}-step ramp)"
            if touching
            else f"zero-energy free shape (self-clearance {clearance:.2f} mm)"
        )
        r = row(
            "sinusoid_end_to_end_ratio",
            table.condition[i],
            float(table.value[i]),
            float(table.spread[i]),
            res.value,
            predicted_sd=float(sd_cal[0]),
            other=res.coarse,
            disc_error=res.error,
            resolution=spacings_used,
            resolution_unit="node spacing (mm)",
            calibrated_without="sinusoid_end_to_end (never fitted)",
            unit="1",
            figure="fig3cd_sinusoids.png",
            note=f"active {side}, at the nuisance priors' centres: wavelength = cell size "
            f"{nominal.cell_size:.3g} mm, A = {nominal.amplitude:.3g} mm (A/l = 0.25, the "
            f"authors' input), {PERIODS} periods, pi flips over {nominal.flip_length:.3g} mm, "
            f"T_NI {nominal.transition:.3g} °C; {how}; over {samples} Latin-hypercube "
            f"samples of the priors it ranges {values.min():.3g}-{values.max():.3g}",
            self_contact=bool(touching),
            contact_resolved=bool(touching),
            nuisance_samples=[round(float(v), 5) for v in values],
        )
        extrapolated = calibrated_range().outside(
            speed=SPEED, rotation_number=0.0, temperature=TEMPERATURE, radius=radius
        )
        band = Band(
            calibration=float(sd_cal[0]),
            calibration_prior=float(sd_prior[0]),
            nuisance=float(np.std(values, ddof=1)),
            numerical=res.error,
        )
        rows.append(finish_row(r, band, extrapolated=extrapolated))
    return rows

"""Lattices of a nuisance sample, their contact-resolved ramps, and the lattice rows' bands.

A :class:`~rotomorph.simulate.nuisance.NuisanceSample` fixes what the paper does not give: the
cell size l and amplitude l/4, the in-plane filament width (the lattice's filament radius is
half of it: the Janus section's lever arm in the plane and the contact radius), T_NI (the
active ink with that transition), the filament and bath densities (the buoyant weight along
the ramp). Ideal step flips are kept: a lattice edge of 10-40 ghost nodes (node spacing
0.3-1 mm) cannot represent a flip shorter than 0.5 mm; the flip's effect is measured on the
single sinusoids. Every ramp is cached on disk (:mod:`rotomorph.simulate.cache`) under the
sample's exact values.

The nuisance band of a lattice number is the spread of it over a Latin hypercube of
:data:`LATTICE_SAMPLES` samples, each ramped as the report's counted state is at its coarser
resolution (contact, bath floor, buoyant weight, the lowest-energy branch rule) but without
the path check (:func:`area_band`, :func:`sign_samples`); the weight's delay of lift-off is
bisected at the filament-density prior's two ends (:func:`lift_off_delays`). These ramps are
too many for ``rotomorph paper`` on a small machine, so ``benchmarks/lattice_nuisance.py``
runs them and prints what they give; the report's lattice bands do not include them and say
so.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from typing import Any

import numpy as np

from rotomorph.errors import RotomorphError
from rotomorph.materials.natural import FilamentModel
from rotomorph.simulate.cache import disk_cached
from rotomorph.simulate.nuisance import NuisanceSample, latin_hypercube, nominal_sample

__all__ = [
    "BATH_EXPANSION",
    "LATTICE_SAMPLES",
    "area_band",
    "heat_sample",
    "lattice_samples",
    "lift_off_delays",
    "sample_buoyancy",
    "sample_lattice",
    "sign_samples",
    "transition_material",
]

logger = logging.getLogger(__name__)

#: Latin-hypercube samples per lattice row (full report; quick mode: :data:`QUICK_SAMPLES`).
LATTICE_SAMPLES = 8
QUICK_SAMPLES = 4
#: Seed of the lattices' Latin hypercube (the sinusoids use 0).
LATTICE_SEED = 1
#: Volumetric thermal expansion of the bath oil (1/K; the bath table's PDMS data sheets).
BATH_EXPANSION = 9.6e-4


def transition_material(transition: float) -> str:
    """Name of the active ink with T_NI = ``transition`` (°C), registered on first use."""
    from rotomorph.materials.material import get_material, register_material

    name = f"lce-tni-{transition:.4f}".replace(".", "p")
    try:
        get_material(name)
    except RotomorphError:
        base = get_material("lce")
        register_material(
            dataclasses.replace(base, name=name, transition_temperature=float(transition))
        )
    return name


def sample_lattice(pattern: str, n: int, ghosts: int, sample: NuisanceSample | None = None) -> Any:
    """The printed n × n lattice of ``sample`` (default: the priors' centres)."""
    from rotomorph.design.lattices import sinusoidal_lattice

    s = nominal_sample() if sample is None else sample
    return sinusoidal_lattice(
        n,
        s.cell_size,
        s.amplitude,
        ghosts,
        pattern,  # type: ignore[arg-type]
        radius=0.5 * s.filament_width,
        active_material=transition_material(s.transition),
    )


def sample_buoyancy(lattice: Any, sample: NuisanceSample) -> Callable[[float], Any]:
    """``T ↦`` the lattice's buoyant weight with the sample's densities (the bath expanding
    by :data:`BATH_EXPANSION` per K from 25 °C)."""
    from rotomorph.lattice.heating import lattice_gravity

    def at(temperature: float) -> Any:
        bath = sample.bath_density / (1.0 + BATH_EXPANSION * (float(temperature) - 25.0))
        return lattice_gravity(lattice, fluid_density=bath, density=sample.filament_density)

    return at


def heat_sample(
    pattern: str,
    n: int,
    ghosts: int,
    steps: int,
    model: FilamentModel,
    sample: NuisanceSample | None = None,
    *,
    contact: bool = False,
    branch: str = "lowest",
    lift_off_tolerance: float | None = None,
    path_check: int = 1,
) -> tuple[Any, Any, str]:
    """(lattice, HeatingResult or None, reason) of one ramp 25 → 175 °C, cached on disk.

    ``contact``: self-contact and the bath floor under the sample's buoyant weight, with the
    ``branch`` rule, optional lift-off bisection and path check (``heat_lattice``).
    """
    from rotomorph.lattice import actuation as modes
    from rotomorph.lattice.heating import heat_lattice

    s = nominal_sample() if sample is None else sample
    lattice = sample_lattice(pattern, n, ghosts, s)
    mode = getattr(modes, "ProgramActuation", modes.ThermalActuation)
    try:
        actuation = mode(filament_model=model)
        key = repr(
            (pattern, n, ghosts, steps, actuation, s.key())
            + (("bath floor", branch, lift_off_tolerance, path_check) if contact else ())
        )
        extra: dict[str, Any] = {}
        if contact:
            extra = {
                "floor": True,
                "gravity": sample_buoyancy(lattice, s),
                "branch": branch,
                "lift_off_tolerance": lift_off_tolerance,
                "path_check": path_check,
            }
        result = disk_cached(
            "heat_lattice_sample",
            key,
            lambda: heat_lattice(lattice, actuation=actuation, steps=steps, **extra),
        )
        return lattice, result, ""
    except RotomorphError as err:
        logger.warning("lattice %s: %s", pattern, err)
        return lattice, None, f"lattice solver failed: {' '.join(str(err).split())[:160]}"


def lattice_samples(
    pattern: str,
    n: int,
    ghosts: int,
    steps: int,
    model: FilamentModel,
    *,
    contact: bool,
    count: int,
) -> list[tuple[NuisanceSample, Any]]:
    """The Latin-hypercube samples of a lattice row and their ramps (``None`` where one
    failed)."""
    out = []
    for s in latin_hypercube(count, seed=LATTICE_SEED):
        _, res, _ = heat_sample(pattern, n, ghosts, steps, model, s, contact=contact)
        out.append((s, res))
    return out


def spread(values: list[float | None]) -> float | None:
    """Sample standard deviation (``None`` with fewer than two finite values)."""
    v = np.asarray([x for x in values if x is not None and np.isfinite(x)], dtype=float)
    return float(np.std(v, ddof=1)) if len(v) >= 2 else None


def area_band(
    fit: Any,
    pattern: str,
    n: int,
    ghosts: int,
    steps: int,
    model: FilamentModel,
    *,
    contact: bool,
    count: int,
) -> tuple[float | None, float | None, float | None, list[float | None]]:
    """(sd_calibration, its prior-held part, sd_nuisance, the samples' areas) of a lattice's
    final area ratio (module docstring). ``fit`` is the calibration the lattice is predicted
    with, ``model`` its model on the report's section mesh."""
    from rotomorph.simulate.validation import at_resolution

    samples = lattice_samples(pattern, n, ghosts, steps, model, contact=contact, count=count)
    values = [None if r is None else float(r.final_area_ratio) for _, r in samples]

    def area(m: FilamentModel) -> Any:
        _, res, _ = heat_sample(pattern, n, ghosts, steps, at_resolution(m), contact=contact)
        return np.array([np.nan if res is None else res.final_area_ratio])

    _, sd, sd_prior = fit.propagate_parts(area, central=False)
    cal = float(sd[0]) if np.isfinite(sd[0]) else None
    prior = float(sd_prior[0]) if np.isfinite(sd_prior[0]) else None
    return cal, prior, spread(values), values


def sign_samples(
    pattern: str,
    n: int,
    ghosts: int,
    steps: int,
    model: FilamentModel,
    *,
    contact: bool,
    count: int,
) -> list[float | None]:
    """The Gaussian-curvature sign at the end of each Latin-hypercube sample's ramp."""
    samples = lattice_samples(pattern, n, ghosts, steps, model, contact=contact, count=count)
    return [None if r is None else float(r.gaussian_sign[-1]) for _, r in samples]


#: Filament densities (g/cm³) at which the lift-off delay is also bisected: the prior's ends
#: (the bath at its prior's centre), so the delay is given as a function of ρ − ρ_bath.
def _density_ends() -> tuple[float, float]:
    from rotomorph.simulate.nuisance import NUISANCE_PRIORS

    p = NUISANCE_PRIORS["filament_density"]
    return p.low, p.high


def buoyant_density(sample: NuisanceSample, temperature: float) -> float:
    """ρ − ρ_bath (g/cm³) of ``sample`` at ``temperature`` (°C)."""
    bath = sample.bath_density / (1.0 + BATH_EXPANSION * (float(temperature) - 25.0))
    return sample.filament_density - bath


def lift_off_delays(
    pattern: str, n: int, ghosts: int, steps: int, model: FilamentModel, tolerance: float
) -> list[dict[str, float]]:
    """Lift-off and weightless buckling, bisected, at the filament density prior's two ends:
    ``[{"buoyant_density_175C", "lift_off_C", "buckling_C", "delay_C"}, ...]`` (entries whose
    lattice never leaves the floor are left out)."""
    out = []
    base = nominal_sample()
    for rho in _density_ends():
        s = dataclasses.replace(base, filament_density=rho)
        _, res, _ = heat_sample(
            pattern, n, ghosts, steps, model, s, contact=True, lift_off_tolerance=tolerance
        )
        if res is None or res.lift_off_bracket is None or res.buckling_bracket is None:
            continue
        lift = 0.5 * sum(res.lift_off_bracket)
        buckle = 0.5 * sum(res.buckling_bracket)
        out.append(
            {
                "buoyant_density_175C": round(buoyant_density(s, 175.0), 4),
                "lift_off_C": round(lift, 2),
                "buckling_C": round(buckle, 2),
                "delay_C": round(lift - buckle, 2),
            }
        )
    return out

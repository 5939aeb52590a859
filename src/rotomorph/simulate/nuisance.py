r"""Inputs the paper does not give, as stated priors: the nuisance parameters of every prediction.

The paper's lattice and sinusoid predictions need numbers it does not report. Each is a
uniform prior on a stated range, with the argument for the range next to it
(:data:`NUISANCE_PRIORS`); predictions are made at the priors' centres and the priors are
propagated into their bands (:mod:`rotomorph.simulate.nuisance_filaments`,
:mod:`rotomorph.simulate.nuisance_lattices`). The ranges were set from
the paper's text alone, before any prediction was computed with them, and are never moved to
change a score.

=====================  ===========  ==============================================================
input                  range        argument
=====================  ===========  ==============================================================
``cold_opening``       3.5–5.0 mm   Fig. 5: 3.5 mm rods enter, and are released by, the cold
                                    contracting gripper's cells; 5 mm spheres are caught by the
                                    cold expanding filter. The printed cell's clear opening lies
                                    between them, if the Fig. 5 lattices have the cells of Figs.
                                    3-4 (the paper describes one lattice design and gives no
                                    other dimensions).
``filament_width``     0.6–1.0 mm   in-plane width of a cured, stacked lattice filament: the
                                    single filament from the 1 mm nozzle is ~600 µm wide
                                    (paper); fused layers may spread, at most to the nozzle's
                                    1 mm outlet (assumption).
``flip_length``        0–0.47 mm    arc length over which the active side turns by π: the paper
                                    gives none; its fastest rotation, ω* = 2 at 3 mm/s
                                    (ω = ω* v / R = 20 rad/s), turns π in π v / ω = 0.47 mm; an
                                    ideal step is the other end.
``filament_density``   1.05–1.25    g/cm³, the inks' mean: not in the paper. Rule of mixtures of
                                    the stated compositions with assumed component densities
                                    (acrylate monomers and oligomers 0.9-1.1, the LC diacrylate
                                    about 1.2, fumed silica 2.2 g/cm³; 5 and 17 wt % silica).
``bath_density``       0.960–0.971  g/cm³ at 25 °C: the paper's silicone oil has no stated grade;
                                    polydimethylsiloxane fluids of 50-1000 cSt (data sheets, the
                                    bath table's source), expanding 9.6e-4 per K.
``transition``         60–130 °C    T_NI, measured by DSC but not stated: cooling to 50 °C
                                    releases the gripper's rods (so T_NI lies at least one
                                    transition width, 10 °C, above 50 °C) and the bulk inks'
                                    response is complete by 150 °C (so T_NI lies at least two
                                    widths below it).
=====================  ===========  ==============================================================

The lattice's **cell size** l (node spacing) follows from the first two: with the sine
amplitude A = l/4 (the authors' published simulation input: a quarter of the cell, one period
per edge, see ``docs/published-simulation.md``) the printed cell's clear opening is
:data:`OPENING_PER_CELL` · l − w (the largest circle inside the cell's loop of centre lines,
:func:`rotomorph.analysis.aperture.passing_diameters`, minus the filament width), so
l = (opening + w) / 0.655 ranges over 6.3–9.2 mm (7.7 mm at the centres). Four such cells span
25–37 mm, one to one and a half of the 25 mm scale bars the lattices are photographed under —
consistent with, not set by, the photographs. The single sinusoidal filaments of Fig. 3C/D are
taken as one lattice edge repeated: wavelength l, amplitude l/4 (their 1 mm scale bars suggest
views of about one period).

Not nuisance parameters: A/l = 0.25 (from the authors' input, :data:`AMPLITUDE_RATIO`), the
filament radius of the calibration filaments (0.3 mm, the paper's ~600 µm) and the print
speed and rotation of every sample (the paper's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

__all__ = [
    "AMPLITUDE_RATIO",
    "NUISANCE_PRIORS",
    "OPENING_PER_CELL",
    "NuisanceSample",
    "Prior",
    "latin_hypercube",
    "nominal_sample",
]

#: Sine amplitude over cell size of the lattice edges and sinusoids: the authors' published
#: simulation input (``A = 0.25`` of the unit cell, one period per edge).
AMPLITUDE_RATIO = 0.25
#: Clear opening of a printed cell per unit cell size, for filaments of zero width: twice the
#: largest circle inside the loop of printed centre lines of a cell with A/l = 0.25 (converged
#: polyline limit; a test recomputes it with :func:`rotomorph.analysis.aperture.passing_diameters`).
OPENING_PER_CELL = 0.655


@dataclass(frozen=True)
class Prior:
    """A uniform prior on ``[low, high]`` with its unit and the argument for its range."""

    name: str
    low: float
    high: float
    unit: str
    source: str

    @property
    def centre(self) -> float:
        """Midpoint of the range (the nominal value predictions are made at)."""
        return 0.5 * (self.low + self.high)

    @property
    def sd(self) -> float:
        """Standard deviation of the uniform prior, (high − low)/√12."""
        return (self.high - self.low) / math.sqrt(12.0)

    def at(self, u: float) -> float:
        """The value at quantile ``u`` ∈ [0, 1]."""
        return self.low + float(u) * (self.high - self.low)

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "name": self.name,
            "distribution": "uniform",
            "range": [self.low, self.high],
            "nominal": self.centre,
            "unit": self.unit,
            "source": self.source,
        }


#: The stated priors, by name (module docstring).
NUISANCE_PRIORS: dict[str, Prior] = {
    p.name: p
    for p in (
        Prior(
            "cold_opening",
            3.5,
            5.0,
            "mm",
            "Fig. 5: 3.5 mm rods enter and leave the cold gripper's cells, 5 mm spheres are "
            "caught by the cold filter (assumed: the Fig. 5 lattices have the cells of Figs. 3-4)",
        ),
        Prior(
            "filament_width",
            0.6,
            1.0,
            "mm",
            "the paper's ~600 um filament from a 1 mm nozzle; stacked layers may spread, at most "
            "to the nozzle's width (assumption)",
        ),
        Prior(
            "flip_length",
            0.0,
            0.47,
            "mm",
            "not given; the paper's fastest rotation (omega* = 2 at 3 mm/s, 20 rad/s) turns the "
            "active side by pi within 0.47 mm; an ideal step is the other end",
        ),
        Prior(
            "filament_density",
            1.05,
            1.25,
            "g/cm3",
            "not given; rule of mixtures of the inks' stated compositions with assumed "
            "component densities (acrylates 0.9-1.1, LC diacrylate ~1.2, fumed silica 2.2)",
        ),
        Prior(
            "bath_density",
            0.960,
            0.971,
            "g/cm3 at 25 C",
            "not given (silicone oil of unstated grade); PDMS fluids of 50-1000 cSt, data "
            "sheets; thermal expansion 9.6e-4 1/K",
        ),
        Prior(
            "transition",
            60.0,
            130.0,
            "C",
            "T_NI measured by DSC but not stated; the rods are released on cooling to 50 C "
            "(T_NI >= 50 C + one transition width) and the inks' response is complete by "
            "150 C (T_NI <= 150 C - two widths)",
        ),
    )
}


@dataclass(frozen=True)
class NuisanceSample:
    """One value of every nuisance input (units as :data:`NUISANCE_PRIORS`)."""

    cold_opening: float
    filament_width: float
    flip_length: float
    filament_density: float
    bath_density: float
    transition: float

    @property
    def cell_size(self) -> float:
        """Lattice node spacing l = (opening + width) / :data:`OPENING_PER_CELL` (mm)."""
        return (self.cold_opening + self.filament_width) / OPENING_PER_CELL

    @property
    def amplitude(self) -> float:
        """Sine amplitude A = :data:`AMPLITUDE_RATIO` · l (mm)."""
        return AMPLITUDE_RATIO * self.cell_size

    def record(self) -> dict[str, float]:
        """JSON-able form, the derived cell size and amplitude included."""
        out = {f.name: round(float(getattr(self, f.name)), 6) for f in fields(self)}
        out["cell_size"] = round(self.cell_size, 6)
        out["amplitude"] = round(self.amplitude, 6)
        return out

    def key(self) -> str:
        """Exact text of the values (cache keys)."""
        return repr(tuple(float(getattr(self, f.name)) for f in fields(self)))


def nominal_sample() -> NuisanceSample:
    """Every input at its prior's centre."""
    return NuisanceSample(**{name: p.centre for name, p in NUISANCE_PRIORS.items()})


def latin_hypercube(count: int, seed: int = 0) -> list[NuisanceSample]:
    """``count`` samples of the priors stratified by a Latin hypercube (McKay, Beckman &
    Conover, *Technometrics* 21, 239 (1979)): every input's range is cut into ``count`` equal
    strata and each stratum is used exactly once, at its centre, the strata of the inputs
    paired by independent seeded permutations (deterministic for a given ``seed``).

    Parameters
    ----------
    count
        Number of samples (>= 2).
    seed
        Seed of the permutations.
    """
    if int(count) != count or count < 2:
        raise ValueError(f"latin_hypercube.count must be an integer >= 2; got {count}")
    rng = np.random.default_rng(seed)
    strata = (np.arange(count) + 0.5) / count
    columns = {name: strata[rng.permutation(count)] for name in NUISANCE_PRIORS}
    return [
        NuisanceSample(**{n: p.at(columns[n][i]) for n, p in NUISANCE_PRIORS.items()})
        for i in range(count)
    ]


def priors_record() -> list[dict[str, Any]]:
    """Every prior as JSON (with the derived cell size's range)."""
    out = [p.record() for p in NUISANCE_PRIORS.values()]
    o, w = NUISANCE_PRIORS["cold_opening"], NUISANCE_PRIORS["filament_width"]
    out.append(
        {
            "name": "cell_size",
            "distribution": "derived: (cold_opening + filament_width) / 0.655",
            "range": [
                round((o.low + w.low) / OPENING_PER_CELL, 4),
                round((o.high + w.high) / OPENING_PER_CELL, 4),
            ],
            "nominal": round(nominal_sample().cell_size, 4),
            "unit": "mm",
            "source": "printed cell opening = 0.655 l - w for A/l = 0.25 (the authors' input)",
        }
    )
    return out

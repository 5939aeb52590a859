"""Lattices that heat into expanding or contracting sheets, domes and saddles.

:mod:`~rotomorph.lattice.model` builds the rod model of a printed
:class:`~rotomorph.design.lattices.Lattice`, :mod:`~rotomorph.lattice.actuation` maps a ramp
parameter to natural values (the paper's recipe under its readings, and a physical temperature
mode), :mod:`~rotomorph.lattice.heating` follows the ramp by quasi-static continuation and
measures area, Gaussian curvature and edge strains.
"""

from rotomorph.lattice.actuation import (
    ACTUATIONS,
    Actuation,
    AdditiveCurvature,
    CurvatureScaling,
    ThermalActuation,
    get_actuation,
)
from rotomorph.lattice.heating import (
    HeatingResult,
    free_edge_ratio,
    heat_lattice,
    lattice_gravity,
    perturbed_state,
)
from rotomorph.lattice.model import LatticeModel, edge_model, lattice_model

__all__ = [
    "ACTUATIONS",
    "Actuation",
    "AdditiveCurvature",
    "CurvatureScaling",
    "HeatingResult",
    "LatticeModel",
    "ThermalActuation",
    "edge_model",
    "free_edge_ratio",
    "get_actuation",
    "heat_lattice",
    "lattice_gravity",
    "lattice_model",
    "perturbed_state",
]

"""What a design's ``[contact]`` table turns into for a run: contact settings, the bath floor
and the buoyant weight, plus the record of those choices for the run's outputs.

The floor lies just below the printed structure (:meth:`rotomorph.contact.Floor.under`: the
lowest centre line 1.005 r above it, as a filament printed on the substrate rests); the
buoyant line weight is (ρ_filament − ρ_bath) g A with ρ_filament the inks' densities
weighted by the section's active share, and ρ_bath the bath fluid's density at every
temperature of the heating ramp (:func:`rotomorph.materials.bath.bath_density`, data and source
in the bath-fluid table): the hot oil is lighter, so the net weight grows as the bath heats.
The weight is that of the printed filament (:class:`rotomorph.solve.loads.Gravity`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from rotomorph.contact import Contact, Floor
from rotomorph.materials.bath import bath_density, bath_fluids
from rotomorph.materials.material import get_material
from rotomorph.materials.parameter_set import MaterialSet
from rotomorph.solve.loads import Gravity, Loads

__all__ = ["filament_surroundings", "lattice_surroundings", "surroundings_record"]


def _density(
    active: str, passive: str, active_fraction: float, materials: MaterialSet | None = None
) -> float:
    """Section density (g/cm³): the inks' densities by area share (1.1 where none is given),
    the inks of ``materials`` (the design's materials file) or registered ones."""
    find = get_material if materials is None else materials.material
    rho_a = find(active).density or 1.1
    rho_p = find(passive).density or 1.1
    return float(active_fraction * rho_a + (1.0 - active_fraction) * rho_p)


def filament_surroundings(
    contact: Any, program: Any, filament: Any, materials: MaterialSet | None = None
) -> tuple[Contact | None, Callable[[float], Loads] | None]:
    """Contact settings of one filament and its loads as a function of the bath temperature
    (°C) (``None, None`` without ``[contact]``; loads ``None`` without gravity).

    Parameters
    ----------
    contact
        The design's ``contact`` table (:class:`rotomorph.io.designfile.ContactModel`) or None.
    program
        The filament's print program (vertices, radius).
    filament
        The filament's design entry (materials, active fraction).
    materials
        The design's materials file (``None``: registered materials).
    """
    if contact is None:
        return None, None
    radius = float(program.radius)
    obstacles = (Floor.under(program.points, radius),) if contact.floor else ()
    settings = Contact(
        radius=radius,
        obstacles=obstacles,
        self_contact=contact.self_contact,
        friction=contact.friction,
    )
    if not contact.gravity:
        return settings, None
    density = _density(
        filament.active_material, filament.passive_material, filament.active_fraction, materials
    )
    area, bath = np.pi * radius**2, str(contact.bath)

    def loads(temperature: float) -> Loads:
        fluid = bath_density(bath, temperature)
        return Loads(gravity=Gravity(density=density, area=area, fluid_density=fluid))

    return settings, loads


def lattice_surroundings(
    contact: Any,
    lattice: Any,
    temperature: float,
    *,
    ramp_in_temperature: bool = False,
    materials: MaterialSet | None = None,
) -> dict[str, Any]:
    """Keyword arguments of :func:`rotomorph.lattice.heating.heat_lattice` for ``[contact]``
    (empty without it): ``contact``, ``floor``, ``gravity``, ``friction``, ``branch``,
    ``path_check``. The buoyant weight (the inks of ``materials``, the design's materials
    file, or registered ones) is that in the bath at ``temperature`` (°C), or, with
    ``ramp_in_temperature`` (a ramp whose parameter is the temperature), at every ramp
    temperature (:func:`rotomorph.lattice.heating.lattice_buoyancy`)."""
    if contact is None:
        return {}
    from rotomorph.lattice.admissibility import lattice_stack  # lattice-only
    from rotomorph.lattice.heating import lattice_buoyancy  # lattice-only

    kwargs: dict[str, Any] = {
        # the printed stack's layers touch, one capsule each (docs/contact.md)
        "contact": Contact(
            radius=lattice.radius, self_contact=contact.self_contact, stack=lattice_stack(lattice)
        ),
        "floor": bool(contact.floor),
        "friction": float(contact.friction),
        "branch": str(contact.branch),
        "path_check": int(contact.path_check),
    }
    if contact.gravity:
        density = None  # registered inks: the lattice layer's own look-up
        if materials is not None:  # the lattice's two inks, as lattice_gravity averages them
            density = _density(lattice.active_material, lattice.passive_material, 0.5, materials)
        weight = lattice_buoyancy(lattice, bath=contact.bath, density=density)
        kwargs["gravity"] = weight if ramp_in_temperature else weight(temperature)
    return kwargs


def surroundings_record(
    contact: Any, temperature: float, *, along_ramp: bool = False, lattice: bool = True
) -> dict[str, Any] | None:
    """What the run assumed about its surroundings, for ``summary.json`` and the HDF5 file;
    ``along_ramp``: the buoyancy followed the bath density over the temperature ramp (the
    density recorded is the one at ``temperature``, the end of the ramp); ``lattice``: the
    lattice-only choices (``branch``, ``path_check``) were applied and are recorded."""
    if contact is None:
        return None
    record: dict[str, Any] = {
        "self_contact": bool(contact.self_contact),
        "floor": bool(contact.floor),
        "gravity": bool(contact.gravity),
        "friction": float(contact.friction),
    }
    if lattice:
        record.update(branch=str(contact.branch), path_check=int(contact.path_check))
    if contact.gravity:
        fluid = bath_fluids()[contact.bath]
        record.update(
            bath=contact.bath,
            bath_density_g_cm3=round(bath_density(contact.bath, temperature), 4),
            bath_density_along_ramp=bool(along_ramp),
            bath_density_source=str(fluid.get("source", "")),
            bath_density_assumption=str(fluid.get("assumptions", "")),
        )
    return record

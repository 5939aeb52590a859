"""Materials layer: inks, process model, Janus cross-section mechanics, natural fields.

Public entry points (see each module for the physics and its sources):

* :func:`get_material`, :func:`register_material`, :class:`Material` (``material``)
* :func:`load_table` of the paper's measured values (``measurements``)
* process model: :func:`dimensionless_rotation`, :func:`order_parameter`,
  :class:`WarnerTerentjev`, :class:`EmpiricalThreshold`, :func:`actuation_fraction` (``process``)
* sections: :func:`filament_section` (``janus``), closed forms (``closed_form``), general
  quadrature (``section``), torsion FEM (``torsion``)
* assembly: :func:`natural_field`, :class:`NaturalField`, :class:`FilamentModel` (``natural``)
* :func:`calibrate`, :func:`predict` (``calibrate``); :func:`free_helix` (``morphology``)
"""

from __future__ import annotations

from rotomorph.materials.calibrate import CalibrationResult, calibrate, predict
from rotomorph.materials.janus import FilamentSection, filament_section
from rotomorph.materials.material import (
    Material,
    blend_material,
    get_material,
    known_materials,
    register_material,
)
from rotomorph.materials.measurements import MeasuredTable, load_table, table_names
from rotomorph.materials.morphology import HelixShape, free_helix
from rotomorph.materials.natural import FilamentModel, NaturalField, natural_field
from rotomorph.materials.process import (
    ActuationStrainModel,
    EmpiricalThreshold,
    WarnerTerentjev,
    actuation_fraction,
    dimensionless_rotation,
    helix_angle,
    helix_angle_profile,
    order_parameter,
)

__all__ = [
    "ActuationStrainModel",
    "CalibrationResult",
    "EmpiricalThreshold",
    "FilamentModel",
    "FilamentSection",
    "HelixShape",
    "Material",
    "MeasuredTable",
    "NaturalField",
    "WarnerTerentjev",
    "actuation_fraction",
    "blend_material",
    "calibrate",
    "dimensionless_rotation",
    "filament_section",
    "free_helix",
    "get_material",
    "helix_angle",
    "helix_angle_profile",
    "known_materials",
    "load_table",
    "natural_field",
    "order_parameter",
    "predict",
    "register_material",
    "table_names",
]

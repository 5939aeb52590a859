"""Materials layer: inks, process model, Janus cross-section mechanics, natural fields.

Public entry points (see each module for the physics and its sources):

* :func:`get_material`, :func:`register_material`, :class:`Material` (``material``)
* materials files as values: :class:`MaterialSet`, :func:`default_materials` (the paper's
  inks), :func:`materials_from_mapping` (``parameter_set``); a lab's calibration from its
  tables: :func:`~rotomorph.materials.lab_calibration.calibrate_tables`
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
from rotomorph.materials.parameter_set import (
    MaterialSet,
    default_materials,
    materials_from_mapping,
)
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
    "MaterialSet",
    "MeasuredTable",
    "NaturalField",
    "WarnerTerentjev",
    "actuation_fraction",
    "blend_material",
    "calibrate",
    "default_materials",
    "dimensionless_rotation",
    "filament_section",
    "free_helix",
    "get_material",
    "helix_angle",
    "helix_angle_profile",
    "known_materials",
    "load_table",
    "materials_from_mapping",
    "natural_field",
    "order_parameter",
    "predict",
    "register_material",
    "table_names",
]

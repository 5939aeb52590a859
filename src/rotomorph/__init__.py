"""rotomorph: design, simulate and print shape-morphing active-passive filaments and lattices.

The common path, imported lazily (``import rotomorph`` stays cheap; numba kernels load on first
use)::

    import rotomorph

    design = rotomorph.load_design("examples/designs/composite_rotation.toml")
    rotomorph.predict(design)                      # closed-form helices, instant
    run = rotomorph.simulate(design, steps=4)      # rod solver over the heating ramp
    run.save("runs/composite")                     # results.h5, summary.json, figures, ParaView
    rotomorph.write_gcode(design, "composite.gcode")

Everything else lives in the subpackages (``rotomorph.design``, ``.materials``, ``.rod``,
``.solve``, ``.lattice``, ``.io``, ``.plot``, ``.simulate``, ``.inverse``, ``.sweep``).
"""

from __future__ import annotations

import importlib
from typing import Any

from rotomorph.errors import (
    ConvergenceError,
    InvalidDesignError,
    InvalidParameterError,
    MachineLimitError,
    MaterialError,
    RotomorphError,
)

__version__ = "0.3.0"

#: Public name -> module that defines it (imported on first access).
_LAZY = {
    "Design": "rotomorph.io.designfile",
    "load_design": "rotomorph.io.designfile",
    "parse_design": "rotomorph.io.designfile",
    "save_design": "rotomorph.io.designfile",
    "design_schema": "rotomorph.io.designfile",
    "simulate": "rotomorph",  # the subpackage itself, callable (rotomorph.simulate.__init__)
    "predict": "rotomorph.simulate.api",
    "write_gcode": "rotomorph.simulate.api",
    "simulate_design": "rotomorph.simulate.design",
    "simulate_filament": "rotomorph.simulate.filament",
    "FilamentSimulation": "rotomorph.simulate.filament",
    "DesignSimulation": "rotomorph.simulate.design",
    "write_run": "rotomorph.simulate.outputs",
    "read_results": "rotomorph.io.results",
    "PrintProgram": "rotomorph.design.program",
    "sinusoidal_lattice": "rotomorph.design.lattices",
    "natural_field": "rotomorph.materials.natural",
    "FilamentModel": "rotomorph.materials.natural",
    "get_material": "rotomorph.materials.material",
    "load_materials": "rotomorph.io.materials_file",
    "MachineProfile": "rotomorph.io.machine",
    "load_machine_profile": "rotomorph.io.machine",
}

__all__ = [
    "ConvergenceError",
    "InvalidDesignError",
    "InvalidParameterError",
    "MachineLimitError",
    "MaterialError",
    "RotomorphError",
    "__version__",
    *sorted(_LAZY),
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'rotomorph' has no attribute {name!r}")
    value = importlib.import_module(f"{module}.{name}" if module == "rotomorph" else module)
    if module != "rotomorph":
        value = getattr(value, name)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))

"""The common path in three calls, as exported at the top level (``rotomorph.simulate`` …).

::

    import rotomorph

    design = rotomorph.load_design("examples/designs/composite_rotation.toml")
    shapes = rotomorph.predict(design)             # closed-form helix per filament, instant
    run = rotomorph.simulate(design, steps=4)       # rod solver over the heating ramp
    run.save("runs/composite")                      # results.h5, summary.json, figures, ParaView
    rotomorph.write_gcode(design, "composite.gcode")

Each function accepts a :class:`~rotomorph.io.designfile.Design`, the path of a design file, or
(where it makes sense) one :class:`~rotomorph.design.program.PrintProgram`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path as FilePath
from typing import Any

from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import Design, load_design

__all__ = ["predict", "simulate", "write_gcode"]

DesignLike = Design | str | FilePath


def _design(design: Any) -> Design:
    if isinstance(design, Design):
        return design
    if isinstance(design, str | os.PathLike):
        return load_design(FilePath(design))
    raise InvalidParameterError(
        "design", f"must be a Design or the path of a design file; got {type(design).__name__}"
    )


def simulate(design: DesignLike | PrintProgram, **options: Any) -> Any:
    """Shapes over heating of a design (or of one print program), by the rod solver.

    Parameters
    ----------
    design
        A :class:`~rotomorph.io.designfile.Design`, a design file path, or a
        :class:`~rotomorph.design.program.PrintProgram`.
    **options
        As :func:`rotomorph.simulate.design.simulate_design` (``steps``, ``temperature`` …) or,
        for a program, :func:`rotomorph.simulate.filament.simulate_filament`.

    Returns
    -------
    DesignSimulation or FilamentSimulation
        Has ``save(folder)`` and ``plot(folder)``.
    """
    if isinstance(design, PrintProgram):
        from rotomorph.simulate.filament import simulate_filament

        return simulate_filament(design, **options)
    from rotomorph.simulate.design import simulate_design

    return simulate_design(_design(design), **options)


def predict(
    design: DesignLike | PrintProgram, *, temperature: float = 175.0, model: Any = None
) -> Any:
    """Closed-form shape of each filament at ``temperature`` (°C): the free helix of its
    natural curvature and twist (instant; uniform filaments only), with the inks of the
    design's materials file when it names one.

    Returns
    -------
    HelixShape or list of HelixShape
        One shape for a program, a list (one per filament) for a design.

    Raises
    ------
    InvalidDesignError
        A lattice design, or a filament whose natural field varies along it (use
        :func:`simulate`).
    """
    from rotomorph.materials.natural import FilamentModel, named_model, natural_field

    name = model if isinstance(model, str) else None  # a name, as simulate accepts
    if name is not None:
        model = named_model(name)  # fails early on an unknown name
    if model is not None and not isinstance(model, FilamentModel):
        from rotomorph.errors import InvalidParameterError

        raise InvalidParameterError("model", f"must be a FilamentModel or its name; got {model!r}")
    if isinstance(design, PrintProgram):
        return natural_field(design, None, temperature, model=model).morphology()
    d = _design(design)
    if d.lattice is not None:
        from rotomorph.errors import InvalidDesignError

        raise InvalidDesignError("lattice", "has no closed-form shape; use rotomorph.simulate")
    from rotomorph.simulate.inks import design_model

    # each filament with its ink pair's model (the design's materials file, if it names one)
    return [
        natural_field(
            p,
            None,
            temperature,
            model=design_model(d, p.active_material, p.passive_material, name or model),
        ).morphology()
        for p in d.to_programs()
    ]


def write_gcode(
    design: DesignLike | Sequence[PrintProgram],
    path: str | os.PathLike[str],
    machine: Any = None,
    **options: Any,
) -> FilePath:
    """Write G-code for a design (or print programs) to ``path`` atomically.

    Parameters
    ----------
    design
        A design, a design file path, or a sequence of print programs.
    path
        G-code file to write.
    machine
        A :class:`~rotomorph.io.machine.MachineProfile` or the path of a profile; default the
        built-in generic machine.
    **options
        As :func:`rotomorph.io.gcode.write_gcode` (``layer_cure_s``, ``pressures`` …).
    """
    from rotomorph.io.gcode import write_gcode as write
    from rotomorph.io.machine import MachineProfile, load_machine_profile

    if machine is None:
        machine = MachineProfile()
    elif isinstance(machine, str | os.PathLike):
        machine = load_machine_profile(FilePath(machine))
    if isinstance(design, Sequence) and not isinstance(design, str):
        return write(list(design), FilePath(path), machine, **options)
    from rotomorph.io.placement import check_placement

    d = _design(design)
    check_placement(d, machine)  # a refusal that names the design key to change
    return write(d.to_programs(), FilePath(path), machine, **{**d.gcode_options(), **options})
